"""The large route's pencils split by the point reflection of the face (solvers/reflection.py):
the permutation of real face bases, the block identity Q_e M_e Q_eᵀ + Q_o M_o Q_oᵀ = M, the kernel's
even/odd parts, and β rows identical (to the Lanczos accuracy) with and without the split."""
import numpy as np
import pytest
import scipy.linalg as sla

from infsup_contact.discretization import registry
from infsup_contact.discretization.square import SQUARE, SQUARE_TRIG, TensorPartition
from infsup_contact.solvers import bottom, infsup, reflection


def _space(case, k, n, gamma=SQUARE):
    g = np.linspace(0.0, 1.0, n + 1)
    part = TensorPartition(g, g)
    return registry.case_space(case, k, part, gamma), part


def _invariant_spd(pi, seed, shift=1.0):
    m = pi.size
    A = np.random.default_rng(seed).standard_normal((m, m))
    A = A @ A.T + shift * m * np.eye(m)
    return 0.5 * (A + A[np.ix_(pi, pi)])


@pytest.mark.parametrize("case,k,gamma", [("T3", 2, SQUARE), ("R5.2", 2, SQUARE), ("DUAL-ALL", 1, SQUARE),
                                          ("PWLIN-Q9", 2, SQUARE), ("R5.4", 2, SQUARE), ("R5.2", 1, SQUARE_TRIG)])
def test_the_reflection_permutes_the_basis(case, k, gamma):
    space, part = _space(case, k, 5, gamma)
    x = gamma.quadrature(part, 2 * k)[0]
    split = reflection.reflection_split(space, x)
    assert split is not None
    pi = split.pi
    assert np.array_equal(pi[pi], np.arange(space.dim))                       # an involution
    np.testing.assert_allclose(space.evaluate(1.0 - x), space.evaluate(x)[:, pi], atol=1e-12)
    ke, ko = split.sizes
    assert ke + ko == space.dim and ke - ko == split.fixed.size


def test_a_graded_partition_has_no_split():
    xs = np.array([0.0, 0.1, 0.35, 0.7, 1.0])
    part = TensorPartition(xs, xs)
    space = registry.case_space("R5.2", 1, part, SQUARE)
    assert reflection.reflection_split(space, SQUARE.quadrature(part, 2)[0]) is None


def test_blocks_reconstruct_an_invariant_matrix_and_detect_a_non_invariant_one():
    space, part = _space("R5.2", 2, 4)
    split = reflection.reflection_split(space, SQUARE.quadrature(part, 4)[0])
    M = _invariant_spd(split.pi, 0)
    Me, Mo, distance = split.blocks(M)
    assert distance <= 1e-14
    r, p, f, h = split.rep, split.pi[split.rep], split.fixed, np.sqrt(0.5)
    m = M.shape[0]
    Qe, Qo = np.zeros((m, Me.shape[0])), np.zeros((m, Mo.shape[0]))
    Qe[r, np.arange(r.size)], Qe[p, np.arange(r.size)] = h, h
    Qe[f, r.size + np.arange(f.size)] = 1.0
    Qo[r, np.arange(r.size)], Qo[p, np.arange(r.size)] = h, -h
    np.testing.assert_allclose(Qe @ Me @ Qe.T + Qo @ Mo @ Qo.T, M, atol=1e-12 * np.abs(M).max())
    M[0, 1] += 1e-6 * np.abs(M).max()
    M[1, 0] = M[0, 1]
    assert split.blocks(M)[2] > reflection.INVARIANCE_RTOL


@pytest.mark.parametrize("d_even,d_odd", [(0, 0), (3, 0), (2, 5)])
def test_split_pencils_equal_the_unsplit_route(d_even, d_odd):
    """A synthetic invariant pencil with an invariant kernel of d_even + d_odd modes: the values
    above the kernel and λ_max of the halves are the unsplit route's (bottom_spectra)."""
    space, part = _space("R5.2", 2, 4)
    split = reflection.reflection_split(space, SQUARE.quadrature(part, 4)[0])
    m, pi = space.dim, split.pi
    rng = np.random.default_rng(1)
    r, p, f, h = split.rep, pi[split.rep], split.fixed, np.sqrt(0.5)
    even = np.zeros((m, d_even))
    for j in range(d_even):  # even vectors: v = v∘π
        v = rng.standard_normal(m)
        even[:, j] = v + v[pi]
    odd = np.zeros((m, d_odd))
    for j in range(d_odd):
        v = rng.standard_normal(m)
        odd[:, j] = v - v[pi]
    Z = np.hstack([even, odd])
    A = _invariant_spd(pi, 2)
    if Z.shape[1]:  # S = P_⊥ A P_⊥ with P_⊥ the Euclidean projector off span Z: S Z = 0, invariant
        Q = sla.qr(Z, mode="economic")[0]
        Pp = np.eye(m) - Q @ Q.T
        A = Pp @ A @ Pp
        A = 0.5 * (A + A.T)
    G = _invariant_spd(pi, 3, shift=0.2)
    d = Z.shape[1]
    kernel = infsup.KernelDecision(d, d, 0, np.inf, "clear", 0.0, np.zeros(0), d, Z if d else None)
    plain = infsup.bottom_spectra(A, {"H": infsup.gram_factor(G)}, kernel if d else None)["H"]
    parts = split.even_odd(Z) if d else None
    if d:
        assert (parts[0].shape[1], parts[1].shape[1]) == (d_even, d_odd)
    factors = {"H": tuple(infsup.gram_factor(b) for b in split.blocks(G)[:2])}
    halves = infsup.split_spectra(split, A, factors, kernel if d else None, parts)["H"]
    assert halves.kernel_dim == plain.kernel_dim == d
    assert halves.smallest_nonzero == pytest.approx(plain.smallest_nonzero, rel=1e-9)
    assert halves.beta == pytest.approx(plain.beta, rel=1e-9, abs=0.0)
    assert halves.gap == pytest.approx(plain.gap, rel=1e-2)


def test_a_kernel_that_is_not_the_sum_of_its_parts_is_refused():
    space, part = _space("R5.2", 2, 4)
    split = reflection.reflection_split(space, SQUARE.quadrature(part, 4)[0])
    v = np.random.default_rng(4).standard_normal(space.dim)
    assert split.even_odd(v[:, None]) is None       # a generic vector: neither even nor odd


@pytest.mark.parametrize("case", ["T3", "R5.2", "DUAL-ALL"])
def test_face_rows_with_and_without_the_split(case, monkeypatch):
    """The iterative route (DENSE_MAX_M = 0) on a real face, hexahedra k = 2, 5:6, with the split
    and with it switched off: the same kernels, β to 1e-9."""
    from infsup_contact.models import MODELS
    monkeypatch.setattr(bottom, "DENSE_MAX_M", 0)
    calls, split_spectra = [], infsup.split_spectra
    monkeypatch.setattr(infsup, "split_spectra", lambda *a, **kw: calls.append(1) or split_spectra(*a, **kw))
    rows = {}
    for on in (True, False):
        if not on:
            monkeypatch.setattr(reflection, "reflection_split", lambda space, x: None)
        rows[on] = infsup.beta_rows("structured", 2, 5, 6, [case], model=MODELS["membranes3d"], element="hex")
        assert bool(calls) == on  # the split was taken, and then switched off
        calls.clear()
    for a, b in zip(rows[True], rows[False]):
        assert (a["kernel_dim"], a["kernel_decision"]) == (b["kernel_dim"], b["kernel_decision"])
        if a["kernel_detected"] == 0:  # σ_{d+1}/η: the first value above the kernel, either way
            assert a["kernel_margin_decades"] == pytest.approx(b["kernel_margin_decades"], abs=1e-3)
        assert a["beta"] == pytest.approx(b["beta"], rel=1e-9, abs=1e-12)
        assert a["smallest_nonzero"] == pytest.approx(b["smallest_nonzero"], rel=1e-8)
        assert a["beta_v1_zero"] == pytest.approx(b["beta_v1_zero"], rel=1e-9, abs=1e-12)


def test_the_split_kernel_is_the_unsplit_one_on_a_real_face(monkeypatch):
    """split_bottom_kernel on W of R5.2 (k = 2, hexahedra 5:6: 16 modes beyond the dimension
    count) decides what bottom_kernel decides: the count, the first value above it, η; its
    vectors span a kernel of W (‖W Z‖ <= η) and are orthonormal."""
    from infsup_contact.models import MODELS
    from infsup_contact.solvers.kernel import bottom_kernel
    captured = {}
    original = reflection.split_bottom_kernel

    def spy(W, split, proven, error):
        captured.update(W=W, split=split, proven=proven, error=error)
        return original(W, split, proven, error)

    monkeypatch.setattr(bottom, "DENSE_MAX_M", 0)
    monkeypatch.setattr(reflection, "split_bottom_kernel", spy)
    infsup.beta_rows("structured", 2, 5, 6, ["R5.2"], model=MODELS["membranes3d"], element="hex", norms=("L2",))
    W, split, proven, error = (captured[k] for k in ("W", "split", "proven", "error"))
    halves, whole = original(W, split, proven, error), bottom_kernel(W, proven, error)
    assert halves is not None and halves.dim == whole.dim > 0 and halves.detected == whole.detected
    assert halves.tol == pytest.approx(whole.tol, rel=1e-12)
    assert halves.singular[-2] == pytest.approx(whole.singular[-2], rel=1e-3)   # σ_{d+1}
    Z = halves.vectors
    np.testing.assert_allclose(Z.T @ Z, np.eye(Z.shape[1]), atol=1e-10)
    assert np.linalg.norm(W @ Z, axis=0).max() <= halves.tol


def test_an_interface_operator_that_is_not_invariant_is_solved_unsplit():
    """split_spectra returns None for an S off invariance (the caller's unsplit route)."""
    space, part = _space("R5.2", 2, 4)
    split = reflection.reflection_split(space, SQUARE.quadrature(part, 4)[0])
    S, G = _invariant_spd(split.pi, 5), _invariant_spd(split.pi, 6)
    factors = {"H": tuple(infsup.gram_factor(b) for b in split.blocks(G)[:2])}
    assert infsup.split_spectra(split, S, factors) is not None
    S[0, 2] += 1e-8 * np.abs(S).max()
    S[2, 0] = S[0, 2]
    assert infsup.split_spectra(split, S, factors) is None
