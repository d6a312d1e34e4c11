"""The face Γ = (0,1)²×{1} as an Interface (issue 28): partitions, quadrature, the trace basis
and the dimension counts, each against an independent route (NGSolve's own evaluation, exact
integrals, numerical ranks)."""
import numpy as np
import ngsolve
import pytest

from infsup_contact.discretization.gamma.interface import Interface
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG, Square
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError
from infsup_contact.models.membranes3d import displacement_space, subdomain_mesh


def grid(n, m=None):
    return TensorPartition(np.linspace(0, 1, n + 1), np.linspace(0, 1, (n if m is None else m) + 1))


def test_square_implements_every_abstract_method():
    assert not Square.__abstractmethods__
    assert isinstance(Square(), Interface) and SQUARE.dim == 2 and SQUARE == Square()
    for name in Interface.__abstractmethods__:
        assert getattr(Square, name) is not getattr(Interface, name), name
    with pytest.raises(InputError, match="quad, trig"):
        Square(cell="hex")


@pytest.mark.parametrize("element,face", [("hex", SQUARE), ("tet", SQUARE_TRIG)])
@pytest.mark.parametrize("side", [1, 2])
def test_partition_of_a_structured_mesh(element, face, side):
    p = face.partition_of(subdomain_mesh("structured", 3, side, element=element).mesh)
    np.testing.assert_allclose(p.xs, np.linspace(0, 1, 4), atol=1e-15)
    np.testing.assert_allclose(p.ys, np.linspace(0, 1, 4), atol=1e-15)
    assert face.cells(p) == 9 and face.partition_key(p) == face.partition_key(grid(3))


def test_a_face_that_is_no_tensor_grid_is_refused():
    mesh = subdomain_mesh("structured", 3, 1).mesh
    ngmesh = mesh.ngmesh
    for p in ngmesh.Points():  # move one interior vertex of Γ (z = 1) along x
        if abs(p[2] - 1) < 1e-12 and abs(p[0] - 1 / 3) < 1e-12 and abs(p[1] - 1 / 3) < 1e-12:
            p[0] = 0.4
    with pytest.raises(InputError, match="tensor grid"):
        SQUARE.partition_of(ngsolve.Mesh(ngmesh))


def test_common_refinement_and_choices():
    p1, p2 = grid(3), grid(4, 2)
    u = SQUARE.multiplier_partition(p1, p2, "union")
    np.testing.assert_allclose(u.xs, np.unique(np.r_[p1.xs, p2.xs]))
    np.testing.assert_allclose(u.ys, np.unique(np.r_[p1.ys, p2.ys]))
    assert SQUARE.multiplier_partition(p1, p2, "omega1") is p1 and SQUARE.multiplier_partition(p1, p2) is p2
    assert SQUARE.cells(u) == (len(u.xs) - 1) * (len(u.ys) - 1)
    for n1, n2 in ((3, 4), (4, 6), (5, 5)):
        for choice in ("omega1", "omega2", "union"):
            part = SQUARE.multiplier_partition(grid(n1), grid(n2), choice)
            assert SQUARE.multiplier_cells(n1, n2, choice) == SQUARE.cells(part)
    with pytest.raises(InputError, match="omega2, omega1, union"):
        SQUARE.multiplier_partition(p1, p2, "both")


@pytest.mark.parametrize("degree", range(0, 6))
def test_quadrature_is_exact(degree):
    p = TensorPartition(np.array([0.0, 0.2, 0.7, 1.0]), np.array([0.0, 0.45, 1.0]))
    x, w = SQUARE.quadrature(p, degree)
    for a in range(degree + 1):  # Q_degree: every x^a y^b with a, b <= degree
        for b in range(degree + 1):
            assert w @ (x[:, 0] ** a * x[:, 1] ** b) == pytest.approx(1 / ((a + 1) * (b + 1)), rel=1e-13)
    xt, wt = SQUARE_TRIG.quadrature(p, degree)  # triangles: total degree 2 degree
    for a in range(2 * degree + 1):
        b = 2 * degree - a
        assert wt @ (xt[:, 0] ** a * xt[:, 1] ** b) == pytest.approx(1 / ((a + 1) * (b + 1)), rel=1e-12)
    # a function with a kink on the diagonals, polynomial on each triangle: |x − y| per cell
    xs, ys = p.xs, p.ys
    ix = np.searchsorted(xs, xt[:, 0]) - 1
    iy = np.searchsorted(ys, xt[:, 1]) - 1
    s = (xt[:, 0] - xs[ix]) / np.diff(xs)[ix] - (xt[:, 1] - ys[iy]) / np.diff(ys)[iy]
    if degree >= 1:  # ∫∫ |u − v| over the unit square, degree 1 on each triangle
        assert wt @ np.abs(s) == pytest.approx(1 / 3, rel=1e-12)


@pytest.mark.parametrize("element,face", [("hex", SQUARE), ("tet", SQUARE_TRIG)])
@pytest.mark.parametrize("k", [1, 2, 3])
def test_trace_basis_is_ngsolves_trace(element, face, k):
    mesh = subdomain_mesh("structured", 2, 2, element=element).mesh
    trace = face.trace(displacement_space(mesh, k))
    assert len(trace.gamma_dofs) == face.trace_dimension(k, 2)
    gf = ngsolve.GridFunction(trace.fes)
    vals = np.zeros(trace.fes.ndof)
    vals[trace.gamma_dofs] = np.random.default_rng(k).standard_normal(len(trace.gamma_dofs))
    gf.vec.FV().NumPy()[:] = vals
    x, _ = face.quadrature(trace.partition, 3)
    ref = np.array([gf(mesh(a, b, 1.0 + 1e-13)) for a, b in x])
    np.testing.assert_allclose(face.trace_basis(trace, x) @ vals[trace.gamma_dofs], ref, atol=1e-10)
    assert face.trace_basis(trace, x) is face.trace_basis(trace, x)  # cached


@pytest.mark.parametrize("element,face", [("hex", SQUARE), ("tet", SQUARE_TRIG)])
@pytest.mark.parametrize("k", [1, 2])
@pytest.mark.parametrize("n1,n2", [(2, 2), (2, 3), (3, 4), (2, 4)])
def test_trace_sum_dimension_is_the_rank_of_both_traces(element, face, k, n1, n2):
    traces = [face.trace(displacement_space(subdomain_mesh("structured", n, side, element=element).mesh, k))
              for n, side in ((n1, 1), (n2, 2))]
    x = np.random.default_rng(1).uniform(size=(6 * (max(n1, n2) * k + 1) ** 2, 2))
    both = np.hstack([face.trace_basis(t, x) for t in traces])
    rank = np.linalg.matrix_rank(both, tol=1e-9 * np.abs(both).max())
    assert face.trace_sum_dimension(k, *(t.partition for t in traces)) == rank
    if n1 == n2:
        assert rank == face.trace_dimension(k, n1)


@pytest.mark.parametrize("degree", [1, 2, 4])
def test_coupling_rule_of_triangles_cuts_the_refinement_by_the_trace_diagonals(degree):
    """On G_h ∪ trace, each rectangle cut by the diagonal of its trace cell: exact for a function
    with a kink on every trace diagonal, |diagonal coordinate| (∬ |u − v| = 1/3 per cell), times
    a polynomial of each variable."""
    from infsup_contact.discretization.face.partitions.quadrature import split_rule

    trace, gh = grid(3), grid(4, 5)
    x, w = split_rule(SQUARE_TRIG.common_refinement(trace, gh), trace, 2 * degree)
    assert w.sum() == pytest.approx(1.0, rel=1e-13)
    ix = np.clip(np.searchsorted(trace.xs, x[:, 0]) - 1, 0, 2)
    iy = np.clip(np.searchsorted(trace.ys, x[:, 1]) - 1, 0, 2)
    u, v = 3 * x[:, 0] - ix, 3 * x[:, 1] - iy  # local coordinates of the trace cell
    assert w @ np.abs(u - v) == pytest.approx(1 / 3, rel=1e-12)
    # ∬ |u − v| u^a du dv = ∫ u^a (u² + (1 − u)²)/2 du = 1/(a+3) − 1/(a+2) + 1/(2(a+1)) per cell
    a = degree - 1
    assert w @ (np.abs(u - v) * u ** a) == pytest.approx(1 / (a + 3) - 1 / (a + 2) + 1 / (2 * (a + 1)), rel=1e-12)


def test_sample_boundary_embed_and_counts():
    p = grid(2, 3)
    x = SQUARE.sample(p, 2)
    assert x.shape == ((2 * 2 + 1) * (3 * 2 + 1), 2) and x.min() == 0 and x.max() == 1
    assert SQUARE.sample(p, 2, upper=1 - 1e-15).max() < 1
    inner = np.array([[0.5, 0.5], [0.1, 0.5], [0.5, 0.95]])
    np.testing.assert_array_equal(SQUARE.at_boundary(grid(3), inner), [False, True, True])
    X, Y, Z = SQUARE.embed(inner)
    np.testing.assert_array_equal(Z, 1.0)
    np.testing.assert_array_equal(X, inner[:, 0])
    assert SQUARE.trace_nodes(2, 3) == 49 and SQUARE.trace_dimension(2, 3) == 25
