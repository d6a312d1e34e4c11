"""Properties every registered multiplier space has, for several N (not a catalogue of today's ids:
a space added to the registry is checked by the same tests).

For each entry of the registry, on each Γ it is defined on (the segment; the face with each cell
shape it pairs with) and each valid k up to 2 (3 on the segment):

* the built dimension equals the registry's count (on the face: the count itself for a face-only
  entry, its square for a tensor product of the segment's space on rectangles);
* the kernel on matching meshes — the multipliers μ with ∫_Γ μ w = 0 for every trace w of the
  displacements, W_h = continuous degree-k Lagrange functions vanishing on ∂Γ on the same cells —
  is at least dim M_h − dim W_h, the count of the pigeonhole argument behind Rem 5.2 / Rem 5.4;
  it is exactly the registry's structural kernel where the registry states one, and 0 for an entry
  declared stable (β_h > 0 needs it) on the segment and as a tensor product on rectangles
  (rank(B ⊗ B) = rank(B)²; on triangles a stable 1D case can have zero modes: T4 at k = 2 has one
  on a 2 × 2 grid, as ``beta --model membranes3d --element tet`` reports);
* the space lives on its partition: every basis function, sampled inside each cell of the
  partition it declares (``pieces`` where the basis is polynomial only on a refinement, 4C's
  pwlin), is one polynomial of the entry's degree there (P_s on intervals and triangles, Q_s on
  rectangles), to a least-squares residual below 1e-9 of its size.

An entry that refuses its construction on a face (a dual basis with a weight ≤ 0) is checked to
refuse in one line naming the remedy (``use case …``).
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.discretization.face.shapes.serendipity import face_of, tensor_modes
from infsup_contact.discretization.face.shapes.square import CELL_SHAPES
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError

SEGMENT_N = (2, 3, 5)
FACE_N = (2, 3)
RESIDUAL = 1e-9
"""Relative least-squares residual below which a sampled function is taken as a polynomial
(round-off of evaluating and fitting degree ≤ 4 on a cell is ~1e-13)."""
RANK_TOL = 1e-10
"""Singular values below this times the largest one count as zero in the coupling's rank (the
entries are integrals of products of O(1) functions over cells of size ≥ 1/25: exact quadrature,
round-off ~1e-15)."""


def _cases():
    """(id, Γ name, k, N) for every registered id on every Γ it is defined on."""
    out = []
    for case, spec in SPACES.items():
        if spec.defined_on(1):
            out += [pytest.param(case, "segment", k, n, id=f"{case}-segment-k{k}-N{n}")
                    for k in range(spec.min_k, 4) for n in SEGMENT_N]
        if spec.defined_on(2):
            out += [pytest.param(case, cell, k, n, id=f"{case}-{cell}-k{k}-N{n}")
                    for cell in CELL_SHAPES if cell in spec.face_cells
                    for k in range(spec.min_k, 3) if cell != "quad8" or k == 2 for n in FACE_N]
    return out


CASES = _cases()


QUADS = ("quad", "quad8")
"""Face cells that are rectangles: Q_k hexahedra's and the QUAD8 faces of HEX20 bodies (k = 2 only)."""


def _gamma(name):
    return SEGMENT if name == "segment" else face_of(name)


def _partition(gamma, n):
    x = np.linspace(0.0, 1.0, n + 1)
    return x if gamma.dim == 1 else TensorPartition(x, x)


def _build(case, gamma, k, n):
    """The space of ``case`` on the uniform partition with N cells per direction, or skip with the
    refusal checked (one line naming the remedy)."""
    try:
        return gamma.space(SPACES[case], k, _partition(gamma, n))
    except InputError as err:
        assert err.key == "case" and "use case" in str(err) and "\n" not in str(err), str(err)
        pytest.skip(f"{case} refuses its construction here: {err}")


def _trace_space(gamma, k, n):
    """W_h: continuous degree-k Lagrange functions vanishing on ∂Γ on the same cells (the traces of
    the displacements of either body on matching meshes), built as the Lagrange space M^1_{0,k}."""
    from infsup_contact.discretization.segment.multipliers import make_space

    x = np.linspace(0.0, 1.0, n + 1)
    if gamma.dim == 1:
        return make_space(x, k, True, True)
    from infsup_contact.discretization.face.spaces.tensor import FaceSpace
    from infsup_contact.discretization.face.spaces.triangles import TriangleSpace

    part = TensorPartition(x, x)
    if gamma.cell == "trig":
        return TriangleSpace(part, k, True, True)
    if gamma.cell == "quad8":  # the serendipity trace: QUAD8 on every rectangle, vanishing on ∂Γ
        from infsup_contact.discretization.face.spaces.cellwise import CellwiseFaceSpace

        return CellwiseFaceSpace(part, "QUAD8", "standard", vanish_on_boundary=True)
    return FaceSpace(make_space(x, k, True, True), make_space(x, k, True, True), part)


@pytest.mark.parametrize("case, gamma_name, k, n", CASES)
def test_built_dimension_is_the_registrys_count(case, gamma_name, k, n):
    spec, gamma = SPACES[case], _gamma(gamma_name)
    space = _build(case, gamma, k, n)
    if spec.dimension is None:
        pytest.skip(f"{case} states no count")
    if gamma.dim == 1 or not spec.defined_on(1):
        assert space.dim == spec.dimension(k, n)
    elif gamma.cell in QUADS:                        # the tensor product of the segment's space
        assert space.dim == spec.dimension(k, n) ** 2
    else:
        pytest.skip(f"no count stated for {case} as P_s on triangles")


def _pieces(space, gamma):
    """The partition on whose cells each basis function is one polynomial, and that degree."""
    pieces = getattr(space, "pieces", None)
    return (space.breakpoints if pieces is None else pieces), getattr(space, "piece_degree", None)


def _cells(gamma, partition):
    """Sample points inside each cell of ``partition`` (on triangles: each quarter of a rectangle)."""
    if gamma.dim == 1:
        x = np.asarray(partition, float)
        for a, b in zip(x[:-1], x[1:]):
            yield a + (b - a) * np.linspace(0.05, 0.95, 11)
        return
    xs, ys = np.asarray(partition.xs, float), np.asarray(partition.ys, float)
    for (x0, x1), (y0, y1) in itertools.product(zip(xs[:-1], xs[1:]), zip(ys[:-1], ys[1:])):
        u, v = np.meshgrid(np.linspace(0.04, 0.96, 9), np.linspace(0.04, 0.96, 9), indexing="ij")
        u, v = u.ravel(), v.ravel()
        if gamma.cell in QUADS:
            yield np.column_stack([x0 + (x1 - x0) * u, y0 + (y1 - y0) * v])
            continue
        # the four triangles (centre, edge) lie inside one triangle of either diagonal's split
        c = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
        corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
        inside = (u + v < 0.96)
        for i in range(4):
            a, b = corners[i], corners[(i + 1) % 4]
            yield c + np.outer(u[inside], a - c) + np.outer(v[inside], b - c)


def _monomials(points, gamma, s):
    """Monomials of degree ≤ s (P_s on intervals and triangles, Q_s on rectangles) at ``points``,
    in coordinates centred on the points' box (conditioning)."""
    p = np.atleast_2d(np.asarray(points, float).T).T
    lo, hi = p.min(axis=0), p.max(axis=0)
    t = (p - lo) / np.where(hi > lo, hi - lo, 1.0) - 0.5
    if gamma.dim == 1:
        return np.column_stack([t[:, 0] ** i for i in range(s + 1)])
    pairs = [(i, j) for i in range(s + 1) for j in range(s + 1) if gamma.cell in QUADS or i + j <= s]
    return np.column_stack([t[:, 0] ** i * t[:, 1] ** j for i, j in pairs])


@pytest.mark.parametrize("case, gamma_name, k, n", CASES)
def test_the_space_lives_on_its_partition(case, gamma_name, k, n):
    spec, gamma = SPACES[case], _gamma(gamma_name)
    space = _build(case, gamma, k, n)
    partition, piece_degree = _pieces(space, gamma)
    s = int(spec.degree(k) if piece_degree is None else piece_degree)
    cells = 0
    for points in _cells(gamma, partition):
        values = np.asarray(space.evaluate(points))
        if hasattr(values, "toarray"):
            values = values.toarray()
        V = _monomials(points, gamma, s)
        assert V.shape[0] > V.shape[1], "too few samples to tell a polynomial"
        coef = np.linalg.lstsq(V, values, rcond=None)[0]
        scale = max(np.abs(values).max(), 1.0)
        assert np.abs(V @ coef - values).max() <= RESIDUAL * scale, f"not P/Q_{s} on a cell of {case}"
        cells += 1
    assert cells >= gamma.cells(partition) if gamma.dim == 2 else cells == len(partition) - 1


def _coupling(space, trace, gamma, k, s, partition):
    """B_ij = ∫_Γ μ_i w_j by the Γ's quadrature, exact for degree s + k on the cells of
    ``partition`` (on each of which both μ_i and w_j are polynomials)."""
    points, weights = gamma.quadrature(partition, s + k)
    mu, w = (np.asarray(f.evaluate(points)) for f in (space, trace))
    mu, w = (m.toarray() if hasattr(m, "toarray") else m for m in (mu, w))
    return (mu * weights[:, None]).T @ w


@pytest.mark.parametrize("case, gamma_name, k, n", CASES)
def test_kernel_on_matching_meshes_is_at_least_the_proofs(case, gamma_name, k, n):
    spec, gamma = SPACES[case], _gamma(gamma_name)
    space = _build(case, gamma, k, n)
    trace = _trace_space(gamma, k, n)
    assert trace.dim == gamma.trace_dimension(k, n)
    partition, piece_degree = _pieces(space, gamma)
    s = int(spec.degree(k) if piece_degree is None else piece_degree)
    B = _coupling(space, trace, gamma, k, max(s, int(spec.degree(k))), partition)
    sv = np.linalg.svd(B, compute_uv=False)
    kernel = space.dim - int(np.sum(sv > RANK_TOL * sv.max()))
    predicted = max(space.dim - trace.dim, 0)
    assert kernel >= predicted
    modes = tensor_modes(*space.factors) if gamma.cell == "quad8" and getattr(space, "factors", None) else 0
    if gamma.cell == "quad8" and spec.defined_on(1):  # the serendipity structure of the QUAD8 trace
        assert kernel == max(predicted, modes)
    tensor = gamma.dim == 1 or (gamma.cell == "quad" and spec.defined_on(1))
    if spec.stable and tensor:  # rank(B ⊗ B) = rank(B)²: the segment's theorem carries to rectangles
        assert kernel == 0, f"{case} is registered stable but has {kernel} zero modes on matching meshes"
    if spec.dimension is not None and (gamma.dim == 1 or not spec.defined_on(1)):
        # a face-only tensor space on QUAD8 traces (the linear duals): the count and the tensor modes
        assert kernel == max(spec.structural_kernel(k, n), modes)
