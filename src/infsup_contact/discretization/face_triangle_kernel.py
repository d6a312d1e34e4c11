"""Lower bounds of the non-matching kernel on the Kuhn-triangulated face (issue 28, tetrahedra).

The face Γ = (0, 1)² of the structured tetrahedral meshes is a Kuhn triangulation: every cell
of the N × N grid cut by its diagonal from (x_i, y_j) to (x_{i+1}, y_{j+1})
(:mod:`.face_triangles`). The traces W_i (continuous P_k on the N_i grid, vanishing on ∂Γ) and
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
(:mod:`.face_triangle_symmetry`), so dim V_c = (χ(id) + a χ(T) + b χ(R) + ab χ(TR))/4 with
χ(g) the number of basis functions g fixes (:func:`class_dimensions`); W1 ∩ W2 is the trace
space of the common coarsening (gcd(N1, N2) cells), as in ``Square.trace_sum_dimension``.

**2. Corner modes.** At the corners (1, 0) and (0, 1) the corner triangle of every Kuhn grid
has its three vertices on ∂Γ, so every trace vanishes on it; when N1 ≤ N2 the corner triangle
of G_h lies in those of both traces and a multiplier supported there (the corner hat of R5.2)
is orthogonal to both; a multiplier odd under TR supported on the few G_h triangles at the
corner (φ_(1−h, 0) − φ_(1, h) for R5.2, k = 1) meets only traces even under TR there (the hats
at (1 − h_i, h_i)) and is a mode as well. Such modes are kernel vectors of Bᵀ supported in a
box of side 2 h2 at a corner (:func:`corner_modes`: the nullity of the coupling of the
multipliers supported in the box, a few dofs, split by the parity of the symmetry fixing that
corner); the pair of corners swapped by G gives one mode per component of that parity.

Both are lower bounds of dim ker_c, hence so is their maximum (:func:`symmetric_kernel_bound`).
On R5.2 and T3 (k = 1, 2), N1, N2 ∈ 2..10, it equals the computed kernel; on spaces whose
multipliers see a trace biorthogonally (the dual basis DUAL-ALL) or discontinuous ones (R5.4)
more modes live in the boundary strip of width h2 and the bound stays below (docs/tet_kernel.md).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sla
from scipy import sparse

from .coupling import weighted_values
from .face_quadrature import split_triangles, triangles_rule
from .face_triangle_symmetry import reflection, transposition
from .face_triangles import TriangleSpace
from .square import TensorPartition

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
    """π_g for g ∈ {T, R, TR}: φ_j ∘ g = φ_π(j) (:mod:`.face_triangle_symmetry`), or None if
    the space is not a triangle space mapped onto itself."""
    if space.dim == 0:
        return {g: np.zeros(0, dtype=int) for g in ("T", "R", "TR")}
    if not hasattr(space, "triangles"):
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


def _box(corner, side: float):
    """((x0, x1), (y0, y1)): the square of side ``side`` in Γ at the corner (cx, cy) ∈ {0, 1}²."""
    return tuple((0.0, side) if c == 0 else (1.0 - side, 1.0) for c in corner)


def _in_box(x: np.ndarray, box, tol: float = 1e-12) -> np.ndarray:
    (x0, x1), (y0, y1) = box
    return (x[:, 0] >= x0 - tol) & (x[:, 0] <= x1 + tol) & (x[:, 1] >= y0 - tol) & (x[:, 1] <= y1 + tol)


def corner_modes(space, k: int, n1: int, n2: int, corner, parity_map: str, side_cells: int = 2) -> tuple:
    """(even, odd): kernel vectors of Bᵀ supported in the box of side ``side_cells`` · h2 at
    ``corner``, by their parity under the symmetry ``parity_map`` ("TR" for (1, 0), "T" for
    (0, 0)) that fixes the corner and the box. The multipliers supported in the box (all their
    sample values outside it zero) are coupled exactly (Duffy rule on the overlay of both traces
    and G_h, :func:`~.face_quadrature.split_triangles`) with every function of W1 and W2;
    the nullity of that small matrix in each parity subspace is the count."""
    side = side_cells / n2
    box = _box(corner, side)
    x = np.einsum("pk,tkd->tpd", _SAMPLES, space.triangles()).reshape(-1, 2)
    values = weighted_values(space, x, np.ones(len(x))).tocsc()
    outside = ~_in_box(x, box)
    rows = np.flatnonzero(np.asarray(abs(values[outside]).sum(axis=0)).ravel() == 0.0)
    if len(rows) == 0:
        return 0, 0
    pi = permutations(space)[parity_map]
    assert set(pi[rows]) == set(rows), "the box is not mapped onto itself"
    pos = {r: i for i, r in enumerate(rows)}
    P = np.zeros((len(rows), len(rows)))
    P[[pos[j] for j in pi[rows]], np.arange(len(rows))] = 1.0
    traces = [trace_space(k, n) for n in (n1, n2)]
    xs = np.unique(np.concatenate([uniform(n).xs for n in (n1, n2)]))
    (x0, x1), (y0, y1) = box
    sub = TensorPartition(xs[(xs >= x0 - 1e-12) & (xs <= x1 + 1e-12)], xs[(xs >= y0 - 1e-12) & (xs <= y1 + 1e-12)])
    B = []
    for w, n in zip(traces, (n1, n2)):
        if w.dim == 0:
            continue
        tri = split_triangles(sub, uniform(n), uniform(n2))
        q, wq = triangles_rule(tri, k + space.degree)
        B.append((weighted_values(space, q, wq)[:, rows].T @ weighted_values(w, q, np.ones(len(q)))).toarray())
    B = np.hstack(B) if B else np.zeros((len(rows), 0))
    scale = np.abs(B).max() if B.size else 1.0
    out = []
    for sign in (1.0, -1.0):
        basis = sla.orth(np.eye(len(rows)) + sign * P)  # the parity subspace
        if basis.shape[1] == 0:
            out.append(0)
            continue
        sv = np.linalg.svd(basis.T @ B, compute_uv=False) if B.size else np.zeros(0)
        out.append(int(basis.shape[1] - np.sum(sv > _RANK_TOL * scale)))
    return tuple(out)


def symmetric_kernel_bound(space, k: int, n1: int, n2: int, side_cells: int = 2) -> dict | None:
    """Per component c: max(dim M_c − dim(W1 + W2)_c, corner modes in c, 0), a lower bound of
    dim ker_c (module docstring); None where the group does not permute the spaces' bases.

    Corners (1, 0) and (0, 1) are swapped by T and R and fixed by TR: a mode of TR-parity p at
    one of them and its image span one vector in each component with χ(T) χ(R) = p. Corners
    (0, 0) and (1, 1) are fixed by T and swapped by R: one vector in each component with
    χ(T) = p. Boxes of side ≤ 1/2 at different corners do not overlap, so all are independent."""
    counts = class_counts(space, k, n1, n2)
    if counts is None:
        return None
    side_cells = min(side_cells, n2 // 2)
    corner = {c: 0 for c in COMPONENTS}
    if side_cells >= 1:
        for point, g, char in (((1.0, 0.0), "TR", lambda a, b: a * b), ((0.0, 0.0), "T", lambda a, b: a)):
            even, odd = corner_modes(space, k, n1, n2, point, g, side_cells)
            for c in COMPONENTS:
                corner[c] += even if char(*c) == 1 else odd
    return {c: max(counts[c], corner[c], 0) for c in COMPONENTS}
