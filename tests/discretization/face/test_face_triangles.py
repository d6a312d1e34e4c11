"""P_s multipliers on the triangles of a tensor partition of the face (issue 28): dimensions
against the numerical rank, polynomial reproduction, exact integrals through the L² Gram, the
sine coefficients by two routes, the measured tail exponents, the registry building them on
tetrahedral traces (and only there), and the kernel against the dimension argument."""
import numpy as np
import pandas as pd
import pytest

from infsup_contact.discretization.face.norms import triangles as ftn
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.face.partitions.quadrature import triangles_rule
from infsup_contact.discretization.face.spaces.tensor import FaceSpace
from infsup_contact.discretization.face.spaces.triangles import TriangleSpace
from infsup_contact.discretization.spaces.registry import case_space, common_ids, SPACES
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError
from infsup_contact.models import make_model
from infsup_contact.solvers.side_cache import SideCache
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.contact.contact import contact_qp
from infsup_contact.solvers.request import MeshOptions

FAMILIES = [(1, True, True), (2, True, True), (1, True, False), (3, True, False), (0, False, False),
            (2, False, False)]
PART = TensorPartition(np.array([0.0, 0.3, 0.5, 1.0]), np.array([0.0, 0.2, 0.7, 1.0]))
RNG = np.random.default_rng(28)
MODEL = make_model("membranes3d")


def rank(A, tol=1e-10):
    sv = np.linalg.svd(A, compute_uv=False)
    return int(np.sum(sv > tol * sv[0]))


def poly(c, x):
    """Σ c[a, b] x^a y^b over a + b ≤ s (c upper-left triangular)."""
    s = c.shape[0] - 1
    return sum(c[a, b] * x[:, 0] ** a * x[:, 1] ** b for a in range(s + 1) for b in range(s + 1 - a))


@pytest.mark.parametrize("s,continuous,vanish", FAMILIES)
def test_dimension_is_the_rank_and_polynomials_are_reproduced(s, continuous, vanish):
    space = TriangleSpace(PART, s, continuous, vanish)
    x = RNG.random((40 * space.dim + 400, 2))
    phi = space.evaluate(x)
    assert rank(phi) == space.dim
    if vanish:  # every function vanishes on ∂Γ
        t = RNG.random(20)
        edge = np.vstack([np.c_[t, 0 * t], np.c_[t, 0 * t + 1], np.c_[0 * t, t], np.c_[0 * t + 1, t]])
        assert np.abs(space.evaluate(edge)).max() < 1e-13
        return
    c = RNG.standard_normal((s + 1, s + 1))
    if continuous:  # nodal interpolation reproduces P_s
        coef = poly(c, space.nodes())
    else:  # P_s ⊂ M: least squares leaves no residual
        coef = np.linalg.lstsq(phi, poly(c, x), rcond=None)[0]
    assert np.abs(phi @ coef - poly(c, x)).max() < 1e-11


@pytest.mark.parametrize("s,continuous,vanish", [f for f in FAMILIES if not f[2]])
def test_l2_gram_integrates_polynomials_exactly(s, continuous, vanish):
    space = TriangleSpace(PART, s, continuous, vanish)
    G = ftn.gram_l2_tri(space)
    assert np.linalg.eigvalsh(G).min() > 0
    x = RNG.random((40 * space.dim + 400, 2))
    phi = space.evaluate(x)
    p, q = RNG.standard_normal((2, s + 1, s + 1))
    a, b = (np.linalg.lstsq(phi, poly(c, x), rcond=None)[0] for c in (p, q))
    exact = sum(p[i, j] * q[k, l] / ((i + k + 1) * (j + l + 1)) for i in range(s + 1) for j in range(s + 1 - i)
                for k in range(s + 1) for l in range(s + 1 - k))
    assert a @ G @ b == pytest.approx(exact, rel=1e-12, abs=1e-13)


def test_sine_coefficients_two_routes():
    """Piecewise constants: the two triangles of a rectangle sum to the closed-form 1D product;
    P_2: a generous Duffy rule of the triangles at low frequencies; the inner moments against
    Gauss quadrature across the series/recursion switch."""
    n = np.arange(1, 25)

    def f(a, b):
        return (np.cos(n * np.pi * a) - np.cos(n * np.pi * b)) / (n * np.pi)

    C = ftn.sine_coefficients_chunk(TriangleSpace(PART, 0, False), n, len(n))
    for i in range(3):
        for j in range(3):
            c = 2 * (3 * i + j)
            exact = 2 * np.outer(f(PART.xs[i], PART.xs[i + 1]), f(PART.ys[j], PART.ys[j + 1]))
            assert np.abs(C[c] + C[c + 1] - exact).max() < 1e-14
    space = TriangleSpace(PART, 2, True, False)
    C = ftn.sine_coefficients_chunk(space, n, len(n))
    x, w = triangles_rule(space.triangles(), 60)
    phi = space.evaluate(x)
    for m, k in ((1, 1), (5, 2), (9, 13)):
        ref = 2 * (w * np.sin(m * np.pi * x[:, 0]) * np.sin(k * np.pi * x[:, 1])) @ phi
        assert np.abs(ref - C[:, m - 1, k - 1]).max() < 1e-14
    omega = np.array([0.0, 0.7, 1.999, 2.0, -2.5, 3.999, 4.0, 11.0, -6.0])  # both sides of the series' bound 2
    t, wt = np.polynomial.legendre.leggauss(60)
    t, wt = 0.5 * (t + 1), 0.5 * wt
    ref = np.array([[np.sum(wt * t ** j * np.exp(1j * o * t)) for o in omega] for j in range(5)])
    assert np.abs(np.array(ftn.moments(omega, 4)) - ref).max() < 1e-14


@pytest.mark.parametrize("s,continuous,vanish,dual", [(1, True, True, False), (1, True, False, False),
                                                     (0, False, False, False), (1, True, True, True)])
def test_tail_exponents_are_the_measured_ones(s, continuous, vanish, dual):
    space = TriangleSpace(TensorPartition(np.linspace(0, 1, 3), np.linspace(0, 1, 3)), s, continuous, vanish, dual)
    p = ftn.TAIL_EXPONENTS[ftn.tail_key(space)]
    assert ftn.tail_exponent(space, 32) == pytest.approx(p, abs=0.1)
    G, info = ftn.gram_h_tri(space)
    assert info["tail_exponent"] == p and not info["capped"] and np.linalg.eigvalsh(G).min() > 0


def test_registry_builds_triangles_on_tetrahedral_traces_only():
    grid = TensorPartition(np.linspace(0, 1, 4), np.linspace(0, 1, 4))
    for case in common_ids(2):
        spec = SPACES[case]
        hexes, tets = case_space(case, 2, grid, SQUARE), case_space(case, 2, grid, SQUARE_TRIG)
        assert isinstance(hexes, FaceSpace)
        assert isinstance(tets, TriangleSpace if spec.lagrange else FaceSpace), case
        if spec.lagrange:
            assert (tets.degree, tets.continuous, tets.vanish, tets.dual) == (spec.degree(2), *spec.lagrange, spec.dual)
    with pytest.raises(InputError, match="degree"):
        TriangleSpace(grid, 0, True)


def trace_sum_rank(sides) -> int:
    """dim(W1 + W2) from the rank of both trace bases at common points (independent route)."""
    x = RNG.random((4000, 2))
    gamma = sides[0].trace.gamma
    return rank(np.hstack([gamma.trace_values(s.trace, x) for s in sides]), tol=1e-9)


@pytest.mark.parametrize("k", [1, 2])
@pytest.mark.parametrize("n", [2, 3, 4])
def test_kernel_is_the_dimension_count_on_tetrahedra(k, n):
    """dim ker Bᵀ = dim M − dim(W1 + W2) on matching meshes, for every case, by the engine and by
    the rank of the coupling matrices; dim(W1 + W2) by trace_sum_dimension and by rank."""
    frame = pd.DataFrame(beta_rows("structured", k, n, n, model=MODEL, mesh=MeshOptions(element="tet"), norms=("L2",)))
    sides = SideCache().pair(MODEL, "structured", k, n, n, MeshOptions(element="tet"))
    gamma = sides[0].trace.gamma
    dim_w = gamma.trace_sum_dimension(k, *(s.trace.partition for s in sides))
    assert dim_w == trace_sum_rank(sides)
    for _, row in frame.iterrows():
        space = case_space(row.case, k, sides[1].trace.partition, gamma)
        assert isinstance(space, TriangleSpace) == (SPACES[row.case].lagrange is not None)
        B = np.hstack([coupling_matrix(s.trace, space, k) for s in sides])
        assert row.kernel_decision == "clear"
        assert row.kernel_dim == space.dim - rank(B) >= max(space.dim - dim_w, 0), row.case
        assert (row.beta > 0) == (row.kernel_dim == 0)
        if not isinstance(space, TriangleSpace) or space.continuous or space.degree > k - 2:
            assert row.kernel_dim == max(space.dim - dim_w, 0), row.case
        elif k == 2:  # P_0 against P_2: ∫_T w = |T|/3 Σ_{edge midpoints} w, so the lower/upper
            # checkerboard (equal areas, every interior edge between a lower and an upper triangle)
            # is orthogonal to every trace: one mode beyond the count
            checker = np.tile([1.0, -1.0], space.dim // 2)
            assert np.abs(checker @ B).max() < 1e-12 and row.kernel_dim == max(space.dim - dim_w, 0) + 1


def test_beta_agrees_with_the_saddle_point_pencil_on_triangles():
    """Continuous P_2 vanishing on ∂Γ on the non-matching tetrahedral pair (2, 3): the Γ-reduced
    β_h against the dense pencil [[A, Bᵀ], [B, 0]] x = σ [[A, 0], [0, G]] x, both norms."""

    from infsup_contact.solvers.infsup import saddle_point_beta

    k, n1, n2 = 2, 2, 3
    case = next(c for c in common_ids(k) if SPACES[c].lagrange == (True, True) and SPACES[c].degree(k) == k)
    sides = SideCache().pair(MODEL, "structured", k, n1, n2, MeshOptions(element="tet"))
    gamma = sides[0].trace.gamma
    space = case_space(case, k, sides[1].trace.partition, gamma)
    assert isinstance(space, TriangleSpace)
    Bs = [coupling_matrix(s.trace, space, k) for s in sides]
    A, B, _ = contact_qp(sides, Bs, [np.zeros(s.ndof) for s in sides])  # the assembled pencil's blocks
    B = B.toarray()
    frame = pd.DataFrame(beta_rows("structured", k, n1, n2, model=MODEL, mesh=MeshOptions(element="tet"), cases=[case]))
    for norm, row in frame.set_index("norm").iterrows():
        assert saddle_point_beta(A, B, gamma.gram(space, norm)[0]) == pytest.approx(row.beta, rel=1e-8)


@pytest.mark.parametrize("s,vanish", [(1, False), (1, True), (2, False), (2, True)])
def test_dual_bases_on_triangles(s, vanish):
    """TRI3 / TRI6-transformed duals: dim of the continuous space, Σ ψ = 1 where every triangle
    keeps a live node, TRI3 biorthogonal to the nodal basis, ∫ψ_i N_j = δ_ij ∫N_j; the sine
    coefficients (with the per-triangle Â) against a generous quadrature; tail exponent 2."""
    dual, nodal = TriangleSpace(PART, s, True, vanish, dual=True), TriangleSpace(PART, s, True, vanish)
    assert dual.dim == nodal.dim
    x, w = triangles_rule(dual.triangles(), 2 * s)
    psi, phi = dual.evaluate(x), nodal.evaluate(x)
    assert rank(psi) == dual.dim
    if not vanish or s == 2:  # (a TRI3 corner triangle with its 3 vertices on ∂Γ has no live node)
        assert np.abs(psi.sum(axis=1) - 1).max() < 1e-13
    if s == 1:
        assert np.abs((psi * w[:, None]).T @ phi - np.diag(phi.T @ w)).max() < 1e-15
    n = np.arange(1, 13)
    C = ftn.sine_coefficients_chunk(dual, n, len(n))
    x, w = triangles_rule(dual.triangles(), 40)
    ref = 2 * (w * np.sin(5 * np.pi * x[:, 0]) * np.sin(11 * np.pi * x[:, 1])) @ dual.evaluate(x)
    assert np.abs(ref - C[:, 4, 10]).max() < 1e-14
    assert ftn.TAIL_EXPONENTS[ftn.tail_key(dual)] == 2.0


@pytest.mark.parametrize("k,n1,n2", [(1, 2, 3), (2, 3, 2)])
def test_couplings_on_non_matching_pairs_sum_to_the_trace_integrals(k, n1, n2):
    """Σ_i μ_i = 1 for the Lagrange spaces without the ∂Γ condition, so 1ᵀ B_s = (∫_Γ w_j)_j:
    the coupling on the pieces cut by the diagonals of both grids against the trace's own
    triangles (Square.quadrature of the trace partition, no multiplier involved)."""
    sides = SideCache().pair(MODEL, "structured", k, n1, n2, MeshOptions(element="tet"))
    gamma = sides[0].trace.gamma
    for case in common_ids(k):
        spec = SPACES[case]
        if spec.lagrange is None or spec.lagrange[1] or spec.dual:
            continue
        space = case_space(case, k, sides[1].trace.partition, gamma)
        for s in sides:
            x, w = gamma.quadrature(s.trace.partition, k)
            integrals = gamma.trace_basis(s.trace, x).T @ w
            assert np.abs(coupling_matrix(s.trace, space, k).sum(axis=0) - integrals).max() < 1e-14, case


def test_p0_coupling_by_triangle_triangle_intersections():
    """B[T, j] = ∫_T w_j for P_0 on the triangles T of G_h (k = 2, non-matching 3 / 2): against
    Σ_τ ∫_{T∩τ} w_j over the trace's triangles τ, T∩τ clipped by T's three edges (a different
    decomposition from the rectangles-cut-by-diagonals of the coupling)."""
    from infsup_contact.discretization.face.partitions.quadrature import _clip

    k = 2
    sides = SideCache().pair(MODEL, "structured", k, 3, 2, MeshOptions(element="tet"))
    gamma = sides[0].trace.gamma
    space = TriangleSpace(sides[1].trace.partition, 0, False)
    trace = sides[0].trace
    taus = TriangleSpace(trace.partition, 0, False).triangles()
    B = coupling_matrix(trace, space, k)
    for row, T in enumerate(space.triangles()):
        pieces = []
        for tau in taus:
            poly = tau
            for a in range(3):
                p, q = T[a], T[(a + 1) % 3]
                r = T[(a + 2) % 3]
                side = lambda z: (q[0] - p[0]) * (z[:, 1] - p[1]) - (q[1] - p[1]) * (z[:, 0] - p[0])
                sign = np.sign(side(r[None])[0])
                poly = _clip(poly, sign * side(poly), 1.0) if len(poly) >= 3 else poly
            if len(poly) >= 3:
                pieces += [[poly[0], poly[m], poly[m + 1]] for m in range(1, len(poly) - 1)]
        x, w = triangles_rule(np.array(pieces), k)
        assert np.abs(gamma.trace_basis(trace, x).T @ w - B[row]).max() < 1e-14
