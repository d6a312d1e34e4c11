"""Stabilised systems (module :mod:`infsup_contact.systems.stabilised`): a level's ``C``, the
(2,2) block −C of [[A, Bᵀ], [B, −C]], checked as G is; β_C² = λ_min(B A⁻¹ Bᵀ + C, G) on every
route; the three-way verdict; and the bubble condensation's identity on the paper's membranes
with P0 multipliers (R5.4, k = 1): β_C of the condensed system is β_h of the enriched pair."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp
import scipy.sparse.linalg  # noqa: F401 (sp.linalg)

from infsup_contact.cli import main
from infsup_contact.systems.engine import ROUTES, level_spectrum
from infsup_contact.systems.levels import dry_check, system_rows, system_verdict
from infsup_contact.systems.manifest import load_manifest
from infsup_contact.systems.readers import SystemFileError
from infsup_contact.systems.stabilised import REGULARISED_MAX, condense_bubbles, stabilised_spectrum

CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)  # verdict's defaults (config/config.yaml claims)


def _suite(case: str, k: int, n: int):
    """(A, B, G = the H^{-1/2}_00 Gram, M = the L² mass) of the suite's membranes, matching meshes."""
    from infsup_contact.systems.export import suite_system

    A, B, G = suite_system(case, k, n, n, norm="H")
    return sp.csr_matrix(A), sp.csr_matrix(B), G, suite_system(case, k, n, n, norm="L2")[2]


def _write(tmp_path, levels, name="stab"):
    """levels: (h, A, B, G, C or None); a ``norm: given`` manifest of MatrixMarket files."""
    lines = [f"name: {name}", "norm: given", "levels:"]
    for i, (h, *mats) in enumerate(levels):
        keys = []
        for key, mat in zip("ABGC", mats):
            if mat is not None:
                scipy.io.mmwrite(tmp_path / f"{key}{i}.mtx", sp.csr_matrix(mat), precision=17)
                keys.append(f", {key}: {key}{i}.mtx")
        lines.append(f"  - {{h: {h!r}{''.join(keys)}}}")
    path = tmp_path / "levels.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path


# ------------------------------------------------------------------ the bubble condensation

def _enriched_membranes(n: int):
    """R5.4 (P0 multipliers) on P1 membranes, N1 = N2 = n, and one quadratic edge bubble per Γ
    edge of Ω2 (the slave side): (A, D, G, K_ub, K_bb, D_b), all exact. NGSolve's H1 basis is
    hierarchical (its order-2 space holds the P1 hats as vertex functions), so its order-2
    stiffness on the vertex dofs and the Γ edge dofs is [[K_2, K_ub], [K_ubᵀ, K_bb]] with K_2 the
    suite's own (checked); D_b = ∫_e b_e μ_e, the bubble's mean from a P2 linear form, scaled
    by μ_e's normalisation read from B (its two hats integrate to |e|/2 each)."""
    import ngsolve

    from infsup_contact.systems.export import _suite_parts

    A, B, space, gamma, sides = _suite_parts("R5.4", 1, n, n, "structured", "omega2", None)
    G = np.asarray(gamma.gram(space, "H")[0], float)
    side = sides[1]
    mesh, nv, off = side.trace.fes.mesh, side.trace.fes.ndof, sides[0].ndof
    fes = ngsolve.H1(mesh, order=2, dirichlet="dir")
    u, v = fes.TnT()
    a = ngsolve.BilinearForm(fes)
    a += ngsolve.grad(u) * ngsolve.grad(v) * ngsolve.dx
    a.Assemble()
    K = sp.csr_matrix(tuple(np.array(x, copy=True) for x in a.mat.CSR()), shape=(fes.ndof, fes.ndof))
    lf = ngsolve.LinearForm(fes)
    lf += v * ngsolve.ds("gamma")
    lf.Assemble()
    mean = lf.vec.FV().NumPy().copy()
    free = np.asarray(side.free)
    assert abs(K[free][:, free] - side.stiffness).max() <= 1e-14 * abs(side.stiffness).max()
    column = {int(d): off + i for i, d in enumerate(free)}
    B = sp.csr_matrix(B)
    slave = [set(int(j) for j in B[r].indices if j >= off) for r in range(B.shape[0])]
    bubbles, rows, values = [], [], []
    for el in mesh.Elements(ngsolve.BND):
        if el.mat != "gamma":
            continue
        dofs = [int(d) for d in fes.GetDofNrs(el)]
        (edge,), cols = [d for d in dofs if d >= nv], {column[d] for d in dofs if d < nv and d in column}
        (r,) = [r for r in range(B.shape[0]) if slave[r] == cols]  # μ_e: the row over this edge's hats
        x0, x1 = (mesh[p].point[0] for p in el.vertices)
        scale = sum(B[r, c] for c in cols) / (0.5 * abs(x1 - x0) * len(cols))  # μ_e's value on e
        bubbles.append(edge)
        rows.append(r)
        values.append(scale * mean[edge])
    K_ub = sp.lil_matrix((A.shape[0], len(bubbles)))
    for j, b in enumerate(bubbles):
        col = K[:, b].tocoo()
        for d, val in zip(col.row, col.data):
            if int(d) in column:
                K_ub[column[int(d)], j] = val
    D_b = sp.csr_matrix((values, (rows, np.arange(len(bubbles)))), shape=(B.shape[0], len(bubbles)))
    return sp.csr_matrix(A), B, G, sp.csr_matrix(K_ub), sp.csr_matrix(K[bubbles][:, bubbles]), D_b


@pytest.mark.parametrize("n", [4, 8])
def test_condensed_beta_C_is_beta_of_the_bubble_enriched_pair(n):
    """B_e A_e⁻¹ B_eᵀ = B_c S_A⁻¹ B_cᵀ + C (block elimination), so β_C of the condensed system is
    β_h of the enriched unstabilised pair: equal to round-off, computed independently."""
    A, D, G, K_ub, K_bb, D_b = _enriched_membranes(n)
    A_e = sp.bmat([[A, K_ub], [K_ub.T, K_bb]], format="csc")
    B_e = sp.hstack([D, D_b], format="csr")
    S_A, B_c, C = condense_bubbles(A, K_ub, K_bb, D, D_b)
    assert np.linalg.eigvalsh(C.toarray()).min() >= -1e-14 * abs(C).max()  # with the (2,2) block −C, C is PSD
    S_e = (B_e @ sp.linalg.splu(A_e).solve(B_e.T.toarray()))
    S_c = B_c @ sp.linalg.splu(sp.csc_matrix(S_A)).solve(B_c.T.toarray()) + C.toarray()
    assert np.abs(S_e - S_c).max() <= 1e-10 * np.abs(S_e).max()
    enriched = level_spectrum(A_e, B_e, G)
    assert enriched.kernel.dim == 0  # one bubble per slave edge removes R5.4's kernel
    plain = level_spectrum(A, D, G)
    assert plain.kernel.dim == 1 and plain.beta == 0.0  # R5.4 at k = 1 on matching meshes: one zero mode
    for route in ("gamma-dense", "solves-dense", "shift-invert"):
        res = level_spectrum(S_A, B_c, G, route=route)
        stab = stabilised_spectrum(S_A, B_c, G, C, route, float(res.kernel.singular[-1]) ** 2)
        assert abs(stab.beta_C - enriched.beta) <= 1e-10 * enriched.beta, route


def test_bubble_stabilisation_of_R54_over_N_4_to_32(tmp_path):
    """R5.4 (k = 1) over N = 4..32, three systems from the same bubbles: (A, D) alone is UNSTABLE
    with its kernel of dimension 1; (A, D) with C = D_b K_bb⁻¹ D_bᵀ (Brezzi–Fortin's minimal
    stabilisation: the bubbles' C, B unchanged) is ``stabilised``, β_C bounded uniformly in h;
    the fully condensed (S_A, B_c, C) has B_c = D − D_b K_bb⁻¹ K_ubᵀ, whose kernel is gone:
    its verdict is the unstabilised pair's, and β_C ≥ β_h there (C is PSD)."""
    plain, minimal, condensed = [], [], []
    for n in (4, 8, 16, 32):
        A, D, G, K_ub, K_bb, D_b = _enriched_membranes(n)
        S_A, B_c, C = condense_bubbles(A, K_ub, K_bb, D, D_b)
        plain.append((1.0 / n, A, D, G, None))
        minimal.append((1.0 / n, A, D, G, C))
        condensed.append((1.0 / n, S_A, B_c, G, C))
    for sub in ("plain", "minimal", "condensed"):
        (tmp_path / sub).mkdir()
    head, rows = system_verdict(load_manifest(_write(tmp_path / "plain", plain)), **CRITERION)
    assert head["verdict"] == "UNSTABLE" and [r["kernel_detected"] for r in rows] == [1, 1, 1, 1]
    assert "stabilisation" not in head
    head, rows = system_verdict(load_manifest(_write(tmp_path / "minimal", minimal, "R5.4+C_b")), **CRITERION)
    assert head["verdict"] == "UNSTABLE" and head["stabilisation"] == "stabilised" and head["verdict_C"] == "STABLE"
    assert "C controls a kernel of dimension 1 (dims [1, 1, 1, 1]) (uniformly in h)" in head["evidence"]
    assert min(r["c_scale"] for r in rows) > REGULARISED_MAX
    head, rows = system_verdict(load_manifest(_write(tmp_path / "condensed", condensed, "R5.4-condensed")),
                                **CRITERION)
    assert (head["stabilisation"] == "stable-without-C") == (head["verdict"] == "STABLE")
    assert head["verdict_C"] == "STABLE" and all(r["beta_C"] >= r["beta"] for r in rows)


# ------------------------------------------------------------------ the three verdict classes

def test_regularised_unstable_pair_with_a_tiny_mass(tmp_path):
    """An UNSTABLE export (R5.4, k = 1) plus C = 1e-10 G: UNSTABLE, ``regularised``; β_C is
    √1e-10 on the kernel mode, all of it from C (c_share 1)."""
    levels = [(1.0 / n, A, B, G, 1e-10 * sp.csr_matrix(G)) for n in (4, 8, 16) for A, B, G, _ in [_suite("R5.4", 1, n)]]
    head, rows = system_verdict(load_manifest(_write(tmp_path, levels)), **CRITERION)
    assert head["verdict"] == "UNSTABLE" and head["stabilisation"] == "regularised"
    assert "regularised: C ~ eps*M" in head["evidence"] and head["kernel_dim"] == 1
    for r in rows:
        assert r["beta"] == 0.0 and r["c_scale"] < REGULARISED_MAX
        # the kernel mode's quotient is exactly 1e-10 (S vanishes there); S's round-off, m ε λ_max(S, G) ~ 1e-14,
        # is 1e-4 of it
        assert r["c_share"] > 1 - 1e-3 and abs(r["beta_C"] ** 2 - 1e-10) <= 1e-3 * 1e-10


@pytest.mark.parametrize("route", ["gamma-dense", "shift-invert"])
def test_zero_coupling_with_a_tiny_mass_is_regularised(tmp_path, route):
    """B = 0 (FreeFEM's shipped mortar tutorial, whose coupling integrals are empty) plus
    C = 1e-10 G: there is no pencil to measure C against (B A⁻¹ Bᵀ = 0), every multiplier is in
    the kernel, and C lifts it only to β_C = 1e-5, below the floor: ``regularised``, UNSTABLE."""
    levels = [(1.0 / n, A, 0 * B, G, 1e-10 * sp.csr_matrix(G)) for n in (4, 8, 16) for A, B, G, _ in [_suite("R5.4", 1, n)]]
    head, rows = system_verdict(load_manifest(_write(tmp_path, levels)), route=route, **CRITERION)
    assert head["verdict"] == "UNSTABLE" and head["stabilisation"] == "regularised", head["evidence"]
    assert "regularised: C lifts the kernel only" in head["evidence"]
    for r, (_, _, B, _, _) in zip(rows, levels):
        assert r["kernel_detected"] == B.shape[0] and abs(r["beta_C"] ** 2 - 1e-10) <= 1e-6 * 1e-10


def test_stable_pair_keeps_its_verdict_and_says_C_is_not_needed(tmp_path):
    """T3 (k = 2, N = 8..32) is STABLE: with any C it is ``stable-without-C``, and β_C ≥ β_h (C is PSD)."""
    levels = [(1.0 / n, A, B, G, 0.1 / n * sp.csr_matrix(M))
              for n in (8, 16, 32) for A, B, G, M in [_suite("T3", 2, n)]]
    head, rows = system_verdict(load_manifest(_write(tmp_path, levels)), **CRITERION)
    assert head["verdict"] == "STABLE" and head["stabilisation"] == "stable-without-C"
    assert all(r["beta_C"] >= r["beta"] * (1 - 1e-12) for r in rows)


def test_mesh_dependent_C_controls_the_kernel_not_uniformly(tmp_path):
    """Barbosa–Hughes-like C = α h² M on R5.4's P0 multipliers (α = 1) holds the kernel, but the
    kernel mode's β_C² is then O(h²) against G: ``stabilised``, "not uniformly"; with C = α h M
    (the h-scaled mass of the minimal stabilisation) β_C stays bounded."""
    for power, how in ((2, "not uniformly"), (1, "uniformly in h")):
        levels = [(1.0 / n, A, B, G, (1.0 / n) ** power * sp.csr_matrix(M))
                  for n in (8, 16, 32) for A, B, G, M in [_suite("R5.4", 1, n)]]
        (tmp_path / str(power)).mkdir()
        head, _ = system_verdict(load_manifest(_write(tmp_path / str(power), levels)), **CRITERION)
        assert head["verdict"] == "UNSTABLE" and head["stabilisation"] == "stabilised"
        assert f"C controls a kernel of dimension 1 (dims [1, 1, 1]) ({how}" in head["evidence"], head["evidence"]


def test_zero_C_is_no_stabilisation(tmp_path):
    levels = [(1.0 / n, A, B, G, sp.csr_matrix(G.shape)) for n in (4, 8, 16) for A, B, G, _ in [_suite("R5.4", 1, n)]]
    head, rows = system_verdict(load_manifest(_write(tmp_path, levels)), **CRITERION)
    assert head["stabilisation"] == "none" and head["verdict"] == "UNSTABLE"
    assert all(r["beta_C"] <= 1e-6 * r["smallest_nonzero"] for r in rows)  # C = 0: the kernel mode is back


def test_without_C_no_column_of_C(tmp_path):
    """A manifest without C: rows and head exactly as before (no stabilisation columns)."""
    levels = [(1.0 / n, A, B, G, None) for n in (4, 8, 16) for A, B, G, _ in [_suite("R5.4", 1, n)]]
    head, rows = system_verdict(load_manifest(_write(tmp_path, levels)), **CRITERION)
    new = {"beta_C", "stabilisation", "verdict_C", "c_share", "c_scale", "residual_C"}
    assert not new & set(head) and not any(new & set(r) for r in rows)


# ------------------------------------------------------------------ routes

@pytest.mark.parametrize("scale", [1.0 / 8, 1e-10])
def test_routes_agree_with_C(tmp_path, scale):
    """β_C² and c_share on the three routes (the shift-invert route's (2,2) block is −(C + δG))
    agree to the pencil's round-off, a few ε λ_max(B A⁻¹ Bᵀ, G); the manifest's rows name the route."""
    A, B, G, M = _suite("R5.4", 1, 8)
    C = scale * sp.csr_matrix(M)
    sigma2 = float(level_spectrum(A, B, G).kernel.singular[-1]) ** 2
    ref = stabilised_spectrum(A, B, G, C, "gamma-dense", sigma2)
    for route in ROUTES[2:]:
        got = stabilised_spectrum(A, B, G, C, route, sigma2)
        assert abs(got.beta_C ** 2 - ref.beta_C ** 2) <= 1e-13 * ref.lam_s, route
        assert abs(got.c_share - ref.c_share) <= 1e-13 * ref.lam_s / ref.beta_C ** 2, route
    manifest = load_manifest(_write(tmp_path, [(1.0 / 8, A, B, G, C)]), min_levels=1)
    assert [system_rows(manifest, route)[0]["route"] for route in ROUTES[1:]] == list(ROUTES[1:])


# ------------------------------------------------------------------ hostile C

def _three_levels(tmp_path):
    """R5.4 (k = 1, N = 4, 8, 16) with C = 1e-3 M: (manifest, levels)."""
    levels = [(1.0 / n, A, B, G, 1e-3 * sp.csr_matrix(M)) for n in (4, 8, 16) for A, B, G, M in [_suite("R5.4", 1, n)]]
    return _write(tmp_path, levels), levels


@pytest.mark.parametrize("bad, found", [
    (lambda C: sp.csr_matrix(C)[:-1], "C is 3 x 4, but B (B0.mtx) has 4 rows: expected 4 x 4"),
    (lambda C: C + sp.csr_matrix(([1.0], ([0], [1])), shape=C.shape), "C is not symmetric"),
    (lambda C: C - 2e-3 * sp.identity(C.shape[0]), "C is not positive semidefinite"),
    (lambda C: -C, "every eigenvalue <= 0: this is the (2,2) block itself"),
    (lambda C: sp.csr_matrix(np.where(np.eye(C.shape[0]) > 0, np.nan, 0.0)), "NaN/inf entries"),
])
def test_bad_C_is_one_line_naming_the_file(tmp_path, capsys, bad, found):
    path, levels = _three_levels(tmp_path)
    scipy.io.mmwrite(tmp_path / "C0.mtx", sp.csr_matrix(bad(sp.csr_matrix(levels[0][4]))), precision=17)
    with pytest.raises(SystemFileError, match="C0.mtx"):
        system_rows(load_manifest(path))
    for argv in (["--dry-run"], []):
        assert main(["verdict", "--system", str(path)] + argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(tmp_path / "C0.mtx") in err and found in err, err


def test_cut_C_and_C_on_some_levels_only_are_refused(tmp_path, capsys):
    path, _ = _three_levels(tmp_path)
    (tmp_path / "C1.mtx").write_bytes((tmp_path / "C1.mtx").read_bytes()[:-2])
    assert main(["verdict", "--system", str(path), "--dry-run"]) == 2
    assert "C1.mtx: MatrixMarket: the last line" in capsys.readouterr().err
    path.write_text(path.read_text().replace(", C: C1.mtx", ""))
    assert main(["verdict", "--system", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "levels[1]: no key 'C' where levels[0] has one" in err, err


def test_dry_run_counts_C(tmp_path):
    path, _ = _three_levels(tmp_path)
    with_c = dry_check(load_manifest(path)).bytes
    path.write_text("".join(line.split(", C:")[0] + ("}\n" if ", C:" in line else "\n")
                            for line in path.read_text().splitlines()))
    assert with_c > dry_check(load_manifest(path)).bytes


def test_cli_prints_the_columns_of_C(tmp_path, capsys):
    path, _ = _three_levels(tmp_path)
    main(["verdict", "--system", str(path)])
    head = capsys.readouterr().out.splitlines()[0].split(",")
    assert {"stabilisation", "beta_C", "verdict_C", "slope_C"} <= set(head)
    main(["beta", "--system", str(path)])
    assert {"beta_C", "c_share", "c_scale"} <= set(capsys.readouterr().out.splitlines()[0].split(","))


def test_C_with_a_described_H_norm_is_read_in_B_rows(tmp_path):
    """``norm: H`` with the multipliers described: C is indexed like B as exported, and β_C is
    that of the same system with the H Gram given (``norm: given``)."""
    from infsup_contact.systems.export import suite_levels, write_system

    levels, norm, gamma = suite_levels("R5.4", 1, [4, 8, 16], norm="H")
    path = write_system(tmp_path, levels, "mtx", "described", norm=norm, gamma=gamma)
    text, given = path.read_text(), []
    for i, n in enumerate((4, 8, 16)):
        A, B, G, M = _suite("R5.4", 1, n)
        scipy.io.mmwrite(tmp_path / f"C{i}.mtx", sp.csr_matrix(M) / n, precision=17)
        text = text.replace(f"    G: G{i}.mtx\n", f"    G: G{i}.mtx\n    C: C{i}.mtx\n")
        given.append((1.0 / n, A, B, G, sp.csr_matrix(M) / n))
    path.write_text(text)
    described = system_rows(load_manifest(path))
    (tmp_path / "given").mkdir()
    plain = system_rows(load_manifest(_write(tmp_path / "given", given)))
    for r, q in zip(described, plain):
        assert abs(r["beta_C"] - q["beta_C"]) <= 1e-10 * q["beta_C"]


def test_large_C_is_checked_by_its_inertia():
    """Above the dense check's size, C + δI's LDLᵀ pivots: a negative eigenvalue is found, a
    semidefinite C (zeros on the diagonal) passes."""
    from infsup_contact.systems.stabilised import DENSE_PSD_MAX_M, check_semidefinite

    m = DENSE_PSD_MAX_M + 1
    d = np.where(np.arange(m) % 2 == 0, 0.0, 1.0)
    check_semidefinite(sp.diags(d).tocsr(), "C.mtx")
    d[7] = -1e-3
    with pytest.raises(SystemFileError, match="C is not positive semidefinite: 1 negative pivots"):
        check_semidefinite(sp.diags(d).tocsr(), "C.mtx")


def test_penalty_rows_of_C_follow_G_or_are_refused(tmp_path, capsys):
    """A tgv diagonal in C alone is refused (one line); the same row marked in G too (a penalty
    row there: the constrained-rows rule) is removed from B, G and C, and β_C is that of the
    system without the row."""
    A, B, G, M = _suite("R5.4", 1, 4)
    C = (sp.csr_matrix(M) / 4).tolil()
    C[0, 0] = 1e30
    path = _write(tmp_path, [(0.25, A, B, G, C.tocsr())])
    assert main(["beta", "--system", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "C0.mtx: 1 penalty rows of C" in err, err
    G2 = sp.lil_matrix(G)
    G2[0, 0] = 1e30
    G2[0, 1:] = 0.0
    G2[1:, 0] = 0.0
    path = _write(tmp_path, [(0.25, A, B, G2.tocsr(), C.tocsr())])
    assert main(["beta", "--system", str(path), "--dry-run"]) == 0  # the dry run removes the row as the run does
    row = system_rows(load_manifest(path, min_levels=1))[0]
    keep = np.arange(1, B.shape[0])
    C_kept = sp.csr_matrix(M)[keep][:, keep] / 4
    ref = stabilised_spectrum(A, B[keep], G[np.ix_(keep, keep)], C_kept, "gamma-dense", 1.0)
    assert row["removed_multipliers"] == 1 and abs(row["beta_C"] - ref.beta_C) <= 1e-10 * ref.beta_C
