"""Face elements of issue 28: reference shapes, weights, dual and transformed-dual bases, pwlin,
and the cellwise face spaces on tensor grids. Every weight is checked against an exact
rational computation (Vandermonde inverse and monomial integrals in Fractions)."""
from fractions import Fraction as Fr
from math import factorial

import numpy as np
import pytest

from infsup_contact.discretization.gamma.constants import spans_constants
from infsup_contact.discretization.segment.dual import dual_space
from infsup_contact.discretization.face.spaces.dual_bases import (
    SWEEP_ALPHAS, alpha_sweep, dual_coefficients, dual_shapes, mass_matrix, transformation, weights)
from infsup_contact.discretization.face.spaces.reference_elements import (
    ELEMENT_NAMES, cell_quadrature, monomials, pwlin_shapes, pwlin_subelements, reference_element)
from infsup_contact.discretization.face.spaces.cellwise import CellwiseFaceSpace
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError

# the spaces by definition (not read from the module): which ξ^a η^b, a, b <= 2, they contain
SPACE = {
    "QUAD4": {(a, b) for a in range(2) for b in range(2)},
    "QUAD8": {(a, b) for a in range(3) for b in range(3) if a + b <= 2} | {(2, 1), (1, 2)},
    "QUAD9": {(a, b) for a in range(3) for b in range(3)},
    "TRI3": {(a, b) for a in range(2) for b in range(2) if a + b <= 1},
    "TRI6": {(a, b) for a in range(3) for b in range(3) if a + b <= 2},
}
rng = np.random.default_rng(28)


def inside(cell, n=60):
    p = rng.uniform(-1, 1, (n, 2)) if cell == "quad" else rng.dirichlet([1, 1, 1], n)[:, :2]
    return p


# ------------------------------------------------------------------ exact rational reference
def exact_integral(cell, a, b):
    """∫ ξ^a η^b over [−1, 1]² or the unit triangle."""
    if cell == "quad":
        return Fr(0) if a % 2 or b % 2 else Fr(4, (a + 1) * (b + 1))
    return Fr(factorial(a) * factorial(b), factorial(a + b + 2))


def exact_inverse(V):
    n = len(V)
    A = [row[:] + [Fr(int(i == j)) for j in range(n)] for i, row in enumerate(V)]
    for c in range(n):
        p = next(r for r in range(c, n) if A[r][c] != 0)
        A[c], A[p] = A[p], A[c]
        A[c] = [x / A[c][c] for x in A[c]]
        for r in range(n):
            if r != c and A[r][c] != 0:
                A[r] = [x - A[r][c] * y for x, y in zip(A[r], A[c])]
    return [row[n:] for row in A]


def exact_T(el, alpha):
    """Popp's T from the geometry: an edge node is the midpoint of two corners."""
    alpha, n = Fr(alpha), el.n_nodes
    nodes = [tuple(Fr(x) for x in p) for p in el.nodes]
    corners = list(range(3 if el.cell == "tri" else 4))
    T = [[Fr(int(i == j)) for j in range(n)] for i in range(n)]
    for m in range(len(corners), n):
        adj = [c for c in corners if any(
            nodes[m] == tuple((x + y) / 2 for x, y in zip(nodes[c], nodes[d])) for d in corners if d != c)]
        share = alpha if len(adj) == 2 else alpha / 2          # QUAD9 centre: to all 4 corners
        for c in adj:
            T[c][m] += share
        T[m][m] = 1 - 2 * alpha
    return T


def exact_weights(name, alpha=0):
    el = reference_element(name)
    exps = sorted(SPACE[name])
    Vinv = exact_inverse([[Fr(x) ** a * Fr(y) ** b for a, b in exps] for x, y in el.nodes])
    d = [sum(exact_integral(el.cell, a, b) * Vinv[m][k] for m, (a, b) in enumerate(exps))
         for k in range(el.n_nodes)]
    T = exact_T(el, alpha)
    return [sum(T[k][j] * d[j] for j in range(el.n_nodes)) for k in range(el.n_nodes)]


# ------------------------------------------------------------------ reference elements
@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_kronecker_and_partition_of_unity(name):
    el = reference_element(name)
    assert np.allclose(el.shapes(el.nodes), np.eye(el.n_nodes), atol=1e-13)
    assert np.allclose(el.shapes(inside(el.cell)).sum(1), 1.0, atol=1e-13)


@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_reproduces_exactly_its_space(name):
    el, p = reference_element(name), inside(reference_element(name).cell)
    N = el.shapes(p)
    for a in range(3):
        for b in range(3):
            interp = N @ (el.nodes[:, 0] ** a * el.nodes[:, 1] ** b)
            assert np.allclose(interp, p[:, 0] ** a * p[:, 1] ** b, atol=1e-12) == ((a, b) in SPACE[name])


def test_quad8_is_the_textbook_serendipity_element():
    el = reference_element("QUAD8")
    p = inside("quad")
    N, x, y = el.shapes(p), p[:, :1], p[:, 1:]
    cx, cy = el.nodes[:4, 0], el.nodes[:4, 1]
    corner = 0.25 * (1 + x * cx) * (1 + y * cy) * (x * cx + y * cy - 1)
    assert np.allclose(N[:, :4], corner, atol=1e-13)
    ex, ey = el.nodes[4:, 0], el.nodes[4:, 1]
    edge = np.where(ex == 0, 0.5 * (1 - x ** 2) * (1 + y * ey), 0.5 * (1 - y ** 2) * (1 + x * ex))
    assert np.allclose(N[:, 4:], edge, atol=1e-13)


@pytest.mark.parametrize("cell", ["quad", "tri"])
@pytest.mark.parametrize("degree", range(7))
def test_cell_quadrature_exact(cell, degree):
    pts, w = cell_quadrature(cell, degree)
    for a in range(degree + 1):
        b = degree - a
        assert np.isclose(w @ (pts[:, 0] ** a * pts[:, 1] ** b), float(exact_integral(cell, a, b)),
                          rtol=0, atol=1e-14)


# ------------------------------------------------------------------ weights, duals, transform
@pytest.mark.parametrize("name", ELEMENT_NAMES)
@pytest.mark.parametrize("alpha", [0, Fr(1, 5), Fr(1, 3)])
def test_weights_match_exact_rational_integrals(name, alpha):
    exact = np.array([float(v) for v in exact_weights(name, alpha)])
    assert np.allclose(weights(name, float(alpha)), exact, rtol=0, atol=1e-14)
    assert np.isclose(exact.sum(), reference_element(name).area)


def test_quoted_weights_against_the_exact_computation():
    """The literature's numbers (on [−1, 1]², area 4, and the unit triangle, area 1/2)."""
    assert exact_weights("QUAD8") == [Fr(-1, 3)] * 4 + [Fr(4, 3)] * 4
    assert exact_weights("TRI6") == [0] * 3 + [Fr(1, 6)] * 3
    assert exact_weights("QUAD9") == [Fr(1, 9)] * 4 + [Fr(4, 9)] * 4 + [Fr(16, 9)]
    assert exact_weights("QUAD8", Fr(1, 5)) == [Fr(1, 5)] * 4 + [Fr(4, 5)] * 4
    assert exact_weights("TRI6", Fr(1, 5)) == [Fr(1, 15)] * 3 + [Fr(1, 10)] * 3


@pytest.mark.parametrize("name", ["QUAD8", "TRI6"])
def test_mass_matrix_exact(name):
    el = reference_element(name)
    exps = sorted(SPACE[name])
    Vinv = exact_inverse([[Fr(x) ** a * Fr(y) ** b for a, b in exps] for x, y in el.nodes])
    mono = [[exact_integral(el.cell, a + c, b + d) for c, d in exps] for a, b in exps]
    M = [[sum(Vinv[m][k] * mono[m][q] * Vinv[q][l] for m in range(len(exps)) for q in range(len(exps)))
          for l in range(el.n_nodes)] for k in range(el.n_nodes)]
    assert np.allclose(mass_matrix(name), np.array(M, dtype=float), rtol=0, atol=1e-14)


@pytest.mark.parametrize("name, transformed", [("QUAD4", False), ("QUAD9", False), ("TRI3", False),
                                               ("QUAD8", True), ("TRI6", True), ("QUAD9", True)])
def test_biorthogonality_on_the_reference_cell(name, transformed):
    el = reference_element(name)
    pts, w = el.quadrature(2 * el.total_degree + 2)           # another rule than the module's
    alpha = 0.2 if transformed else 0.0
    Nt = el.shapes(pts) @ transformation(name, alpha).T
    psi = dual_shapes(name, pts, transformed, alpha)
    d = Nt.T @ w
    assert np.allclose((psi * w[:, None]).T @ Nt, np.diag(d), atol=1e-13)
    assert np.allclose(psi.sum(1), 1.0, atol=1e-12)


@pytest.mark.parametrize("name, alpha", [("QUAD8", None), ("TRI6", None), ("QUAD8", 0.1), ("TRI6", 0.0)])
def test_non_positive_weights_refused(name, alpha):
    with pytest.raises(InputError) as err:
        dual_coefficients(name) if alpha is None else dual_coefficients(name, True, alpha)
    assert name in str(err.value) and ("transformed=True" in str(err.value)) == (alpha is None)


@pytest.mark.parametrize("name", ["QUAD8", "TRI6", "QUAD9"])
@pytest.mark.parametrize("alpha", SWEEP_ALPHAS)
def test_transformation_keeps_unity_and_span(name, alpha):
    el = reference_element(name)
    T = transformation(name, alpha)
    p = inside(el.cell)
    N, Nt = el.shapes(p), el.shapes(p) @ T.T
    assert np.allclose(Nt.sum(1), 1.0, atol=1e-13)
    assert np.isclose(np.linalg.det(T), (1 - 2 * alpha) ** (el.n_nodes - len(el.corners)))
    assert np.linalg.matrix_rank(np.hstack([N, Nt]), tol=1e-9) == el.n_nodes
    assert np.allclose(T, np.eye(el.n_nodes)) == (alpha == 0)
    with pytest.raises(InputError):
        transformation(name, 0.5)


@pytest.mark.parametrize("name", ["QUAD8", "TRI6"])
def test_alpha_sweep_rows(name):
    for row in alpha_sweep(name):
        exact = [float(v) for v in exact_weights(name, Fr(row["alpha"]))]
        assert np.isclose(row["min_weight"], min(exact), atol=1e-14)
        assert row["positive"] == (min(exact) > 1e-12)
        A = np.diag(row["weights"]) @ np.linalg.inv(mass_matrix(name, row["alpha"]))
        assert np.isinf(row["cond"]) if min(map(abs, exact)) < 1e-12 else np.isclose(row["cond"], np.linalg.cond(A))


# ------------------------------------------------------------------ pwlin
@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_pwlin_basis(name):
    el = reference_element(name)
    used = sorted({k for _, nodes in pwlin_subelements(name) for k in nodes})
    assert used == list(range(el.n_nodes))
    p = inside(el.cell, 200)
    Phi = pwlin_shapes(name, p)
    assert Phi.shape == (len(p), el.n_nodes) and np.allclose(Phi.sum(1), 1.0, atol=1e-13)
    assert np.allclose(pwlin_shapes(name, el.nodes), np.eye(el.n_nodes), atol=1e-13)
    for a, b in [(1, 0), (0, 1)]:                                 # P1 is reproduced
        assert np.allclose(Phi @ (el.nodes[:, 0] ** a * el.nodes[:, 1] ** b), p[:, 0] ** a * p[:, 1] ** b)
    # continuity: both sides of every sub-element edge agree
    for _, nodes in pwlin_subelements(name):
        c = el.nodes[list(nodes)]
        for k in range(len(c)):
            mid, e = 0.5 * (c[k] + c[(k + 1) % len(c)]), c[(k + 1) % len(c)] - c[k]
            nrm = 1e-7 * np.array([-e[1], e[0]])
            q = np.array([mid + nrm, mid - nrm])
            ok = np.all(np.abs(q) <= 1, 1) if el.cell == "quad" else (q.min(1) >= 0) & (q.sum(1) <= 1)
            if ok.all():
                v = pwlin_shapes(name, q)
                assert np.allclose(v[0], v[1], atol=1e-5)


# ------------------------------------------------------------------ face spaces on grids
GRID = TensorPartition(np.array([0.0, 0.3, 0.55, 1.0]), np.array([0.0, 0.45, 1.0]))
NX, NY = 3, 2
DIMS = {"QUAD4": ((NX + 1) * (NY + 1), (NX - 1) * (NY - 1)),
        "QUAD8": ((2 * NX + 1) * (2 * NY + 1) - NX * NY, (2 * NX - 1) * (2 * NY - 1) - NX * NY),
        "QUAD9": ((2 * NX + 1) * (2 * NY + 1), (2 * NX - 1) * (2 * NY - 1))}


@pytest.mark.parametrize("name", ["QUAD4", "QUAD8", "QUAD9"])
@pytest.mark.parametrize("vanish", [False, True])
def test_dimensions(name, vanish):
    for basis in ["standard", "transformed_dual", "pwlin"]:
        assert CellwiseFaceSpace(GRID, name, basis, vanish_on_boundary=vanish).dim == DIMS[name][vanish]
    square = TensorPartition(np.linspace(0, 1, 4), np.linspace(0, 1, 4))
    n = 3
    full = {"QUAD4": (n + 1) ** 2, "QUAD8": (2 * n + 1) ** 2 - n ** 2, "QUAD9": (2 * n + 1) ** 2}[name]
    assert CellwiseFaceSpace(square, name).dim == full


@pytest.mark.parametrize("name", ["QUAD4", "QUAD8", "QUAD9"])
def test_gram_integrates_polynomials_exactly(name):
    S = CellwiseFaceSpace(GRID, name)
    pts, w = S.quadrature(8)
    Phi = S.evaluate(pts)
    G, ones = (Phi * w[:, None]).T @ Phi, Phi.T @ w
    X = S.nodes()
    top = max(SPACE[name], key=lambda e: (sum(e), e))              # xy, x²y, x²y²
    coef = {(0, 0): 0.5, (1, 0): -1.0, (0, 1): 2.0, top: 3.0}       # p = Σ c x^a y^b
    c = sum(v * X[:, 0] ** a * X[:, 1] ** b for (a, b), v in coef.items())
    ip = sum(v / ((a + 1) * (b + 1)) for (a, b), v in coef.items())
    ip2 = sum(u * v / ((a + c_ + 1) * (b + d + 1)) for (a, b), u in coef.items() for (c_, d), v in coef.items())
    assert np.isclose(ones @ c, ip, rtol=1e-13) and np.isclose(c @ G @ c, ip2, rtol=1e-13)


@pytest.mark.parametrize("name, dual, primal", [("QUAD4", "dual", "standard"), ("QUAD9", "dual", "standard"),
                                                ("QUAD8", "transformed_dual", "transformed"),
                                                ("QUAD9", "transformed_dual", "transformed")])
@pytest.mark.parametrize("vanish", [False, True])
def test_global_biorthogonality_and_constants(name, dual, primal, vanish):
    Psi = CellwiseFaceSpace(GRID, name, dual, vanish_on_boundary=vanish)
    Phi = CellwiseFaceSpace(GRID, name, primal, vanish_on_boundary=vanish)
    assert np.allclose(Psi.nodes(), Phi.nodes())
    pts, w = Psi.quadrature(8)
    B = (Psi.evaluate(pts) * w[:, None]).T @ Phi.evaluate(pts)
    assert np.allclose(B, np.diag(Phi.evaluate(pts).T @ w), atol=1e-13)
    assert spans_constants(Psi) and spans_constants(Phi) != vanish
    plain = CellwiseFaceSpace(GRID, name, dual, vanish_on_boundary=vanish, keep_constants=False)
    assert spans_constants(plain) != vanish


def test_quad4_boundary_dual_is_the_tensor_product_of_the_1d_dual():
    S = CellwiseFaceSpace(GRID, "QUAD4", "dual", vanish_on_boundary=True)
    dx, dy = dual_space(GRID.xs, 1, True), dual_space(GRID.ys, 1, True)
    p = rng.uniform(0, 1, (300, 2))
    kron = np.einsum("pi,pj->pij", dx.evaluate(p[:, 0]), dy.evaluate(p[:, 1])).reshape(len(p), -1)
    order = [np.flatnonzero(np.isclose(np.repeat(dx.nodes(), dy.dim), x) & np.isclose(np.tile(dy.nodes(), dx.dim), y))[0]
             for x, y in S.nodes()]
    assert np.allclose(S.evaluate(p), kron[:, order], atol=1e-12)


def test_refusals():
    with pytest.raises(InputError):
        CellwiseFaceSpace(GRID, "TRI6")
    with pytest.raises(InputError):
        CellwiseFaceSpace(GRID, "QUAD4", "mortar")
    with pytest.raises(InputError, match="QUAD8"):
        CellwiseFaceSpace(GRID, "QUAD8", "dual")


@pytest.mark.parametrize("name", ["QUAD4", "QUAD8", "QUAD9"])
@pytest.mark.parametrize("basis", ["standard", "transformed", "pwlin"])
def test_continuous_bases_are_continuous_across_cells(name, basis):
    S = CellwiseFaceSpace(GRID, name, basis)
    assert spans_constants(S)
    t, eps = rng.uniform(0, 1, 20), 1e-9
    for x in GRID.xs[1:-1]:
        left, right = np.column_stack([np.full(20, x - eps), t]), np.column_stack([np.full(20, x + eps), t])
        assert np.allclose(S.evaluate(left), S.evaluate(right), atol=1e-7)
    for y in GRID.ys[1:-1]:
        below, above = np.column_stack([t, np.full(20, y - eps)]), np.column_stack([t, np.full(20, y + eps)])
        assert np.allclose(S.evaluate(below), S.evaluate(above), atol=1e-7)


@pytest.mark.parametrize("name", ELEMENT_NAMES)
def test_monomials_are_each_power_product_bit_for_bit(name):
    """monomials makes each distinct power of a coordinate once and gathers it: every column is
    ξ^a η^b of the direct elementwise powers, bit for bit (edges, the corners, random points)."""
    el = reference_element(name)
    rng = np.random.default_rng(7)
    pts = np.vstack([rng.uniform(-1.0, 1.0, (500, 2)), el.nodes, [[0.0, -0.0], [1e-300, -1e100]]])
    got = monomials(el.exponents, pts)
    assert got.shape == (len(pts), len(el.exponents))
    for j, (a, b) in enumerate(el.exponents):
        want = pts[:, 0] ** np.full(len(pts), a) * pts[:, 1] ** np.full(len(pts), b)
        assert np.array_equal(got[:, j], want, equal_nan=True)
