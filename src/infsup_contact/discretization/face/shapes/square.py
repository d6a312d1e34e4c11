"""Γ = (0, 1)² × {1}, the contact face of the 3D model problem.

A partition of the face is, for now, a tensor grid of rectangles (:class:`TensorPartition`):
the trace of a structured hexahedral mesh, and the common refinement of two such traces.
:class:`Square` is the second implementation of :class:`~.gamma.interface.Interface`: its points
are arrays of shape (n, 2) (x, y), its quadrature is the tensor Gauss–Legendre rule per
rectangle, its multiplier spaces are tensor products of the segment's 1D spaces
(:mod:`.face.spaces.tensor`) and its norms are computed factor by factor (:mod:`.face.norms.tensor`); the
registry's face element spaces (QUAD8/QUAD9 dual, transformed dual, 4C pwlin: ``face_build``,
:mod:`.face.spaces.cellwise`) are not tensor products, and their norms go through the exact projection
onto discontinuous tensor pieces (:mod:`.face.norms.cellwise`).

The trace of a tetrahedral mesh from the same structured grid (every rectangle cut in two
triangles by its diagonal from (x_i, y_j) to (x_{i+1}, y_{j+1})) has the same tensor partition;
``Square(cell="trig")`` is its interface (the trace basis is then P_k on triangles, not Q_k;
its couplings are integrated on the rectangles cut by the diagonals of the trace and of G_h,
:mod:`.face.partitions.quadrature`). There the registry's Lagrange cases (``SpaceSpec.lagrange``) are
P_s on the triangles of G_h (:mod:`.face.spaces.triangles`, Grams in :mod:`.face.norms.triangles`),
the duals TRI3 / TRI6 (s ≤ 2); other spaces stay tensor products.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ....errors import InputError
from ...gamma.interface import Interface
from ...gamma.multiplier_meshes import check_choice, intervals_per_direction
from ...gamma.trace import GammaTrace
from ..partitions.quadrature import split_rule
from ..partitions.tensor_grid import TensorPartition, coarsening_cells, merge_breakpoints
from .trace_shapes import shape_values
from ...gamma.quadrature import gauss_legendre

CELL_SHAPES = ("quad", "trig", "quad8")
"""Boundary cells of a face: rectangles of Q_k hexahedra, their Kuhn triangles, QUAD8 rectangles of
serendipity HEX20 bodies (:mod:`.face.shapes.serendipity`)."""
CELL_BODIES = {"quad": "hexahedra (element hex)", "trig": "tetrahedra (element tet)",
               "quad8": "serendipity HEX20 bodies (element hex20)"}
"""The bodies whose traces each face cell is, for the one-line refusal of a space on other bodies."""


@dataclass(frozen=True)
class Square(Interface):
    """Γ = (0, 1)² × {z}: partitions are :class:`TensorPartition`; points are (n, 2) arrays.

    Attributes
    ----------
    boundary : str
        Name of Γ's boundary region in the meshes (``gamma``).
    z : float
        Height of Γ.
    cell : {"quad", "trig", "quad8"}
        Shape of the boundary elements on Γ: rectangles of a hexahedral mesh, or each
        rectangle cut in two triangles (a tetrahedral mesh); ``quad8``: the QUAD8 rectangles of
        serendipity HEX20 bodies, whose trace is :class:`~.face.shapes.serendipity.SerendipitySquare`'s.
    width : float
        Γ's extent in x (1: the unit face). A narrower face (0, width) × (0, 1) is the trace
        of a narrower body (:mod:`infsup_contact.study.face.edge_dropping`); the trace
        (:meth:`trace`, :meth:`trace_basis`, :meth:`quadrature`) serves it, the multiplier
        spaces, norms and counts of this class are those of the unit face.
    """

    boundary: str = "gamma"
    z: float = 1.0
    cell: str = "quad"
    width: float = 1.0

    def __post_init__(self):
        if self.cell not in CELL_SHAPES:
            raise InputError("cell", ", ".join(CELL_SHAPES), got=self.cell)

    @property
    def dim(self) -> int:
        return 2

    def embed(self, x):
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        return x[:, 0], x[:, 1], np.full(len(x), self.z)

    # --- partitions
    def _gamma_elements(self, mesh):
        """(element, vertex coordinates (nv, 2)) of the Γ boundary elements of ``mesh``."""
        import ngsolve

        out = []
        for el in mesh.Elements(ngsolve.BND):
            if el.mat == self.boundary:
                out.append((el, np.array([mesh[v].point[:2] for v in el.vertices])))
        return out

    def _partition_of_elements(self, elements, tol: float = 1e-12) -> TensorPartition:
        """The tensor grid of the Γ elements; :class:`InputError` unless they tile one."""
        if not elements:
            raise InputError("mesh", f"boundary elements named {self.boundary!r} on Γ")
        pts = np.vstack([v for _, v in elements])
        part = TensorPartition(merge_breakpoints(pts[:, 0], tol), merge_breakpoints(pts[:, 1], tol))
        per_cell = 1 if self.cell == "quad" else 2
        nv = 4 if self.cell == "quad" else 3
        lo = np.array([v.min(axis=0) for _, v in elements])
        hi = np.array([v.max(axis=0) for _, v in elements])
        cell = []
        for d, g in enumerate((part.xs, part.ys)):  # each element spans exactly one interval per direction
            i, j = (np.argmin(np.abs(g[None, :] - b[:, d, None]), axis=1) for b in (lo, hi))
            cell.append(np.where(j == i + 1, i, -1))
        counts = np.bincount(np.maximum(cell[0], 0) * (len(part.ys) - 1) + np.maximum(cell[1], 0),
                             minlength=part.cells)
        if (any(len(v) != nv for _, v in elements) or np.any(cell[0] < 0) or np.any(cell[1] < 0)
                or np.any(counts != per_cell) or part.xs[0] != 0.0 or part.ys[0] != 0.0
                or part.xs[-1] != self.width or part.ys[-1] != 1.0):
            raise InputError("mesh", f"a face Γ tiled by a tensor grid of {self.cell}s "
                             f"({len(elements)} elements on {len(part.xs) - 1} x {len(part.ys) - 1} cells)")
        return part

    def partition_of(self, mesh) -> TensorPartition:
        """x and y breakpoints of the Γ boundary elements (a tensor grid, checked)."""
        return self._partition_of_elements(self._gamma_elements(mesh))

    def uniform_partition(self, n: int) -> TensorPartition:
        """The n × n tensor grid of the face (a structured trace)."""
        return TensorPartition(np.linspace(0.0, self.width, int(n) + 1), np.linspace(0.0, 1.0, int(n) + 1))

    def common_refinement(self, *partitions, tol: float = 1e-12) -> TensorPartition:
        """Union of the x breakpoints and of the y breakpoints, merging within ``tol`` (for
        triangles the tensor grid under them: :meth:`coupling_quadrature` cuts its cells)."""
        return TensorPartition(merge_breakpoints(np.concatenate([p.xs for p in partitions]), tol),
                               merge_breakpoints(np.concatenate([p.ys for p in partitions]), tol))

    def multiplier_partition(self, trace1, trace2, choice: str = "omega2", tol: float = 1e-12):
        check_choice(choice)
        if choice == "union":
            return self.common_refinement(trace1, trace2, tol=tol)
        return trace2 if choice == "omega2" else trace1

    def cells(self, partition) -> int:
        """Number of rectangles of ``partition``."""
        return partition.cells if isinstance(partition, TensorPartition) else 0

    def partition_key(self, partition) -> bytes:
        return np.asarray(partition.xs, float).tobytes() + b"|" + np.asarray(partition.ys, float).tobytes()

    def sample(self, partition, per_cell: int, upper: float | None = None) -> np.ndarray:
        """Tensor grid of the 1D samples of x and y (x-major order), shape (n, 2)."""
        t = np.linspace(0.0, 1.0, per_cell + 1)
        hi = 1.0 if upper is None else upper
        axes = [np.unique(np.clip((g[:-1, None] + np.outer(np.diff(g), t)).ravel(), 0.0, hi))
                for g in (np.asarray(partition.xs), np.asarray(partition.ys))]
        X, Y = np.meshgrid(*axes, indexing="ij")
        return np.column_stack([X.ravel(), Y.ravel()])

    @staticmethod
    def _cell_index(partition, x: np.ndarray):
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        ix = np.clip(np.searchsorted(partition.xs, x[:, 0], side="right") - 1, 0, len(partition.xs) - 2)
        iy = np.clip(np.searchsorted(partition.ys, x[:, 1], side="right") - 1, 0, len(partition.ys) - 2)
        return ix, iy

    def at_boundary(self, partition, x: np.ndarray) -> np.ndarray:
        """Whether each point lies in a rectangle touching ∂Γ."""
        ix, iy = self._cell_index(partition, x)
        return (ix == 0) | (iy == 0) | (ix == len(partition.xs) - 2) | (iy == len(partition.ys) - 2)

    # --- trace dofs
    def trace(self, fes) -> GammaTrace:
        """Collect the Γ boundary elements (element, vertex coordinates, dofs) and the free Γ dofs."""
        free = fes.FreeDofs()
        elements, dofs = [], set()
        for el, verts in self._gamma_elements(fes.mesh):
            dn = np.array(fes.GetDofNrs(el))
            elements.append((verts, dn, el))
            dofs.update(int(d) for d in dn if d >= 0 and free[int(d)])
        part = self._partition_of_elements([(el, v) for v, _, el in elements])
        return GammaTrace(fes, np.array(sorted(dofs), dtype=int), elements, part, self)

    def _reference(self, verts: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Reference coordinates in one element (affine: rectangles and triangles) of points x.

        NGSolve's reference quadrilateral has its vertices 0, 1, 2, 3 at (0,0), (1,0), (1,1),
        (0,1); its reference triangle at (1,0), (0,1), (0,0).
        """
        if self.cell == "quad":
            origin, e1, e2 = verts[0], verts[1] - verts[0], verts[3] - verts[0]
        else:
            origin, e1, e2 = verts[2], verts[0] - verts[2], verts[1] - verts[2]
        return np.linalg.solve(np.column_stack([e1, e2]), (x - origin).T).T

    def trace_values(self, trace: GammaTrace, x: np.ndarray) -> np.ndarray:
        """Dense values (len(x), number of Γ dofs) of the Γ-dof basis at points x of Γ."""
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        phi = np.zeros((len(x), len(trace.gamma_dofs)))
        for pts, cols, shapes in self._trace_blocks(trace, x):
            phi[np.ix_(pts, cols)] += shapes
        return phi

    def sparse_trace_basis(self, trace: GammaTrace, x: np.ndarray):
        """:meth:`trace_values` as CSR without the dense (len(x), n_Γ) array: exactly
        ``csr_matrix(trace_values(trace, x))`` (the same values; sorted indices, no stored zeros),
        since every point is taken by one element, whose Γ dofs are distinct."""
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        blocks = list(self._trace_blocks(trace, x))
        rows = np.concatenate([np.repeat(p, len(c)) for p, c, _ in blocks] or [np.zeros(0, int)])
        cols = np.concatenate([np.tile(c, len(p)) for p, c, _ in blocks] or [np.zeros(0, int)])
        vals = np.concatenate([v.ravel() for _, _, v in blocks] or [np.zeros(0)])
        keep = vals != 0
        phi = sp.coo_matrix((vals[keep], (rows[keep], cols[keep])), shape=(len(x), len(trace.gamma_dofs))).tocsr()
        phi.sum_duplicates()  # sorts the column indices
        return phi

    def _trace_blocks(self, trace: GammaTrace, x: np.ndarray):
        """(points, Γ-dof positions, shape values (points, positions)) per trace element: the
        points of x (n, 2) it takes (those of its cell of the trace partition not taken by an
        earlier element of the cell, ascending) and its basis functions there (NGSolve's CalcShape)."""
        part = trace.breakpoints
        position = -np.ones(trace.fes.ndof, dtype=int)
        position[trace.gamma_dofs] = np.arange(len(trace.gamma_dofs))
        by_cell = {}
        for e, (verts, _, _) in enumerate(trace.elements):
            c = self._cell_index(part, verts.mean(axis=0)[None, :])
            by_cell.setdefault((int(c[0][0]), int(c[1][0])), []).append(e)
        ix, iy = self._cell_index(part, x)
        ny = len(part.ys) - 1
        cell = ix * ny + iy
        order = np.argsort(cell, kind="stable")  # the points of every cell, ascending
        bounds = np.searchsorted(cell[order], np.arange(cell.max(initial=-1) + 2))
        tol = 1e-10
        found = []  # (points, Γ-dof positions, kept, element, reference coordinates) per element taking points
        for (cx, cy), elems in by_cell.items():
            c = cx * ny + cy
            pts = order[bounds[c]:bounds[c + 1]] if c + 1 < len(bounds) else order[:0]
            todo = np.ones(len(pts), dtype=bool)
            for e in elems:
                verts, dn, el = trace.elements[e]
                ref = self._reference(verts, x[pts])
                inside = todo & np.all(ref >= -tol, axis=1)
                if self.cell == "trig":
                    inside &= ref.sum(axis=1) <= 1.0 + tol
                if not inside.any():
                    continue
                todo &= ~inside
                pos = position[dn]
                found.append((pts[inside], pos, pos >= 0, el, ref[inside]))
        values = shape_values(trace.fes, [(el, ref, len(pos)) for _, pos, _, el, ref in found])
        for (pts, pos, keep, _, _), shapes in zip(found, values):
            yield pts, pos[keep], shapes[:, keep]

    def trace_basis(self, trace: GammaTrace, x: np.ndarray) -> np.ndarray:
        """Dense values of the Γ-dof basis at the points x (n, 2), cached on the trace
        (read-only) as :meth:`Segment.trace_basis <.segment.Segment.trace_basis>` does."""
        return trace.cached_basis(x, lambda x: self.trace_values(trace, x))

    # --- quadrature and norms
    def quadrature(self, partition, degree: int) -> tuple:
        """Tensor Gauss–Legendre rule per rectangle, exact for degree ``degree`` in each
        variable (Q_degree, which contains P_degree): ⌊degree/2⌋ + 1 points per direction."""
        t, w = gauss_legendre(degree // 2 + 1)

        def axis(g):
            g = np.asarray(g, dtype=float)
            a, b = g[:-1, None], g[1:, None]
            return (0.5 * (a + b) + 0.5 * (b - a) * t).ravel(), (0.5 * (b - a) * w).ravel()

        if self.cell == "trig":  # both triangles of every cell, total degree 2 degree (⊇ Q_degree)
            return split_rule(partition, partition, 2 * degree)
        (x, wx), (y, wy) = axis(partition.xs), axis(partition.ys)
        X, Y = np.meshgrid(x, y, indexing="ij")
        return np.column_stack([X.ravel(), Y.ravel()]), np.outer(wx, wy).ravel()

    def coupling_quadrature(self, trace: GammaTrace, space, degree: int) -> tuple:
        """Quadrature ``degree`` on the common refinement of the trace and G_h; for triangles
        every rectangle is cut by the diagonal of the trace cell containing it
        (:func:`~.face.partitions.quadrature.split_rule`), exact for the P_k × Q_s products. A space that is
        polynomial only on a finer tensor partition (its ``pieces``: 4C pwlin) is integrated on those."""
        pieces = space.pieces
        if pieces is None:
            raise InputError("space", "a face space polynomial on the rectangles of a tensor partition",
                             got=space.name)
        if self.cell != "trig":
            return self.quadrature(self.common_refinement(trace.partition, pieces), degree)
        return split_rule(self.common_refinement(trace.partition, pieces), trace.partition, 2 * degree,
                          space.breakpoints)

    def gram(self, space, norm: str, h_route: str = "logkernel", **kwargs) -> tuple:
        """:func:`~.face.norms.tensor.gram`: L² exactly (kron of the 1D Grams), H by the double sine
        series (the only route on the square: ``h_route`` "logkernel", the command line's
        default, and "series" both name it; ``n_max`` > 0 in ``info`` says it is a series).
        A non-tensor space: :mod:`.face.norms.cellwise` (same norms, same series)."""
        from ..norms.cellwise import gram_cellwise
        from ..norms.tensor import gram
        from ..norms.triangles import gram as gram_triangles
        from ..spaces.triangles import TriangleSpace

        if isinstance(space, TriangleSpace):
            return gram_triangles(space, norm, **kwargs)
        return (gram if space.factors is not None else gram_cellwise)(space, norm, **kwargs)

    def gram_independent(self, space) -> bool:
        """Whether ``space``'s Grams share nothing with another space's (a tensor space: numpy alone,
        no shared series), so two may be computed at once (:class:`~infsup_contact.solvers.side_cache.GramCache`)."""
        return getattr(space, "factors", None) is not None  # :meth:`gram`'s tensor route

    def gram_session(self):
        """Spaces on one G_h that share a piece space reuse its series
        (:func:`~.face.norms.cellwise.shared_piece_sums`)."""
        from ..norms.cellwise import shared_piece_sums

        return shared_piece_sums()

    def builds(self, spec) -> bool:
        """Whether ``spec`` is defined on this face's cells (``spec.face_cells``)."""
        return self.cell in spec.face_cells

    def check_builds(self, spec) -> None:
        if not self.builds(spec):
            own = " and ".join(CELL_BODIES.get(c, c) for c in spec.face_cells)
            raise InputError("case", f"a space defined on the faces of {CELL_BODIES.get(self.cell, self.cell)} "
                             f"({spec.id} is built on the faces of {own} only)", got=spec.id)

    def space(self, spec, k: int, partition):
        """The tensor product of ``spec``'s 1D space on xs and on ys (:class:`.face.spaces.tensor.FaceSpace`),
        or the entry's own face space where it has one (``spec.face_build``: the cellwise element
        spaces of :mod:`.face.spaces.cellwise`); on triangles (``cell="trig"``) a Lagrange case
        (``spec.lagrange``) is P_s on the triangles of G_h instead
        (:class:`.face.spaces.triangles.TriangleSpace`, s = ``spec.degree(k)``; a dual basis
        (``spec.dual``) for s ∈ {1, 2} only, TRI3 / TRI6: the tensor dual above)."""
        from ..spaces.tensor import FaceSpace
        from ..spaces.triangles import DUAL_ELEMENTS, TriangleSpace

        if not isinstance(partition, TensorPartition) or partition.cells < 1:
            raise InputError("multiplier mesh", f"a tensor partition of Γ with at least one rectangle "
                             f"(case {spec.id}, k = {k})")
        self.check_builds(spec)
        if spec.face_build is not None:
            return spec.face_build(k, partition)
        s, dual = int(spec.degree(k)), spec.dual
        if self.cell == "trig" and spec.lagrange is not None and (not dual or s in DUAL_ELEMENTS):
            return TriangleSpace(partition, s, *spec.lagrange, dual=dual)
        return FaceSpace(spec.build(k, np.asarray(partition.xs, float)),
                         spec.build(k, np.asarray(partition.ys, float)), partition)

    # --- spaces and counts
    def trace_dimension(self, k: int, cells: int) -> int:
        """dim W_h = (n k − 1)² on an n × n grid (``cells`` is n, the cells per direction):
        continuous Q_k (or P_k on the triangles) vanishing on ∂Γ has one dof per interior
        node of the (n k + 1)² Lagrange lattice."""
        return (cells * k - 1) ** 2

    def trace_sum_dimension(self, k: int, trace1, trace2) -> int:
        """dim(W1 + W2) = dim W1 + dim W2 − dim(W1 ∩ W2), per direction products.

        For quadrilaterals W_i = W_i^x ⊗ W_i^y (1D traces vanishing at the ends, dim n k − 1) and
        (A ⊗ A') ∩ (B ⊗ B') = (A ∩ B) ⊗ (A' ∩ B'); A ∩ B is the 1D trace space on the common
        coarsening (the shared breakpoints). For triangles the space on the common coarsening
        (cut by the same diagonals) is a subspace of W1 ∩ W2 when both grids are uniform, so the
        count is an upper bound of dim(W1 + W2) and the proven kernel stays a lower bound; it
        equals the numerical rank of both trace bases on every pair tested (k = 1..3)."""
        d = [(len(p.xs) - 1) * k - 1 for p in (trace1, trace2)]
        e = [(len(p.ys) - 1) * k - 1 for p in (trace1, trace2)]
        dc = (coarsening_cells(trace1.xs, trace2.xs) * k - 1) * (coarsening_cells(trace1.ys, trace2.ys) * k - 1)
        return d[0] * e[0] + d[1] * e[1] - max(dc, 0)

    def proven_kernel(self, space, k: int, traces, dim_w: int) -> int:
        """max(dim M − dim(W1 + W2), 0), and on triangles the checkerboard mode
        (:meth:`checkerboard_modes`): rank B <= dim M − 1 where it exists."""
        glob = max(space.dim - dim_w, 0)
        return max(glob, self.checkerboard_modes(space, k, [t.partition for t in traces]))

    def checkerboard_modes(self, space, k: int, trace_partitions) -> int:
        """1 where a discontinuous P_0 multiplier space and P_2 traces live on the same triangles, else 0.

        Every rectangle is cut by the same diagonal, so the triangles are two-coloured: lower
        and upper, and triangles sharing an edge have opposite colours. Let μ = ±1/|T| (lower +,
        upper −). A P_2 trace vanishing on ∂Γ is spanned by vertex functions, whose integral over
        every triangle is 0 (∫_T λ_v (2λ_v − 1) = 0), and interior-edge functions, with ∫_T φ_e =
        |T|/3 on the two triangles of the edge; so b(φ, μ) = 0 for every trace function of both
        sides when their triangles are those of G_h: μ is in the kernel of Bᵀ whatever the
        dimension count says (T4 at k = 2 on tetrahedra: the count is 0, the kernel 1). Not
        for P_k, k ≠ 2 (P_1 and P_3 vertex functions have non-zero integrals), nor where a trace's
        triangles differ from G_h's (non-matching meshes)."""
        if self.cell != "trig" or k != 2 or not space.lives_on_triangles or space.degree != 0 or space.continuous:
            return 0
        key = self.partition_key(space.breakpoints)
        return int(all(self.partition_key(p) == key for p in trace_partitions))

    def trace_nodes(self, k: int, cells: int) -> int:
        """(n k + 1)² Γ nodes of a side on an n × n grid, boundary included."""
        return (cells * k + 1) ** 2

    def multiplier_cells(self, n1: int, n2: int, choice: str = "omega2") -> int:
        """Rectangles of G_h for n1 × n1 and n2 × n2 traces: the intervals per direction squared."""
        return intervals_per_direction(n1, n2, choice) ** 2


SQUARE = Square()
"""Γ = (0, 1)² × {1} of the hexahedral meshes."""
SQUARE_TRIG = Square(cell="trig")
"""The same face, traced by tetrahedral meshes (rectangles cut in two triangles)."""
