"""Lower bounds of the non-matching kernel on the Kuhn-triangulated face (tetrahedra).

The face Γ = (0, 1)² of the structured tetrahedral meshes is a Kuhn triangulation: every cell
of the N × N grid cut by its diagonal from (x_i, y_j) to (x_{i+1}, y_{j+1})
(:mod:`.face.spaces.triangles`). The traces W_i (continuous P_k on the N_i grid, vanishing on ∂Γ) and
a multiplier space M on G_h (the Ω2 trace) are compared by the dimension count
max(dim M − dim(W1 + W2), 0) (``planar_kernel``), which on non-matching pairs undercounts
(R5.2, k = 1: 6:7 has kernel 5 against 3, 7:8 has 4 against 0). Two mechanisms explain it.

**1. The symmetry of the pair.** Both grids, hence M, W1, W2 and the coupling
b(v, μ) = ∫_Γ v μ, are invariant under the group G = {id, T, R, TR} ≅ Z2 × Z2 of the Kuhn
square: the transposition T(x, y) = (y, x), the point reflection R(x, y) = (1 − x, 1 − y) and
TR(x, y) = (1 − y, 1 − x) (the reflections x → 1 − x and y → 1 − y flip the diagonals and are
not symmetries). So ker Bᵀ = {μ ∈ M : μ ⊥ W1, μ ⊥ W2} splits into the four isotypic
components c = (χ(T), χ(R)) ∈ {±1}², and in each the dimension argument holds separately:

    dim ker_c ≥ dim M_c − dim(W1 + W2)_c,   dim ker ≥ Σ_c max(dim M_c − dim(W1 + W2)_c, 0),

which exceeds max(Σ_c …, 0) whenever the components' counts have different signs (an
extension of the count by group representations, e.g. Fässler & Stiefel, *Group Theoretical
Methods and Their Applications*, 1992, ch. 2). The bases are permuted by G
(:mod:`.face.symmetry`), so dim V_c = (χ(id) + a χ(T) + b χ(R) + ab χ(TR))/4 with
χ(g) the number of basis functions g fixes (:func:`class_dimensions`); W1 ∩ W2 is the trace
space of the common coarsening (gcd(N1, N2) cells), as in ``Square.trace_sum_dimension``.

**2. Boundary-layer modes.** Every trace vanishes on ∂Γ, and in the layer of G_h cells along
∂Γ only the first row of interior nodes of each trace reaches: few trace functions against many
multipliers, whatever the global count says. At the corners (1, 0) and (0, 1) the corner
triangle of every Kuhn grid has its three vertices on ∂Γ, so every trace vanishes on it; when
N1 <= N2 the corner triangle of G_h lies in those of both traces and the corner hat of R5.2 is
orthogonal to both, as is φ_(1−h, 0) − φ_(1, h) (odd under TR, it meets only the TR-even hats
at (1 − h_i, h_i)). For a dual basis (DUAL-ALL), biorthogonal to W2, μ ⊥ W2 leaves exactly the
duals ψ_v of the nodes v on ∂Γ (4 N2 of them, supported in the layer), and ψ_v couples to W1
only where a line of the Ω1 grid cuts its star (on a star cut by no such line a W1 function is
linear, and ∫ ψ_v w = w(v) ∫ φ_v = 0): the whole kernel lives in the layer, 4 N2 − rank. Such
modes are counted exactly, per component, as the nullity of the coupling of the multipliers
supported in the layer of width 2 h2 (:func:`layer_modes`, O(N) dofs).

Both are lower bounds of dim ker_c, hence so is their maximum (:func:`symmetric_kernel_bound`).
On R5.2, DUAL-ALL and T3 (k = 1, 2), N1, N2 ∈ 3..10, it equals the computed kernel; on the
discontinuous R5.4 it stays below on near-matching pairs (k = 2: 6:7 gives 16 of 18; k = 1, N1 =
2 N2: a checkerboard mode), and neither trace-side layer dependencies explain the rest
(docs/tet_kernel.md).
"""
from __future__ import annotations

import math

import numpy as np

from ..gamma.coupling import weighted_values
from .partitions.quadrature import split_triangles, triangles_rule
from .symmetry import reflection, transposition
from .spaces.triangles import TriangleSpace
from .partitions.tensor_grid import TensorPartition

#: The isotypic components (χ(T), χ(R)) of G = {id, T, R, TR}; χ(TR) = χ(T) χ(R).
COMPONENTS = ((1, 1), (1, -1), (-1, 1), (-1, -1))

#: Barycentric sample points per triangle (interior, general position for P_s, s ≤ 3).
_SAMPLES = np.random.default_rng(7).dirichlet(np.ones(3), size=12)
_RANK_TOL = 1e-8


def uniform(n: int) -> TensorPartition:
    """The n × n grid of the face."""
    x = np.linspace(0.0, 1.0, n + 1)
    return TensorPartition(x, x)


def trace_space(k: int, n: int) -> TriangleSpace:
    """W: continuous P_k on the Kuhn n × n grid vanishing on ∂Γ (the Γ trace of P_k on the
    structured tetrahedra with the lateral faces clamped)."""
    return TriangleSpace(uniform(n), k, True, True)


def permutations(space) -> dict | None:
    """π_g for g ∈ {T, R, TR}: φ_j ∘ g = φ_π(j) (:mod:`.face.symmetry`), or None if
    the space is not a triangle space mapped onto itself."""
    if space.dim == 0:
        return {g: np.zeros(0, dtype=int) for g in ("T", "R", "TR")}
    if not space.lives_on_triangles:
        return None
    t, r = transposition(space), reflection(space)
    if t is None or r is None:
        return None
    return {"T": t, "R": r, "TR": r[t]}  # φ_j∘T∘R = φ_t(j)∘R = φ_r(t(j))


def class_dimensions(space) -> dict | None:
    """dim of each isotypic component (χ(T), χ(R)) of a space the group permutes, from the
    characters χ(g) = #{j : π_g(j) = j}; None where the group does not permute the basis."""
    pi = permutations(space)
    if pi is None:
        return None
    chi = {g: int(np.sum(p == np.arange(len(p)))) for g, p in pi.items()}
    out = {}
    for a, b in COMPONENTS:
        d4 = space.dim + a * chi["T"] + b * chi["R"] + a * b * chi["TR"]
        assert d4 % 4 == 0, "a character sum not divisible by |G|: not a representation"
        out[(a, b)] = d4 // 4
    return out


def class_counts(space, k: int, n1: int, n2: int) -> dict | None:
    """dim M_c − dim(W1 + W2)_c per component, W1 ∩ W2 = the trace space on gcd(n1, n2) cells."""
    g = math.gcd(n1, n2)
    dims = [class_dimensions(s) for s in (space, trace_space(k, n1), trace_space(k, n2), trace_space(k, g))]
    if any(d is None for d in dims):
        return None
    m, w1, w2, both = dims
    if n1 == n2:
        return {c: m[c] - w2[c] for c in COMPONENTS}
    return {c: m[c] - w1[c] - w2[c] + both[c] for c in COMPONENTS}


def component_basis(pi: dict, rows: np.ndarray, c) -> np.ndarray:
    """Orthonormal basis (len(rows), n_c) of the component c = (χ(T), χ(R)) of the span of the
    basis functions ``rows`` (a union of G-orbits; φ_j ∘ g = φ_π_g(j)): one vector
    Σ_g χ_c(g) e_π_g(j) per orbit where it is not zero (a permutation representation on one
    orbit holds each character at most once), without the dense projector."""
    a, b = c
    pos = -np.ones(max(int(rows.max()) + 1, 1), dtype=int)
    pos[rows] = np.arange(len(rows))
    seen = np.zeros(len(rows), dtype=bool)
    cols = []
    for i, j in enumerate(rows):
        if seen[i]:
            continue
        v = np.zeros(len(rows))
        for g, chi in ((None, 1), ("T", a), ("R", b), ("TR", a * b)):
            img = pos[j if g is None else pi[g][j]]
            v[img] += chi
            seen[img] = True
        if np.any(v):
            cols.append(v / np.linalg.norm(v))
    return np.array(cols).T if cols else np.zeros((len(rows), 0))


def layer_modes(space, k: int, n1: int, n2: int, width_cells: int = 2) -> dict:
    """Per component c: the kernel vectors of Bᵀ supported in the boundary layer
    {x ∈ Γ : dist(x, ∂Γ) <= width_cells · h2} (a union of G_h triangles, invariant under G).

    The multipliers supported there (all their sample values farther in are zero) are coupled
    exactly with every function of W1 and W2 (Duffy rule on the overlay of both traces and
    G_h, :func:`~.face.partitions.quadrature.split_triangles`, restricted to the layer); the nullity of that
    matrix on the span of :func:`component_basis` is the count of c. The width is capped at
    (n2 − 1) // 2 cells, so that the layer never is the whole face (whose nullity would be the
    kernel itself, not a count): no layer for n2 <= 2."""
    depth = min(width_cells, (n2 - 1) // 2) / n2
    x = np.einsum("pk,tkd->tpd", _SAMPLES, space.triangles()).reshape(-1, 2)
    values = weighted_values(space, x, np.ones(len(x))).tocsc()
    if depth <= 0:
        return {c: 0 for c in COMPONENTS}
    inner = _distance(x) > depth + 1e-12
    rows = np.flatnonzero(np.asarray(abs(values[inner]).sum(axis=0)).ravel() == 0.0)
    if len(rows) == 0:
        return {c: 0 for c in COMPONENTS}
    pi = permutations(space)
    tri = split_triangles(TensorPartition(*(2 * [np.unique(np.concatenate([uniform(n).xs for n in (n1, n2)]))])),
                          uniform(n1), uniform(n2))
    tri = tri[_distance(tri.mean(axis=1)) <= depth + 1e-12]
    q, wq = triangles_rule(tri, k + space.degree)
    mu = weighted_values(space, q, wq)[:, rows].T
    blocks = [(mu @ weighted_values(w, q, np.ones(len(q)))).tocsc() for w in (trace_space(k, n1), trace_space(k, n2))]
    B = np.hstack([b[:, np.flatnonzero(np.diff(b.indptr))].toarray() for b in blocks])  # the touching traces
    scale = np.abs(B).max() if B.size else 1.0
    out = {}
    for c in COMPONENTS:
        basis = component_basis(pi, rows, c)
        sv = np.linalg.svd(basis.T @ B, compute_uv=False) if B.size and basis.shape[1] else np.zeros(0)
        out[c] = int(basis.shape[1] - np.sum(sv > _RANK_TOL * scale))
    return out


def _distance(x: np.ndarray) -> np.ndarray:
    """Distance of points (n, 2) of Γ to ∂Γ."""
    return np.minimum(np.minimum(x[:, 0], 1.0 - x[:, 0]), np.minimum(x[:, 1], 1.0 - x[:, 1]))


def symmetric_kernel_bound(space, k: int, n1: int, n2: int, width_cells: int = 2) -> dict | None:
    """Per component c: max(dim M_c − dim(W1 + W2)_c, boundary-layer modes in c, 0), a lower
    bound of dim ker_c (module docstring: both are); None where the group does not permute
    the spaces' bases."""
    counts = class_counts(space, k, n1, n2)
    if counts is None:
        return None
    layer = layer_modes(space, k, n1, n2, width_cells)
    return {c: max(counts[c], layer[c], 0) for c in COMPONENTS}
