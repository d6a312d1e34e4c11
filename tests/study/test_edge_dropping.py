"""Edge dropping (issue 28, item 5): multipliers of Ω1's face cut at x = L, β_h with and
without κ scaling (:mod:`infsup_contact.study.face.edge_dropping`)."""
import numpy as np
import pytest

from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.spaces.registry import edge_cases
from infsup_contact.discretization.face.spaces.clipped import ClippedFace, clip_1d
from infsup_contact.discretization.face.norms.tensor import partial_gram
from infsup_contact.discretization.segment.norms import sine_coefficients
from infsup_contact.discretization.gamma.quadrature import gauss_legendre_01
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError
from infsup_contact.solvers.spectra import spectrum
from infsup_contact.study.face.edge_dropping import (edge_row, geometry, interface_operator,
                                                kappa_1d, scaled_cond, side_pair)
from infsup_contact.solvers.request import MeshOptions

from helpers.tensor_sides import box_gamma_block, couplings_1d, lagrange_1d, tensor_interface_operator


def _face(case, k, n):
    x = np.linspace(0.0, 1.0, n + 1)
    return registry.case_space(case, k, TensorPartition(x, x), SQUARE)


@pytest.mark.parametrize("k, n, n2", [(1, 2, 4), (2, 2, 3)])
def test_full_cover_equals_the_face_engine(k, n, n2):
    """θ = 1: the study gives the β_h of the full-face engine (membranes3d hexahedra,
    multiplier mesh omega1) for every edge case."""
    from infsup_contact.models.membranes3d import MEMBRANES3D
    from infsup_contact.solvers.infsup import beta_rows_all

    cases = edge_cases(k)
    rows = beta_rows_all("structured", k, n, n2, cases, ("omega1",), model=MEMBRANES3D, mesh=MeshOptions(element="hex"))
    for case in cases:
        mine = edge_row(case, k, n, n2, 1.0)
        ref = {r["norm"]: r["beta"] for r in rows if r["case"] == case}
        assert mine["beta_L2"] == pytest.approx(ref["L2"], rel=1e-10)
        assert mine["beta_H"] == pytest.approx(ref["H"], rel=1e-4)   # two truncated series
        assert mine["dropped"] == 0 and mine["kappa_min"] == pytest.approx(1.0)


@pytest.mark.parametrize("case", ["R5.4", "DUAL-ALL"])
def test_beta_invariant_under_kappa_scaling(case):
    """κ scaling is a diagonal change of basis: β_h (Rayleigh quotient) is unchanged, recomputed
    from scratch on the scaled space, while the conditioning of D changes."""
    k, n, n2, theta = 1, 3, 6, 0.1
    row = edge_row(case, k, n, n2, theta)
    L = geometry(n, n2, theta)[0]
    full = _face(case, k, n)
    scaled = ClippedFace.of(full, L, scale_x=1.0 / kappa_1d(full.sx, L))
    S = interface_operator(scaled, side_pair(k, n, n2, theta))
    for norm in ("L2", "H"):
        beta = spectrum(S, scaled.gram(norm)[0]).beta
        assert beta == pytest.approx(row[f"beta_{norm}"], rel=1e-5)
    assert row["cond_D_kappa"] != pytest.approx(row["cond_D"], rel=1e-3)
    # the scaled-condition route against a direct SVD where the latter is still accurate
    assert row["cond_S_kappa"] == pytest.approx(np.linalg.cond(S), rel=1e-6)
    assert row["cond_G_kappa"] == pytest.approx(np.linalg.cond(scaled.gram("L2")[0]), rel=1e-8)


def test_scaled_cond_against_svd():
    """cond₂(diag(r) A) from the normalized matrix equals the SVD's, rectangular and symmetric."""
    rng = np.random.default_rng(3)
    A = rng.standard_normal((5, 8))
    r = 10.0 ** rng.uniform(-3, 3, 5)
    assert scaled_cond(A, r, False) == pytest.approx(np.linalg.cond(A * r[:, None]), rel=1e-8)
    M = A @ A.T
    assert scaled_cond(M, r, True) == pytest.approx(np.linalg.cond(M * np.outer(r, r)), rel=1e-6)
    assert scaled_cond(A.T @ A, np.ones(8), True) == np.inf     # rank 5 of 8


@pytest.mark.parametrize("case", ["R5.2", "R5.4", "DUAL-ALL", "T4", "T5"])
def test_dimension_counts(case):
    """Cut at a breakpoint j/N: exactly the space of the registry on j cells (x) times N cells
    (y); cut inside the last column (0 < θ < 1): nothing dropped."""
    k, n = 2, 4
    spec = registry.space_spec(case)
    full = _face(case, k, n)
    for j in range(1, n + 1):
        assert ClippedFace.of(full, j / n).dim == spec.dimension(k, j) * spec.dimension(k, n)
    for theta in (0.5, 1e-3):
        assert ClippedFace.of(full, (n - 1 + theta) / n).dim == full.dim


@pytest.mark.parametrize("case", ["R5.2", "R5.4", "DUAL-ALL"])
def test_clipped_functions_are_restrictions(case):
    """On (0, L) the kept functions are the unrestricted ones (pulled back and cut exactly)."""
    k, n, L = 2, 3, (2 + 0.3) / 3
    full = _face(case, k, n)
    sx = full.sx
    clipped, kept = clip_1d(sx, L)
    x = np.linspace(1e-3, L - 1e-3, 97)
    assert np.allclose(clipped.evaluate(x / L), sx.evaluate(x)[:, kept], atol=1e-12)
    d = np.arange(1.0, sx.dim + 1)
    scaled, _ = clip_1d(sx, L, scale=d)
    assert np.allclose(scaled.evaluate(x / L), sx.evaluate(x)[:, kept] * d[kept], atol=1e-12)


def test_kappa_of_hats():
    """Covered fractions of the last two hats (k = 1): θ² at x = 1 and 1/2 + θ − θ²/2 at x_{N−1}
    (∫ of the linear hat over the covered part of its support)."""
    n, theta = 4, 0.3
    kap = kappa_1d(_face("R5.2", 1, n).sx, (n - 1 + theta) / n)
    assert kap[-1] == pytest.approx(theta ** 2, rel=1e-12)
    assert kap[-2] == pytest.approx(0.5 + theta - theta ** 2 / 2, rel=1e-12)
    assert np.allclose(kap[:-2], 1.0)


def test_anisotropic_series_against_direct_sum():
    """partial_gram(aspect = L) equals the truncated series of the rectangle's Dirichlet
    eigenfunctions (2/√L) sin(mπx/L) sin(nπy), coefficients by quadrature on the rectangle."""
    L, n_max = 0.7, 12
    face = ClippedFace.of(_face("R5.4", 1, 3), L)
    t, w = gauss_legendre_01(30)
    def coeffs(space, scale):  # ∫ φ(x) sin(mπx/scale) dx on [0, scale], per interval
        bp = np.asarray(space.breakpoints) * scale
        x = (bp[:-1, None] + np.diff(bp)[:, None] * t).ravel()
        wx = (np.diff(bp)[:, None] * w).ravel()
        m = np.arange(1, n_max + 1)
        return (space.evaluate(x / scale) * wx[:, None]).T @ np.sin(np.pi * np.outer(x, m) / scale)
    cx, cy = coeffs(face.space.sx, L), coeffs(face.space.sy, 1.0)
    m = np.arange(1, n_max + 1)
    lam = np.pi * np.sqrt((m[:, None] / L) ** 2 + m[None, :] ** 2)
    c = (2.0 / np.sqrt(L)) * cx[:, None, :, None] * cy[None, :, None, :]  # (a, b, m, n)
    c = c.reshape(face.dim, n_max, n_max)
    direct = np.einsum("imn,jmn,mn->ij", c, c, 1.0 / lam)
    assert np.allclose(partial_gram(face.space, n_max, aspect=L), direct, rtol=1e-10, atol=1e-14)
    assert np.allclose(sine_coefficients(face.space.sx, m) / np.sqrt(2.0) * L, cx, atol=1e-12)


def test_bad_input():
    with pytest.raises(InputError, match="theta"):
        edge_row("R5.4", 1, 2, 4, 0.0)
    with pytest.raises(InputError, match="L"):
        clip_1d(_face("R5.4", 1, 2).sx, 1.5)


@pytest.mark.parametrize("k, gamma_top", [(1, True), (2, False)])
def test_fast_diagonalization_equals_sparse_lu(k, gamma_top):
    """(K_ff⁻¹)_ΓΓ of a box with a non-cubic, non-uniform grid: the 1D eigen route equals the
    assembled 3D sparse LU route."""
    xs, ys, zs = np.array([0.0, 0.3, 0.55, 0.8]), np.linspace(0.0, 1.0, 4), np.array([1.0, 1.2, 1.7, 2.0])
    a = box_gamma_block(xs, ys, zs, k, gamma_top, route="eig")
    b = box_gamma_block(xs, ys, zs, k, gamma_top, route="lu")
    assert np.allclose(a, b, rtol=1e-10, atol=1e-13 * np.abs(b).max())


@pytest.mark.parametrize("case, k", [("R5.2", 1), ("R5.4", 1), ("T5", 2)])
def test_nodal_twin_spans_the_restriction(case, k):
    """For a nodal basis the space built on the clipped partition and the restricted registry
    space are the same space: equal β_h from the two bases (θ where both pencils are accurate)."""
    from infsup_contact.study.face.edge_dropping import beta_on, nodal_twin

    n, n2, theta = 3, 6, 0.3
    L = geometry(n, n2, theta)[0]
    full = _face(case, k, n)
    twin = nodal_twin(full, L)
    sides = side_pair(k, n, n2, theta)
    def operator(face):
        return interface_operator(face, sides)
    a = beta_on(ClippedFace.of(full, L), full, operator, ("L2", "H"), 1e-7, cut=True)
    b = beta_on(twin, twin.space, operator, ("L2", "H"), 1e-7, cut=False)
    assert twin.dim == ClippedFace.of(full, L).dim
    assert a["beta_L2"] == pytest.approx(b["beta_L2"], rel=1e-8)
    assert a["beta_H"] == pytest.approx(b["beta_H"], rel=1e-4)
    assert a["beta_L2_resolved"] and b["beta_H_resolved"]
    assert nodal_twin(_face("DUAL-ALL", k, n), L) is None


def test_csv_entry(capsys):
    """The module's command line prints one CSV row per (k, N, case, θ)."""
    import csv
    import io

    from infsup_contact.study.face.edge_table import COLUMNS, main

    assert main(["--k", "1", "--N", "2", "--theta", "1", "0.5", "--norm", "L2"]) == 0
    rows = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    assert len(rows) == 2 * len(edge_cases(1)) and tuple(rows[0]) == COLUMNS
    assert all(r["beta_H"] == "" for r in rows)            # H not asked


@pytest.mark.parametrize("k", [1, 2])
def test_ngsolve_route_equals_tensor_route(k):
    """Two independent routes to the same numbers (N = 4, N2 = 8): the production path (NGSolve
    Q_k hexahedra of the boxes, Γ bases evaluated by NGSolve, couplings by tensor Gauss on the
    rectangles) and the 1D Kronecker route of ``helpers.tensor_sides`` (stiffness from 1D matrices,
    fast diagonalization, couplings as products of 1D Gauss sums): β_h in both norms and the
    condition numbers of S and D (D from 1D sums here) in the unscaled and κ-scaled bases. A
    condition number is O(1) only while it is moderate: each route's round-off of S (dim M ε ‖S‖)
    moves λ_min(S) by dim M ε cond relative (ε cond = 4e-6 at cond = 1.9e10: R5.2, k = 2, θ = 0.25);
    so cond_S to the larger of 1e-8 and twice that, not to 1e-8 alone."""
    n, n2 = 4, 8
    for theta in (1.0, 0.25):
        L, xs1, grids = geometry(n, n2, theta)
        t1 = lagrange_1d(xs1, k)
        for case in edge_cases(k):
            ng = edge_row(case, k, n, n2, theta)
            tp = edge_row(case, k, n, n2, theta, operator=lambda f: tensor_interface_operator(f, k, grids))
            for key in ("beta_H", "beta_L2"):
                assert ng[key] == pytest.approx(tp[key], rel=1e-9), (case, theta, key)
            for key in ("cond_S", "cond_S_kappa"):
                roundoff = 2 * ng["dim_M"] * np.finfo(float).eps * tp[key]
                assert ng[key] == pytest.approx(tp[key], rel=max(1e-8, roundoff)), (case, theta, key)
            face = ClippedFace.of(_face(case, k, n), L)
            r = np.sqrt(np.diag(face.gram("L2")[0]))
            D = np.kron(couplings_1d(face, t1, "x", k), couplings_1d(face, t1, "y", k))
            assert ng["cond_D"] == pytest.approx(scaled_cond(D / r[:, None], r, False), rel=1e-9)


def test_narrow_side_mesh():
    """Ω2 = (0, L) × (0, 1) × (1, 2) from MakeStructured3DMesh: its Γ trace is the uniform
    grid of (0, L) × (0, 1) with (N2 k − 1)² dofs and Square(width = L) checks its extent."""
    from infsup_contact.discretization.face.shapes.square import Square
    from infsup_contact.models.membranes3d import subdomain_mesh

    n, n2, theta, k = 2, 3, 0.4, 2
    L = geometry(n, n2, theta)[0]
    side1, side2 = side_pair(k, n, n2, theta)
    assert np.allclose(side2.trace.partition.xs, np.linspace(0.0, L, n2 + 1), atol=1e-15)
    assert np.allclose(side2.trace.partition.ys, np.linspace(0.0, 1.0, n2 + 1), atol=1e-15)
    assert len(side2.trace.gamma_dofs) == (n2 * k - 1) ** 2 == SQUARE.trace_dimension(k, n2)
    assert side1.trace.partition.xs[-1] == 1.0
    with pytest.raises(InputError, match="tensor grid"):
        Square(width=L).partition_of(subdomain_mesh("structured", n2, 2).mesh)
    with pytest.raises(InputError, match="width"):
        subdomain_mesh("structured", n2, 2, width=1.5)


def test_h_cap_bounds_the_series():
    """``h_cap`` bounds n_max of the H series and the capped row says so; a larger cap lowers
    the error estimate."""
    small = edge_row("R5.4", 1, 2, 4, 0.05, norms=("H",), h_cap=64)
    large = edge_row("R5.4", 1, 2, 4, 0.05, norms=("H",), h_cap=4096)
    assert small["n_max"] <= 64 and small["h_capped"]
    assert large["n_max"] > 64 and large["h_rel_error"] < small["h_rel_error"]


# ------------------------------------------------------------------ issue 39, item 5: never θ = 0 silently
def test_theta_below_the_geometry_is_refused():
    """θ = 1e-12 at N = 4 used to drop the cut column whole (dim M 20 instead of 25): β_H 0.55, the
    θ = 0 space, instead of ~θ. Now refused naming theta and the range; the smallest θ allowed
    keeps the column."""
    from infsup_contact.discretization.face.spaces.clipped import min_covered_fraction
    from infsup_contact.study.face.edge_table import edge_plan

    for call in (lambda: edge_row("R5.2", 1, 4, 8, 1e-12), lambda: edge_plan([1], [4], [1.0, 1e-12])):
        with pytest.raises(InputError) as err:
            call()
        assert err.value.key == "theta" and "4e-09 <= θ <= 1" in str(err.value), err.value
    full = _face("R5.2", 1, 4)
    for theta in (min_covered_fraction(4), 1e-6, 0.01):
        assert ClippedFace.of(full, geometry(4, 8, theta)[0]).dim == full.dim   # nothing dropped


@pytest.mark.parametrize("module, argv, flag, allowed", [
    ("face.edge_table", ["--k", "5", "--N", "4"], "--k", "1, 2, 3, 4"),          # was: a header, exit 0
    ("face.edge_table", ["--k", "1", "--N", "4", "--theta", "0.5", "1e-12"], "--theta", "4e-09 <= θ <= 1"),
    ("face.edge_table", ["--k", "2", "--N", "4", "--case", "PWLIN-T6"], "--case", "T3, R5.2"),
    ("face.edge_table", ["--k", "1", "--N", "0"], "--N", ">= 1"),                # was: a traceback
    ("face.edge_table", ["--k", "1", "--N", "4", "--n2-factor", "0"], "--n2-factor", ">= 1"),
    ("face.edge_table", ["--k", "1", "--N", "4", "--norm", "X"], "--norm", "'H', 'L2'"),
    ("face.alpha", ["--N", "0"], "--N", ">= 1"),
    ("face.families", ["--k", "5"], "--k", "1..4"),
    ("face.families", ["--element", "bogus"], "--element", "hex, tet"),
    ("machines.paths", [], "out_dir", "required"),
])
def test_study_command_lines_refuse_in_one_line(module, argv, flag, allowed, capsys):
    """Every study module's ``python -m`` command: impossible input is one line naming the flag
    and the allowed values, exit 2, nothing on stdout (never a header only, never a traceback)."""
    import importlib

    mod = importlib.import_module(f"infsup_contact.study.{module}")
    entry = mod.cli if module == "machines.paths" else mod.main
    try:
        code = entry(argv)
    except SystemExit as exc:  # argparse's own refusals
        code = exc.code
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, (code, out, err)
    assert flag in err and allowed in err and "Traceback" not in err, err
