"""The face Γ = (0, 1)² traced by unstructured and perturbed tetrahedral meshes (issue 28, item 1):
general triangulations, their common refinement by polygon clipping (shapely), P_s multiplier
spaces on any triangulation and their exact Gram matrices.

Every check is a mathematical property or two independent routes agreeing: the structured Kuhn
triangles through the general route against the structured route of :mod:`.face_triangles`."""
from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from infsup_contact.discretization.face.norms import triangles as ftn
from infsup_contact.discretization.face.norms import unstructured as tf
from infsup_contact.discretization.face.spaces.triangles import TriangleSpace
from infsup_contact.discretization.face.spaces.unstructured import MeshTriangleSpace, mesh_space
from infsup_contact.discretization.spaces.registry import SPACES, case_space
from infsup_contact.discretization.face.shapes.square import SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.discretization.face.shapes.triangulated_square import TRIANGULATED
from infsup_contact.discretization.face.partitions.triangulation import Triangulation, barycentric, locate, overlay
from infsup_contact.errors import InputError
from infsup_contact.models import make_model
from infsup_contact.models import membranes3d
from infsup_contact.solvers.side_cache import SideCache
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.request import MeshOptions

MODEL = make_model("membranes3d")
GENERAL = dataclasses.replace(MODEL, side_operator=lambda mesh, k: membranes3d.side_operator(mesh, k, gamma=TRIANGULATED))
"""The structured meshes read through the general triangulated face (the second route)."""


def rank(A, tol=1e-10):
    sv = np.linalg.svd(A, compute_uv=False)
    return int(np.sum(sv > tol * sv[0]))


@pytest.fixture(scope="module")
def unstructured():
    """Traces of the unstructured pair N1 = 3, N2 = 4 (Netgen, non-matching)."""
    return [TRIANGULATED.partition_of(membranes3d.subdomain_mesh("unstructured", n, side, element="tet").mesh)
            for n, side in ((3, 1), (4, 2))]


def test_unstructured_faces_do_not_match_and_tile_the_square(unstructured):
    a, b = unstructured
    assert a.areas.sum() == pytest.approx(1.0, abs=1e-13) and b.areas.sum() == pytest.approx(1.0, abs=1e-13)
    assert np.all(a.areas > 0) and np.all(b.areas > 0)
    assert a.key != b.key


def test_common_refinement_areas_and_parents(unstructured):
    """The overlay's triangles tile Γ (areas sum to 1) and each lies in exactly one triangle of
    each side: its recorded parent contains its vertices, no other triangle contains its centroid."""
    a, b = unstructured
    r = overlay(a, b)
    assert r.areas.sum() == pytest.approx(1.0, abs=1e-12) and np.all(r.areas > 0)
    centroid = r.corners.mean(axis=1)
    for side, tri in enumerate((a, b)):
        parent = r.parents[:, side]
        lam = np.stack([barycentric(tri.corners[parent[t]][None], r.corners[t])[:, 0] for t in range(r.cells)])
        assert lam.min() > -1e-10
        inside = barycentric(tri.corners, centroid).min(axis=2) > 1e-10  # (refined, tri)
        assert np.all(inside.sum(axis=1) == 1) and np.all(inside[np.arange(r.cells), parent])
    # the refinement of a triangulation with itself is itself (areas, cells)
    same = overlay(a, a)
    assert same.cells == a.cells and np.allclose(np.sort(same.areas), np.sort(a.areas))


@pytest.mark.parametrize("degree", [1, 2, 4, 6])
def test_quadrature_on_the_refinement_is_exact(unstructured, degree):
    """∫_Γ x^a y^b = 1/((a + 1)(b + 1)) for a + b ≤ degree, on the refinement of the pair."""
    x, w = TRIANGULATED.quadrature(TRIANGULATED.common_refinement(*unstructured), degree)
    for a in range(degree + 1):
        for b in range(degree + 1 - a):
            assert w @ (x[:, 0] ** a * x[:, 1] ** b) == pytest.approx(1.0 / ((a + 1) * (b + 1)), abs=1e-14)


@pytest.mark.parametrize("k", [1, 2])
def test_trace_dimensions_are_ngsolves(k):
    """dim W_h (P_k lattice nodes off ∂Γ) = NGSolve's free Γ dofs; on the pair, dim(W1 + W2) =
    trace_sum_dimension = the rank of both trace bases at common points (non-matching: W1 ∩ W2 = 0)."""
    sides = SideCache().pair(MODEL, "unstructured", k, 2, 3, MeshOptions(element="tet"))
    gamma = sides[0].trace.gamma
    assert gamma is TRIANGULATED
    for s in sides:
        assert len(s.trace.gamma_dofs) == gamma.trace_dimension_of(k, s.trace.partition)
    for s, n, side in zip(sides, (2, 3), (1, 2)):  # natural lateral faces: ∂Γ's nodes are free too
        mesh = membranes3d.subdomain_mesh("unstructured", n, side, element="tet")
        free = membranes3d.side_operator(mesh, k, dirichlet=membranes3d.FAR, gamma=TRIANGULATED)
        assert len(free.trace.gamma_dofs) == gamma.trace_dimension_of(k, s.trace.partition, clamped=False)
    x = np.random.default_rng(28).random((3000, 2))
    both = np.hstack([gamma.trace_values(s.trace, x) for s in sides])
    assert gamma.trace_sum_dimension(k, *(s.trace.partition for s in sides)) == rank(both, 1e-9)


@pytest.mark.parametrize("s,continuous,vanish,dual", [(1, True, True, False), (1, True, False, False),
                                                      (0, False, False, False), (2, True, False, False),
                                                      (1, True, True, True), (2, True, True, True)])
def test_general_spaces_are_the_structured_ones(s, continuous, vanish, dual):
    """On the Kuhn triangles of a tensor grid, MeshTriangleSpace spans the TriangleSpace functions
    (same dimension, equal up to a permutation of the basis), and the sine coefficients (closed-form
    Fourier transform per triangle) equal the structured route's (factorised Duffy rule): the
    partial H Grams agree to round-off."""
    grid = TensorPartition(np.array([0.0, 0.3, 0.5, 1.0]), np.array([0.0, 0.2, 0.7, 1.0]))
    old = TriangleSpace(grid, s, continuous, vanish, dual)
    tri = Triangulation(old.triangles().reshape(-1, 2), np.arange(3 * len(old.triangles())).reshape(-1, 3))
    from infsup_contact.discretization.face.partitions.triangulation import from_elements

    new = mesh_space(from_elements(old.triangles()), s, continuous, vanish, dual)
    assert tri.cells == new.breakpoints.cells and new.dim == old.dim
    x = np.random.default_rng(1).random((500, 2))
    A, B = old.evaluate(x), new.evaluate(x)
    P, *_ = np.linalg.lstsq(B, A, rcond=None)
    assert np.abs(B @ P - A).max() < 1e-12 and np.allclose(np.abs(P).sum(axis=0), 1.0)
    Gs, Gg = ftn.partial_gram(old, 40), tf.partial_gram(new, 40)
    assert np.abs(P.T @ Gg @ P - Gs).max() < 1e-13 * np.abs(Gs).max()
    assert np.abs(P.T @ tf.gram_l2(new) @ P - ftn.gram_l2_tri(old)).max() < 1e-15


@pytest.mark.parametrize("s,continuous,vanish,dual", [(0, False, False, False), (1, True, True, True),
                                                      (2, True, False, False)])
def test_sine_coefficients_against_quadrature(unstructured, s, continuous, vanish, dual):
    """The closed-form coefficients on a Netgen face against a Duffy rule of degree 44 (exact to
    round-off for these frequencies) of 2 ∬ φ sin(mπx) sin(nπy)."""
    space = mesh_space(unstructured[1], s, continuous, vanish, dual)
    n = np.arange(1, 13, dtype=float)
    C = tf.sine_coefficients(space, n, n)
    x, w = tf.triangles_rule(space.triangles(), 44)
    phi = space.evaluate(x)
    for a, b in ((0, 0), (4, 10), (11, 2)):
        ref = 2 * (w * np.sin((a + 1) * np.pi * x[:, 0]) * np.sin((b + 1) * np.pi * x[:, 1])) @ phi
        assert np.abs(ref - C[:, a, b]).max() < 1e-14


@pytest.mark.parametrize("k", [1, 2])
def test_general_route_gives_the_structured_beta(k):
    """Two routes to β_h on the structured non-matching pair (2, 3): the traces read as general
    triangulations (shapely overlay, NGSolve point location, P_s on any triangles, Fourier
    coefficients) against the structured face; every Lagrange case and the dual, both norms."""
    cases = [c for c in ("T3", "R5.2", "R5.4", "T5", "DUAL") if SPACES[c].valid_for(k)]
    rows = {}
    for name, model in (("structured", MODEL), ("general", GENERAL)):
        # the H series of the continuous nodal cases only (the others' are long; their partial sums
        # are compared in test_general_spaces_are_the_structured_ones)
        split = [(cases, ("L2",)), (cases[:2], ("H",))]
        frames = [r for c, norms in split
                  for r in beta_rows("structured", k, 2, 3, cases=c, model=model, mesh=MeshOptions(element="tet"), norms=norms)]
        rows[name] = pd.DataFrame(frames).set_index(["case", "norm"])
    a, b = rows["structured"], rows["general"]
    assert (a.kernel_dim == b.kernel_dim).all() and (a.dim_M == b.dim_M).all()
    # the general count bounds dim(W1 + W2) from above (W1 ∩ W2 from matched triangles only)
    assert (b.dim_W >= a.dim_W).all() and (b.structural_kernel_dim <= b.kernel_dim).all()
    assert np.allclose(a.beta, b.beta, rtol=1e-8, atol=1e-12)


@pytest.mark.parametrize("k", [1, 2])
def test_unstructured_kernels_and_beta(k):
    """Non-matching unstructured pairs: the kernel of every case, decided clearly from Bᵀ, is the
    proven count max(global count, corner count) (TriangulatedSquare.proven_kernel); the corner
    count is positive somewhere (the global one alone would miss those modes); β_L² > 0 exactly
    where there is no kernel, and for T3 and the dual basis."""
    cases = [c for c in ("T3", "R5.2", "T4", "R5.4", "T5", "DUAL") if SPACES[c].valid_for(k)]
    frame = pd.DataFrame(beta_rows("unstructured", k, 3, 4, cases=cases, model=MODEL, mesh=MeshOptions(element="tet"), norms=("L2",)))
    for _, row in frame.iterrows():
        assert row.kernel_decision == "clear"
        assert row.kernel_dim == row.structural_kernel_dim and row.kernel_check == "agree", row.case
        assert (row.beta > 0) == (row.kernel_dim == 0)
    beyond = frame.structural_kernel_dim > np.maximum(frame.dim_M - frame.dim_W, 0)
    assert beyond.any() or k == 1  # at k = 2 the corner modes of R5.2 / R5.4
    stable = frame.set_index("case").loc[["T3", "DUAL"]]
    assert (stable.kernel_dim == 0).all() and (stable.beta > 0).all()


def test_bad_inputs():
    with pytest.raises(InputError, match="family"):
        membranes3d.subdomain_mesh("curved", 2, 1, element="tet")
    with pytest.raises(InputError, match="element"):
        membranes3d.subdomain_mesh("unstructured", 2, 1, element="hex")
    with pytest.raises(InputError, match="alpha"):
        membranes3d.subdomain_mesh("perturbed", 2, 1, element="tet", alpha=0.5)
    part = TRIANGULATED.partition_of(membranes3d.subdomain_mesh("unstructured", 2, 1, element="tet").mesh)
    with pytest.raises(InputError, match="case"):
        case_space("DUAL-Q9", 2, part, TRIANGULATED)
    with pytest.raises(InputError, match="points"):
        locate(part, np.array([[1.5, 0.5]]))
    assert isinstance(case_space("T3", 2, part, TRIANGULATED), MeshTriangleSpace)
    with pytest.raises(InputError, match="not empty"):  # N = 2: no vertex inside Γ
        case_space("T3", 1, part, TRIANGULATED)
    assert SQUARE_TRIG.cells(part) == 0  # the structured face refuses a general triangulation


def _points(mesh):
    return np.array([mesh[v].point for v in mesh.vertices])


@pytest.mark.parametrize("element", ["tet", "hex"])
def test_perturbed_meshes_are_seeded_and_keep_the_planes(element):
    """Same seed, same mesh; another seed, another; every vertex within α h (per coordinate) of
    the structured one, on the same box planes; the hexahedra's face stays the tensor grid."""
    n, alpha = 3, 0.2
    base = _points(membranes3d.subdomain_mesh("structured", n, 1, element=element).mesh)
    a, b, c = (_points(membranes3d.subdomain_mesh("perturbed", n, 1, element=element, seed=s).mesh) for s in (5, 5, 6))
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    d = a - base
    assert np.abs(d).max() <= alpha / n and np.abs(d).max() > 0
    on_plane = np.abs(base - np.rint(base)) < 1e-12
    assert np.all(d[on_plane] == 0.0)
    face = membranes3d.subdomain_mesh("perturbed", n, 1, element=element, seed=5).interface
    assert (face is TRIANGULATED) == (element == "tet")


def test_perturbed_matching_pair_counts_are_exact():
    """N1 = N2: both perturbed faces are the same triangulation (shifts drawn from (seed, N));
    dim(W1 + W2) = dim W, the kernel of every continuous case is dim M − dim W exactly."""
    k, n = 1, 3
    sides = SideCache().pair(MODEL, "perturbed", k, n, n, MeshOptions(element="tet", seed=2))
    p1, p2 = (s.trace.partition for s in sides)
    assert p1.key == p2.key
    assert TRIANGULATED.trace_sum_dimension(k, p1, p2) == TRIANGULATED.trace_dimension_of(k, p1)
    frame = pd.DataFrame(beta_rows("perturbed", k, n, n, cases=["T3", "R5.2", "DUAL"], model=MODEL,
                                   mesh=MeshOptions(element="tet", seed=2), norms=("L2",)))
    assert (frame.kernel_dim == frame.structural_kernel_dim).all() and (frame.kernel_check == "agree").all()


def test_sample_and_boundary_cells(unstructured):
    """sample(·, 1) is the vertex set, sample(·, 2) adds one midpoint per edge (Euler: E = V + T − 1);
    at_boundary marks exactly the points of triangles with a vertex on ∂Γ."""
    tri = unstructured[0]
    v = TRIANGULATED.sample(tri, 1)
    assert len(v) == len(tri.points)
    assert len(TRIANGULATED.sample(tri, 2)) == len(v) + (len(v) + tri.cells - 1)
    centroids = tri.corners.mean(axis=1)
    touching = np.any((tri.corners < 1e-12) | (tri.corners > 1 - 1e-12), axis=(1, 2))
    assert np.array_equal(TRIANGULATED.at_boundary(tri, centroids), touching)
