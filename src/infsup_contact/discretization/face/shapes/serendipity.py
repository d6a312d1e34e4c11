"""Γ = (0, 1)² × {1} traced by serendipity HEX20 bodies: QUAD8 faces.

The trace of a 20-node hexahedron on a face is the 8-node serendipity quadrilateral QUAD8 =
P2 + {ξ²η, ξη²} (:mod:`.face.spaces.reference_elements`): nodal values at the four corners and
the four edge midpoints, no centre node. :class:`SerendipitySquare` is :class:`~.square.Square`
with that trace: the same tensor partitions, quadrature, multiplier spaces and norms, but

* the trace is read from a nodal displacement space that is not NGSolve's (:class:`NodalDofs`:
  the dof locations and free dofs of scikit-fem's ``ElementHexS2``, :mod:`infsup_contact.models.hex20`);
* its basis on Γ is the QUAD8 nodal basis on every rectangle of the trace partition;
* its counts: dim W_h = (n − 1)² vertices + 2 n (n − 1) edge midpoints = (3n − 1)(n − 1) inside Γ on
  an n × n grid (QUAD9 has (2n − 1)²: the n² centres are missing);
* it builds the registry entries that name ``quad8`` among their ``face_cells``.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ....errors import InputError
from ...gamma.trace import GammaTrace
from ..spaces.reference_elements import reference_element
from .square import Square
from ..partitions.tensor_grid import TensorPartition, coarsening_cells, merge_breakpoints

QUAD8 = reference_element("QUAD8")


@dataclass(frozen=True, eq=False)
class NodalDofs:
    """A nodal displacement space as its face trace needs it (the role of ``ngsolve.H1``).

    Attributes
    ----------
    points : ndarray, shape (ndof, 3)
        Location of every dof (the node whose value it is).
    free : ndarray of bool, shape (ndof,)
        Dofs not fixed by the Dirichlet condition.
    vertices : ndarray, shape (nv, 3)
        The mesh vertices (the trace partition is read from those on Γ).
    basis : object
        The library's basis (scikit-fem ``CellBasis``), kept for consumers that interpolate.
    """

    points: np.ndarray
    free: np.ndarray
    vertices: np.ndarray
    basis: object = None

    @property
    def ndof(self) -> int:
        return len(self.points)


def interior_dimension(nx: int, ny: int) -> int:
    """QUAD8 nodes strictly inside Γ on an nx × ny grid: vertices, then x- and y-edge midpoints."""
    return max(nx - 1, 0) * max(ny - 1, 0) + nx * max(ny - 1, 0) + max(nx - 1, 0) * ny


@dataclass(frozen=True)
class SerendipitySquare(Square):
    """The face of HEX20 bodies (module docstring); ``cell`` is ``quad8``."""

    cell: str = "quad8"

    # --- partitions and the trace
    def _on_gamma(self, points: np.ndarray, tol: float = 1e-12) -> np.ndarray:
        return np.abs(points[:, 2] - self.z) < tol

    def partition_of(self, mesh) -> TensorPartition:
        """The tensor grid of the vertices on Γ of a scikit-fem mesh (``mesh.p``, shape (3, nv))."""
        return self._partition_of_vertices(np.asarray(mesh.p, float).T)

    def _partition_of_vertices(self, vertices: np.ndarray, tol: float = 1e-12) -> TensorPartition:
        on = vertices[self._on_gamma(vertices)]
        if not len(on):
            raise InputError("mesh", f"vertices on Γ (z = {self.z:g})")
        part = TensorPartition(merge_breakpoints(on[:, 0], tol), merge_breakpoints(on[:, 1], tol))
        if (len(on) != len(part.xs) * len(part.ys) or part.xs[0] != 0.0 or part.ys[0] != 0.0
                or part.xs[-1] != self.width or part.ys[-1] != 1.0):
            raise InputError("mesh", f"a face Γ tiled by a tensor grid of rectangles ({len(on)} vertices on Γ)")
        return part

    def trace(self, fes: NodalDofs) -> GammaTrace:
        """The free Γ dofs of ``fes`` and, per rectangle of the trace partition, the Γ-dof positions of
        its QUAD8 nodes (in the reference element's order; −1 for a fixed dof). :class:`InputError`
        unless the dofs on Γ are exactly the QUAD8 nodes of the grid (corners and edge midpoints)."""
        part = self._partition_of_vertices(np.asarray(fes.vertices, float))
        pts = np.asarray(fes.points, float)
        on = np.flatnonzero(self._on_gamma(pts))
        lattice = self._lattice_index(part, pts[on, :2])
        nx, ny = len(part.xs) - 1, len(part.ys) - 1
        centre = (lattice[:, 0] % 2 == 1) & (lattice[:, 1] % 2 == 1)
        n_nodes = (nx + 1) * (ny + 1) + nx * (ny + 1) + ny * (nx + 1)
        if np.any(lattice < 0) or np.any(centre) or len(on) != n_nodes:
            raise InputError("mesh", f"a serendipity (QUAD8) trace: {n_nodes} Γ dofs at the corners and edge "
                             f"midpoints of the {nx} x {ny} grid (got {len(on)})")
        gamma_dofs = np.sort(on[np.asarray(fes.free, bool)[on]])
        position = -np.ones((2 * nx + 1, 2 * ny + 1), dtype=int)
        live = np.asarray(fes.free, bool)[on]
        position[lattice[live, 0], lattice[live, 1]] = np.searchsorted(gamma_dofs, on[live])
        I = 2 * np.arange(nx)[:, None, None] + (QUAD8.nodes[:, 0] + 1).astype(int)[None, None, :]
        J = 2 * np.arange(ny)[None, :, None] + (QUAD8.nodes[:, 1] + 1).astype(int)[None, None, :]
        cells = position[I, J].reshape(nx * ny, QUAD8.n_nodes)  # cell c = i ny + j
        return GammaTrace(fes, gamma_dofs, [cells], part, self)

    @staticmethod
    def _lattice_index(part: TensorPartition, xy: np.ndarray, tol: float = 1e-10) -> np.ndarray:
        """(I, J) on the lattice of half cells (I = 2 i + ξ + 1), −1 where a point is on none."""
        out = []
        for d, g in enumerate((np.asarray(part.xs), np.asarray(part.ys))):
            half = np.sort(np.concatenate([g, 0.5 * (g[:-1] + g[1:])]))
            i = np.argmin(np.abs(half[None, :] - xy[:, d, None]), axis=1)
            out.append(np.where(np.abs(half[i] - xy[:, d]) < tol, i, -1))
        return np.column_stack(out)

    # --- the trace basis: QUAD8 on every rectangle
    def _local(self, trace: GammaTrace, x: np.ndarray) -> tuple:
        """(values (n, 8), Γ-dof positions (n, 8)) of the QUAD8 functions of the cell holding each
        point (a point on a cell boundary takes the cell on its upper / right side: the trace is
        continuous, so the choice does not change a value)."""
        part = trace.breakpoints
        ix, iy = self._cell_index(part, x)
        xs, ys = np.asarray(part.xs), np.asarray(part.ys)
        ref = np.column_stack([2 * (x[:, 0] - xs[ix]) / (xs[ix + 1] - xs[ix]) - 1,
                               2 * (x[:, 1] - ys[iy]) / (ys[iy + 1] - ys[iy]) - 1])
        return QUAD8.shapes(ref), trace.elements[0][ix * (len(ys) - 1) + iy]

    def trace_values(self, trace: GammaTrace, x: np.ndarray) -> np.ndarray:
        """Dense values (len(x), number of Γ dofs) of the Γ-dof basis at points x of Γ."""
        return self.sparse_trace_basis(trace, x).toarray()

    def sparse_trace_basis(self, trace: GammaTrace, x: np.ndarray):
        """The Γ-dof basis at points x as CSR (sorted indices, no stored zeros)."""
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        vals, pos = self._local(trace, x)
        keep = (pos >= 0) & (vals != 0)
        rows = np.broadcast_to(np.arange(len(x))[:, None], pos.shape)
        phi = sp.coo_matrix((vals[keep], (rows[keep], pos[keep])), shape=(len(x), len(trace.gamma_dofs))).tocsr()
        phi.sum_duplicates()  # sorts the column indices (the 8 local dofs are distinct)
        return phi

    # --- counts
    def allows(self, k: int) -> bool:
        """HEX20 bodies have k = 2 only."""
        return k == 2

    def _check_k(self, k: int) -> None:
        if not self.allows(k):
            raise InputError("k", "2 (the serendipity HEX20 element is quadratic)", got=k)

    def trace_dimension(self, k: int, cells: int) -> int:
        """dim W_h = (3n − 1)(n − 1): the QUAD8 nodes inside Γ on an n × n grid."""
        self._check_k(k)
        return interior_dimension(cells, cells)

    def trace_sum_dimension(self, k: int, trace1, trace2) -> int:
        """dim W1 + dim W2 − dim W_c, W_c the QUAD8 trace on the common coarsening (shared
        breakpoints). Serendipity Q2 is invariant under axis-aligned affine maps, so W_c ⊂ W1 ∩ W2 and
        this is an upper bound of dim(W1 + W2) (the proven kernel stays a lower bound); equal on
        matching meshes."""
        self._check_k(k)
        d = [interior_dimension(len(p.xs) - 1, len(p.ys) - 1) for p in (trace1, trace2)]
        dc = interior_dimension(coarsening_cells(trace1.xs, trace2.xs), coarsening_cells(trace1.ys, trace2.ys))
        return d[0] + d[1] - dc

    def proven_kernel(self, space, k: int, traces, dim_w: int) -> int:
        """max(dim M − dim(W1 + W2), 0), and for a tensor product space M = Mˣ ⊗ Mʸ the modes of the
        serendipity structure, whichever is larger: on the G_h of both traces :func:`tensor_modes`
        (the kernel), on non-matching traces :func:`product_modes` (a lower bound; up to
        :data:`PRODUCT_MODES_MAX_DIM`)."""
        glob = max(space.dim - dim_w, 0)
        if getattr(space, "factors", None) is None:
            return glob
        key = self.partition_key(space.breakpoints)
        if all(self.partition_key(t.partition) == key for t in traces):
            return max(glob, tensor_modes(*space.factors))
        modes = product_modes(*space.factors, [t.partition for t in traces])
        return glob if modes is None else max(glob, modes)

    def natural_modes(self, space, partitions) -> int | None:
        """A lower bound of dim ker Bᵀ against traces that do not vanish on ∂Γ (a contact scene with
        natural lateral faces) on ``partitions``: for a tensor space the products orthogonal to every
        full QUAD8 trace (:func:`product_modes` with ``vanish=False``: QUAD8 lacks the cell centres,
        so a Q2 multiplier has modes the traces cannot see); None for other spaces (or too large)."""
        if getattr(space, "factors", None) is None:
            return None
        return product_modes(*space.factors, partitions, vanish=False)

    def trace_nodes(self, k: int, cells: int) -> int:
        """3n² + 4n + 1 QUAD8 nodes of a side on an n × n grid, boundary included."""
        self._check_k(k)
        return (cells + 1) ** 2 + 2 * cells * (cells + 1)


SERENDIPITY = SerendipitySquare()
"""Γ = (0, 1)² × {1} of the HEX20 bodies."""


def face_of(cell: str) -> Square:
    """The face whose boundary cells are ``cell`` (one of :data:`~.square.CELL_SHAPES`)."""
    return SERENDIPITY if cell == "quad8" else Square(cell=cell)


def tensor_modes(mx, my, rtol: float = 1e-10) -> int:
    """dim ker Bᵀ of a tensor space M = Mˣ ⊗ Mʸ against the QUAD8 trace on the grid of its factors.

    The QUAD8 functions vanishing on ∂Γ are the hats, the x-edge bubbles times y-hats and the
    x-hats times y-edge bubbles (no cell bubbles: those are QUAD9's centres), so
    W = P2_0ˣ ⊗ P1_0ʸ + P1_0ˣ ⊗ P2_0ʸ with P1_0, P2_0 the 1D continuous P1, P2 vanishing at the
    ends. With K_d = Mᵈ ∩ (P_d,0)^⊥ (d = 1, 2; K_2 ⊂ K_1), a ⊗ b is orthogonal to W when a ⊥ P2_0ˣ,
    when b ⊥ P2_0ʸ, or when a ⊥ P1_0ˣ and b ⊥ P1_0ʸ; splitting each Mᵈ into K_2 ⊕ (K_1 ⊖ K_2) ⊕ rest,
    the kernel is spanned by the products of basis classes with either factor in K_2 or both in K_1:
    dim = m_x m_y − (m_x − k2_x)(m_y − k2_y) + (k1_x − k2_x)(k1_y − k2_y), and no other product
    class is orthogonal to W. The 1D dimensions k_d = m − rank of the exact 1D coupling.
    E.g. continuous Q1 (T5 at k = 2): k1 = 2, k2 = 0, four modes a ⊗ b, a and b the P1 functions
    with nodal values (−(2 − √3))^i from either end; discontinuous Q0 (T4 at k = 2): the checkerboard."""
    k1, k2 = zip(*(_orthogonal_dims(f, rtol) for f in (mx, my)))
    m = (mx.dim, my.dim)
    return m[0] * m[1] - (m[0] - k2[0]) * (m[1] - k2[1]) + (k1[0] - k2[0]) * (k1[1] - k2[1])


PRODUCT_MODES_MAX_DIM = 2500
"""Largest dim M whose non-matching product modes :func:`product_modes` counts (one dense eigensolve)."""


def product_modes(mx, my, partitions, rtol: float = 1e-10, vanish: bool = True) -> int | None:
    """dim of the span of the products A ⊗ B ⊂ Mˣ ⊗ Mʸ orthogonal to the QUAD8 traces on every
    partition of ``partitions``: a lower bound of dim ker Bᵀ (None above :data:`PRODUCT_MODES_MAX_DIM`).

    Side i's trace is P2_0ˣ ⊗ P1_0ʸ + P1_0ˣ ⊗ P2_0ʸ on its grid (:func:`tensor_modes`), so A ⊗ B is
    orthogonal to it when (A ⊥ P2_0ˣ or B ⊥ P1_0ʸ) and (A ⊥ P1_0ˣ or B ⊥ P2_0ʸ): four choices per
    side; for each combination A and B are the largest subspaces meeting the chosen 1D conditions,
    and the span of all these products is the range of Σ Π_A ⊗ Π_B (orthogonal projectors in the
    coefficients), whose rank is counted. On matching traces it is :func:`tensor_modes`.

    ``vanish=False``: the traces of bodies whose lateral faces are natural (a contact scene's), which
    do not vanish on ∂Γ: the same count with the full 1D P1, P2 (P2ˣ ⊗ P1ʸ + P1ˣ ⊗ P2ʸ is QUAD8
    with its boundary nodes)."""
    if mx.dim * my.dim > PRODUCT_MODES_MAX_DIM:
        return None
    per_side = [(("x", 2, p.xs), ("y", 1, p.ys)) for p in partitions]
    second = [(("x", 1, p.xs), ("y", 2, p.ys)) for p in partitions]
    choices = [[(a, b) for a in f for b in g] for f, g in zip(per_side, second)]
    total = np.zeros((mx.dim * my.dim,) * 2)
    for combo in itertools.product(*choices):
        conds = [c for pair in combo for c in pair]
        A = _perpendicular(mx, [(d, g) for axis, d, g in conds if axis == "x"], rtol, vanish)
        B = _perpendicular(my, [(d, g) for axis, d, g in conds if axis == "y"], rtol, vanish)
        if A.shape[1] and B.shape[1]:
            total += np.kron(A @ A.T, B @ B.T)
    eig = np.linalg.eigvalsh(total)
    return int(np.sum(eig > rtol * max(eig.max(), 1.0)))


def _perpendicular(factor, conditions, rtol: float, vanish: bool = True) -> np.ndarray:
    """Orthonormal coefficients of the functions of a 1D space orthogonal to P_d,0 (``vanish``; else
    P_d) on each grid of ``conditions`` ((d, breakpoints) pairs; exact Gauss rule on the common refinement)."""
    from scipy.linalg import null_space

    from ...gamma.quadrature import gauss_legendre
    from ...segment.multipliers import make_space

    if not conditions:
        return np.eye(factor.dim)
    x = np.unique(np.concatenate([np.asarray(factor.breakpoints, float)] + [np.asarray(g, float) for _, g in conditions]))
    t, w = gauss_legendre(factor.degree // 2 + 3)
    a, b = x[:-1, None], x[1:, None]
    pts, wts = (0.5 * (a + b) + 0.5 * (b - a) * t).ravel(), (0.5 * (b - a) * w).ravel()
    mu = factor.evaluate(pts) * wts[:, None]
    G = np.hstack([mu.T @ make_space(np.asarray(g, float), d, True, vanish).evaluate(pts) for d, g in conditions])
    return null_space(G.T, rcond=rtol)


def _orthogonal_dims(factor, rtol: float) -> tuple:
    """(dim M ∩ P1_0^⊥, dim M ∩ P2_0^⊥) of a 1D space on its breakpoints (exact Gauss rule per interval)."""
    from ...gamma.quadrature import gauss_legendre
    from ...segment.multipliers import make_space

    x = np.asarray(factor.breakpoints, float)
    t, w = gauss_legendre(factor.degree // 2 + 3)
    a, b = x[:-1, None], x[1:, None]
    pts, wts = (0.5 * (a + b) + 0.5 * (b - a) * t).ravel(), (0.5 * (b - a) * w).ravel()
    mu = factor.evaluate(pts) * wts[:, None]
    out = []
    for degree in (1, 2):
        A = mu.T @ make_space(x, degree, True, True).evaluate(pts)
        s = np.linalg.svd(A, compute_uv=False) if A.size else np.zeros(0)
        rank = int(np.sum(s > rtol * s.max())) if s.size and s.max() > 0 else 0
        out.append(factor.dim - rank)
    return tuple(out)
