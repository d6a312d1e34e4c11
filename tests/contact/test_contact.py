"""The contact problem (4.1) on real meshes: routes agree, the sign of λ, rates, failures."""
import numpy as np
import pytest

from infsup_contact.study.claims.membranes import sign_check
from infsup_contact.contact.kkt import solve_kkt_sparse
from infsup_contact.models.membranes import load_vector
from infsup_contact.contact.contact import contact_qp, solve_contact
from infsup_contact.study.contact.scenes import manufactured, membranes
from infsup_contact.study.contact.rows import contact_row


@pytest.mark.parametrize("case,k,n1,n2", [("T3", 1, 6, 6), ("T5", 2, 5, 4), ("T4", 2, 6, 6)])
def test_gamma_reduced_pdas_equals_full_sparse_kkt(case, k, n1, n2):
    sc = membranes(c1=1.0, c2=2.0)
    sol = solve_contact(sc, case, k, "perturbed", n1, n2, time_floor=False)
    sides = sol.sides
    Bs = [coupling for coupling in _couplings(sol)]
    A, B, F = contact_qp(sides, Bs, [load_vector(s, f) for s, f in zip(sides, (sc.f1, sc.f2))], sol.c)
    u, lam, _ = solve_kkt_sparse(A, B, F)
    assert np.abs(lam - sol.lam).max() <= 1e-10 * max(1.0, np.abs(lam).max())
    u_ours = np.concatenate([gf.vec.FV().NumPy()[s.free] for gf, s in zip(sol.u, sides)])
    assert np.abs(u - u_ours).max() <= 1e-10 * np.abs(u).max()
    assert sol.pdas.complementarity <= 1e-10


def _couplings(sol):
    from infsup_contact.discretization.gamma.coupling import coupling_matrix
    return [coupling_matrix(s.trace, sol.space, s.trace.fes.globalorder) for s in sol.sides]


def test_sign_of_lambda_is_minus_c_dudy():
    """λ_h ≈ −c_i ∂u_ih/∂x2 (not +, as (3.13) prints), increasingly so on finer meshes."""
    coarse, fine = sign_check(n=8), sign_check(n=16)
    for i in (1, 2):
        assert fine[f"minus_c{i}"] < 0.15 and fine[f"minus_c{i}"] < 0.6 * coarse[f"minus_c{i}"]
        assert fine[f"plus_c{i}"] > 1.8  # |λ − (−λ)| / |λ| → 2


@pytest.mark.parametrize("case,k,expected", [("T3", 1, 1.0), ("T4", 2, 2.0), ("T5", 2, 2.0)])
def test_stable_pairs_energy_rate(case, k, expected):
    ns = [4, 8, 16]
    rows = [contact_row("manufactured", case, k, "structured", n, n, time_floor=False) for n in ns]
    err = [r["energy_error"] for r in rows]
    slope = np.polyfit(np.log(1.0 / np.array(ns)), np.log(err), 1)[0]
    assert abs(slope - expected) < 0.15, (err, slope)
    assert max(r["complementarity"] for r in rows) <= 1e-10
    lam = [r["lambda_hm12_error"] for r in rows]
    assert lam[-1] < lam[0]


def test_unstable_pair_is_flagged_and_oscillates():
    """R5.4: solved without crash, kernel reported, λ_h's total variation grows (T4 stays)."""
    rows = {case: [contact_row("manufactured", case, 2, "structured", n, n, time_floor=False)
                   for n in (8, 16, 32)] for case in ("R5.4", "T4")}
    assert all(r["kernel_dim"] == 1 for r in rows["R5.4"])
    assert all(r["kernel_dim"] == 0 for r in rows["T4"])
    tv_unstable = [r["lambda_tv"] for r in rows["R5.4"]]
    tv_stable = [r["lambda_tv"] for r in rows["T4"]]
    assert tv_unstable[-1] > 2 * tv_unstable[0] and tv_unstable[-1] > 5 * tv_stable[-1]


def test_r52_active_kernel_gives_nonunique_flag():
    """Pressing everywhere activates the endpoint modes of R5.2's kernel: λ_h not unique."""
    sc = membranes(f0=4.0)  # Ω1 pushed up, Ω2 down everywhere: contact on all of Γ
    sol = solve_contact(sc, "R5.2", 1, "structured", 8, 8, time_floor=False)
    assert sol.pdas.kernel_dim_K == 2
    assert sol.pdas.nonunique
    assert sol.pdas.complementarity <= 1e-10


def test_load_from_exact_solution_equals_quadrature_of_f():
    """Green's formula: c(∇u, ∇v) − ∫_Γ c ∂u/∂n v equals ∫ f v (smooth case, where f is benign)."""
    from infsup_contact.models.membranes import load_vector_from_exact
    from infsup_contact.models.membranes import side_operator
    from infsup_contact.discretization.segment.meshes import mesh_pair

    sc = manufactured(c1=1.0, c2=3.0, p=6.0, q=6.0)  # f smooth enough for its quadrature to be exact-ish
    for mesh, f, g, c, ny in zip(mesh_pair("perturbed", 6, 6), (sc.f1, sc.f2), (sc.grad_u1, sc.grad_u2),
                                 (1.0, 3.0), (1.0, -1.0)):
        side = side_operator(mesh, 2)
        F_quad, F_green = load_vector(side, f), load_vector_from_exact(side, g, c, ny)
        F_wrong = load_vector_from_exact(side, g, c, -ny)
        assert np.abs(F_quad - F_green).max() <= 1e-6 * np.abs(F_quad).max()
        assert np.abs(F_quad - F_wrong).max() > 1e3 * np.abs(F_quad - F_green).max()


def test_errors_against_a_reference_vanish_on_itself_and_do_not_depend_on_call_order():
    """The reference's own samples are kept on it after the first measurement: measuring
    itself gives zero, and a solution measured before and after the cache fills gives the
    same errors (the cached samples are those a fresh evaluation would give)."""
    from infsup_contact.study.contact import accuracy
    sc = membranes(c1=1.0, c2=2.0)
    ref = solve_contact(sc, "T3", 1, "structured", 16, 16, time_floor=False)
    fresh = solve_contact(sc, "T3", 1, "structured", 16, 16, time_floor=False)
    coarse = solve_contact(sc, "T4", 2, "structured", 4, 4, time_floor=False)

    def errors(sol, reference):
        return (*accuracy.energy_and_l2_vs_reference(sol, reference),
                *accuracy.lambda_errors_vs_reference(sol, reference),
                accuracy.contact_set_error_vs_reference(sol, reference))

    first = errors(coarse, ref)           # fills ref's cache
    assert errors(coarse, ref) == first   # served from it
    assert errors(coarse, fresh) == first  # an equal reference evaluated afresh
    assert min(first[:4]) > 1e-4
    assert max(errors(ref, ref)) < 1e-12


def test_cases_sharing_one_pair_solve_as_if_alone():
    """A pair built once and solved with several spaces gives each case the solution it
    gets from a pair of its own (nothing a case does leaks into the shared sides)."""
    from infsup_contact.contact.contact import contact_pair, solve_contact_on
    sc = membranes(c1=1.0, c2=2.0)
    pair = contact_pair(sc, 2, "perturbed", 6, 5)
    for case in ("R5.2", "T4", "T3"):
        shared = solve_contact_on(pair, case, time_floor=False)
        alone = solve_contact(sc, case, 2, "perturbed", 6, 5, time_floor=False)
        assert np.array_equal(shared.lam, alone.lam)
        for a, b in zip(shared.u, alone.u):
            assert np.array_equal(a.vec.FV().NumPy(), b.vec.FV().NumPy())
        assert shared.t_solve >= pair.seconds


# ------------------------------------------------------------------ issue 39, item 5.5: references never pickled
def test_a_saved_reference_measures_exactly_as_the_solved_one(tmp_path):
    """save_reference writes plain arrays (.npz): the errors against the loaded reference equal,
    bit for bit, those against the solved one, and it reads with allow_pickle=False."""
    from infsup_contact.study.contact import accuracy
    from infsup_contact.study.contact.rows import load_reference, save_reference

    sc = membranes(c1=1.0, c2=2.0)
    ref = solve_contact(sc, "T3", 2, "structured", 8, 8, time_floor=False)
    coarse = solve_contact(sc, "T4", 2, "structured", 4, 4, time_floor=False)
    save_reference(tmp_path / "ref.npz", ref)
    with np.load(tmp_path / "ref.npz", allow_pickle=False) as data:
        assert all(data[key].dtype != object for key in data.files)
    loaded = load_reference(tmp_path / "ref.npz")

    def errors(reference):
        return (*accuracy.energy_and_l2_vs_reference(coarse, reference),
                *accuracy.lambda_errors_vs_reference(coarse, reference),
                accuracy.contact_set_error_vs_reference(coarse, reference))

    assert errors(loaded) == errors(ref)


def _planted(path, marker):
    """A file whose unpickling runs code (touches ``marker``)."""
    import os
    import pickle

    class Payload:
        def __reduce__(self):
            return (os.system, (f"touch {marker}",))

    path.write_bytes(pickle.dumps(Payload()))


@pytest.mark.parametrize("how", ["pickle", "object-array-npz", "npy", "truncated", "missing", "wrong-shape"])
def test_a_planted_or_damaged_reference_is_refused_unread(tmp_path, how):
    """The references were pickles: a planted one ran its code on the next rerun. Now a pickle
    payload (as the file, or as an object array inside an .npz) is refused without being
    unpickled, as is any other file that is not a reference: one line naming the file."""
    import pickle

    from infsup_contact.errors import InputError
    from infsup_contact.study.contact.rows import load_reference, save_reference

    marker, path = tmp_path / "code-ran", tmp_path / "membranes_k1.npz"
    if how == "pickle":
        _planted(path, marker)
    elif how == "object-array-npz":
        payload = tmp_path / "p.pickle"
        _planted(payload, marker)
        obj = np.empty(1, dtype=object)
        obj[0] = pickle.loads  # never called: the point is an object array holding a pickle
        np.savez(path, format=np.array("infsup-contact reference 1"), lam=obj)
    elif how == "npy":
        np.save(tmp_path / "a.npy", np.ones(3))
        path = tmp_path / "a.npy"
    elif how in ("truncated", "wrong-shape"):
        ref = solve_contact(membranes(), "T3", 1, "structured", 4, 4, time_floor=False)
        save_reference(path, ref)
        if how == "truncated":
            path.write_bytes(path.read_bytes()[:200])
        else:
            with np.load(path, allow_pickle=False) as data:
                entries = {k: data[k] for k in data.files}
            entries["lam"] = entries["lam"][:-1]
            np.savez(path, **entries)
    with pytest.raises(InputError) as err:
        load_reference(path)
    line = str(err.value)
    assert err.value.key == "reference" and str(path) in line and "\n" not in line, line
    assert not marker.exists(), "the planted code ran"
