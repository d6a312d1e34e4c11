"""Γ = (0, 1)² × {1} traced by any tetrahedral mesh: partitions are general triangulations.

:class:`TriangulatedSquare` is the third implementation of :class:`~.gamma.interface.Interface`, a
sibling of :class:`~.face.shapes.square.Square` (whose partitions are tensor grids): the face of
unstructured (Netgen) and perturbed tetrahedral meshes, Ω1 and Ω2 meshed
independently, so their traces do not match. Its partition is a
:class:`~.face.partitions.triangulation.Triangulation`; the common refinement is the polygon overlay of two
triangulations (shapely, :func:`~.face.partitions.triangulation.overlay`), fanned into triangles, on which a
P_k trace times a P_s multiplier is a polynomial of total degree k + s: the Duffy rule there is
exact (:meth:`quadrature`). The multiplier spaces of the registry's Lagrange cases
(``SpaceSpec.lagrange``, duals ``SpaceSpec.dual`` of degree 1 or 2) are P_s on the triangles of
G_h (:mod:`.face.spaces.unstructured`), their Grams :mod:`.face.norms.unstructured` (L² exact, H^{-1/2}_00 by the
closed-form Fourier transform of every triangle). The trace basis is NGSolve's: each point is
located in its boundary element and the element's ``CalcShape`` evaluated there.

Dimension counts: dim W_i (continuous P_k on trace i vanishing on ∂Γ) is the number of P_k
lattice nodes off ∂Γ (exact); dim(W1 ∩ W2) is bounded below by the nodes whose triangles are
triangles of both traces (:func:`~.face.partitions.triangulation.matched_interior_nodes`; exact for equal
traces, 0 for generic non-matching ones), so :meth:`trace_sum_dimension` is an upper bound of
dim(W1 + W2) and the global count max(dim M − dim(W1 + W2), 0) a lower bound of the kernel;
:meth:`proven_kernel` adds the modes at the corners of Γ that it misses. The counts that
take a number of cells (:meth:`trace_dimension`, :meth:`trace_nodes`,
:meth:`multiplier_cells`: sizing and emptiness checks) are those of the structured N × N grid.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ....errors import InputError
from ...gamma.interface import Interface, check_choice
from ...gamma.trace import GammaTrace
from .square import SQUARE_TRIG
from ..partitions.triangulation import (CORNERS, Triangulation, contains, corner_triangles, from_elements, interior_nodes,
                            locate, matched_interior_nodes, on_boundary, overlay)
from ..partitions.quadrature import triangles_rule

#: Common refinements a face keeps (by the keys of their inputs).
_REFINEMENT_CACHE = 8


@dataclass(frozen=True)
class TriangulatedSquare(Interface):
    """Γ = (0, 1)² × {z} whose partitions are :class:`~.face.partitions.triangulation.Triangulation` s.

    Attributes
    ----------
    boundary : str
        Name of Γ's boundary region in the meshes (``gamma``).
    z : float
        Height of Γ.
    """

    boundary: str = "gamma"
    z: float = 1.0
    cache: dict = field(default_factory=dict, repr=False, compare=False, hash=False)

    @property
    def dim(self) -> int:
        return 2

    def embed(self, x):
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        return x[:, 0], x[:, 1], np.full(len(x), self.z)

    # --- partitions
    def _gamma_elements(self, mesh):
        import ngsolve

        out = [(el, np.array([mesh[v].point[:2] for v in el.vertices]))
               for el in mesh.Elements(ngsolve.BND) if el.mat == self.boundary]
        if not out:
            raise InputError("mesh", f"boundary elements named {self.boundary!r} on Γ")
        if any(len(v) != 3 for _, v in out):
            raise InputError("mesh", "a face Γ of triangles (a tetrahedral mesh)")
        return out

    def _partition(self, vertex_sets, order: bool = False):
        tri, perm = from_elements(vertex_sets, order=True)
        if abs(tri.areas.sum() - 1.0) > 1e-10 or tri.points.min() < -1e-12 or tri.points.max() > 1 + 1e-12:
            raise InputError("mesh", f"a face Γ = (0, 1)² tiled by its triangles (area {tri.areas.sum():.6g})")
        return (tri, perm) if order else tri

    def partition_of(self, mesh) -> Triangulation:
        """The triangles of the Γ boundary elements of ``mesh`` (they must tile (0, 1)²)."""
        return self._partition([v for _, v in self._gamma_elements(mesh)])

    def uniform_partition(self, n: int) -> Triangulation:
        """The Kuhn triangles of the n × n grid (each cell cut by its diagonal (x_i, y_j)–(x_i+1, y_j+1))."""
        x = np.linspace(0.0, 1.0, int(n) + 1)
        cells = [(x[i], x[i + 1], x[j], x[j + 1]) for i in range(int(n)) for j in range(int(n))]
        return self._partition([tri for a, b, c, d in cells for tri in (((a, c), (b, c), (b, d)), ((a, c), (b, d), (a, d)))])

    def common_refinement(self, *partitions, tol: float = 1e-12) -> Triangulation:
        """The overlay of the triangulations (shapely), fanned; one partition is returned as it is."""
        key = tuple(p.key for p in partitions)
        out = self.cache.get(key)
        if out is None:
            out = partitions[0]
            for p in partitions[1:]:
                out = overlay(out, p, tol)
            if len(self.cache) >= _REFINEMENT_CACHE:
                self.cache.clear()
            self.cache[key] = out
        return out

    def multiplier_partition(self, trace1, trace2, choice: str = "omega2", tol: float = 1e-12):
        """Ω2's or Ω1's trace, or the common refinement (``union``: the fanned overlay, a
        triangulation refining both, with T-junctions only where a vertex of one lies on an
        edge of the other)."""
        check_choice(choice)
        if choice == "union":
            r = self.common_refinement(trace1, trace2, tol=tol)
            return Triangulation(r.points, r.triangles)
        return trace2 if choice == "omega2" else trace1

    def cells(self, partition) -> int:
        return partition.cells if isinstance(partition, Triangulation) else 0

    def partition_key(self, partition) -> bytes:
        return partition.key

    def sample(self, partition, per_cell: int, upper: float | None = None) -> np.ndarray:
        """The P_{per_cell} lattice points of every triangle, duplicates removed, shape (n, 2)."""
        from ..spaces.triangles import local_lattice
        from ..partitions.triangulation import glue

        alpha = local_lattice(max(int(per_cell), 1)).astype(float) / max(int(per_cell), 1)
        pts = np.einsum("la,tac->tlc", alpha, partition.corners).reshape(-1, 2)
        pts = np.clip(pts, 0.0, 1.0 if upper is None else upper)
        x, _ = glue(pts, 1e-12)
        return x[np.lexsort((x[:, 1], x[:, 0]))]

    def at_boundary(self, partition, x: np.ndarray) -> np.ndarray:
        """Whether each point lies in a triangle with a vertex on ∂Γ."""
        touching = on_boundary(partition.points)[partition.triangles].any(axis=1)
        return touching[locate(partition, x)[0]]

    # --- trace dofs
    def trace(self, fes) -> GammaTrace:
        """The Γ boundary elements (vertex coordinates, dofs, element) and the free Γ dofs."""
        free = fes.FreeDofs()
        elements, dofs = [], set()
        for el, verts in self._gamma_elements(fes.mesh):
            dn = np.array(fes.GetDofNrs(el))
            elements.append((verts, dn, el))
            dofs.update(int(d) for d in dn if d >= 0 and free[int(d)])
        part, perm = self._partition([v for v, _, _ in elements], order=True)
        elements = [elements[i] for i in perm]  # in the partition's order (trace_values locates there)
        return GammaTrace(fes, np.array(sorted(dofs), dtype=int), elements, part, self)

    def trace_values(self, trace: GammaTrace, x: np.ndarray) -> np.ndarray:
        """Dense values (len(x), Γ dofs) of the Γ-dof basis: each point located in a boundary
        element (the trace partition keeps their order), NGSolve's ``CalcShape`` at its reference
        coordinates (reference triangle vertices 0, 1, 2 at (1, 0), (0, 1), (0, 0))."""
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        position = -np.ones(trace.fes.ndof, dtype=int)
        position[trace.gamma_dofs] = np.arange(len(trace.gamma_dofs))
        tri, _ = locate(trace.partition, x)
        phi = np.zeros((len(x), len(trace.gamma_dofs)))
        for e in np.unique(tri):
            verts, dn, el = trace.elements[e]
            pts = np.flatnonzero(tri == e)
            origin, e1, e2 = verts[2], verts[0] - verts[2], verts[1] - verts[2]
            ref = np.linalg.solve(np.column_stack([e1, e2]), (x[pts] - origin).T).T
            fe = trace.fes.GetFE(el)
            pos = position[dn]
            keep = pos >= 0
            if not keep.any():
                continue
            shapes = np.array([np.asarray(fe.CalcShape(a, b, 0.0)) for a, b in ref])
            phi[np.ix_(pts, pos[keep])] += shapes[:, keep]
        return phi

    def trace_basis(self, trace: GammaTrace, x: np.ndarray) -> np.ndarray:
        """:meth:`trace_values`, cached on the trace (read-only)."""
        return trace.cached_basis(x, lambda x: self.trace_values(trace, x))

    # --- quadrature and norms
    def quadrature(self, partition, degree: int) -> tuple:
        """The Duffy rule on every triangle, exact for total degree ``degree``."""
        return triangles_rule(partition.corners, int(degree))

    def coupling_quadrature(self, trace: GammaTrace, space, degree: int) -> tuple:
        """Exact for ``degree`` on the overlay of the trace and G_h (P_k × P_s is polynomial there)."""
        return self.quadrature(self.common_refinement(trace.partition, space.breakpoints), degree)

    def gram(self, space, norm: str, h_route: str = "logkernel", **kwargs) -> tuple:
        """:func:`~.face.norms.unstructured.gram`: L² exact, H by the extrapolated double sine series
        with exact coefficients (the only route here, as on :class:`~.face.shapes.square.Square`)."""
        from ..norms.unstructured import gram

        return gram(space, norm, **kwargs)

    def builds(self, spec) -> bool:
        """Whether ``spec`` has a space on triangles of a general G_h: a Lagrange case, its dual
        of degree 1 or 2 (checked when built)."""
        return spec.lagrange is not None and "trig" in spec.face_cells

    def check_builds(self, spec) -> None:
        if not self.builds(spec):
            raise InputError("case", f"a Lagrange case or its dual on a general triangulation of Γ "
                             f"({spec.id} has no space on triangles)", got=spec.id)

    def space(self, spec, k: int, partition):
        """P_s on the triangles of G_h (:class:`~.face.spaces.unstructured.MeshTriangleSpace`,
        s = ``spec.degree(k)``, continuity and ∂Γ condition from ``spec.lagrange``, dual basis for
        ``spec.dual``)."""
        from ..spaces.unstructured import mesh_space

        if not isinstance(partition, Triangulation):
            raise InputError("multiplier mesh", f"a triangulation of Γ (case {spec.id}, k = {k})")
        self.check_builds(spec)
        continuous, vanish = spec.lagrange
        return mesh_space(partition, int(spec.degree(k)), continuous, vanish, spec.dual)

    # --- counts
    def trace_dimension(self, k: int, cells: int) -> int:
        """Of the structured N × N triangles (``cells`` = N): (N k − 1)²."""
        return SQUARE_TRIG.trace_dimension(k, cells)

    def trace_dimension_of(self, k: int, partition, clamped: bool = True) -> int:
        """dim W_h of a triangulation: P_k lattice nodes off ∂Γ (exact; all nodes when the
        lateral faces are not clamped, e.g. a contact scene's natural ones)."""
        return interior_nodes(partition, k, clamped)

    def trace_sum_dimension(self, k: int, trace1, trace2) -> int:
        """dim W1 + dim W2 − (matched nodes, a lower bound of dim(W1 ∩ W2)): an upper bound of
        dim(W1 + W2), exact for equal traces (module docstring)."""
        return (self.trace_dimension_of(k, trace1) + self.trace_dimension_of(k, trace2)
                - matched_interior_nodes(trace1, trace2, k))

    def proven_kernel(self, space, k: int, traces, dim_w: int) -> int:
        """max(global count, corner count). Global: max(dim M − dim(W1 + W2), 0). Corners: for
        the star S of each corner c of Γ in G_h (its cells at c; stars sharing a cell are skipped),
        the multipliers supported in S (dim M_S) are orthogonal to both traces but for at most
        U = dim(W1|_S + W2|_S) of them; U is bounded by the free trace dofs on the trace cells
        meeting S, and where S lies in a corner triangle of a trace
        (:func:`~.face.partitions.triangulation.corner_triangles`) by k(k − 1)/2, the dimension of
        (x − c_x)(y − c_y) P_{k−2}, in which every trace function vanishing on both sides through
        c lies (one space for both sides when both contain S). Σ_c max(dim M_S − U, 0) is a lower
        bound of dim ker Bᵀ (the M_S of different corners are independent)."""
        glob = max(space.dim - dim_w, 0)
        from ..spaces.unstructured import MeshTriangleSpace

        if not isinstance(space, MeshTriangleSpace):
            return glob
        dofs = space._dofs
        g_h = space.breakpoints
        count = np.bincount(dofs[dofs >= 0], minlength=space.dim)
        q = k * (k - 1) // 2
        meets = [self.common_refinement(t.partition, g_h).parents for t in traces]  # (trace cell, G_h cell)
        free = [set(int(d) for d in t.gamma_dofs) for t in traces]
        corner = [corner_triangles(t.partition) for t in traces]
        local, used = 0, set()
        for c, point in enumerate(CORNERS):
            star = set(np.flatnonzero(np.any(np.all(np.abs(g_h.corners - point) < 1e-12, axis=2), axis=1)).tolist())
            if not star or star & used:
                continue
            used |= star
            own = sum(1 for cell in star for d in dofs[cell] if d >= 0 and count[d] == 1
                      and set(np.flatnonzero(np.any(dofs == d, axis=1)).tolist()) <= star)
            bounds, inside = [], []
            for t, m, f, cor in zip(traces, meets, free, corner):
                cells = np.unique(m[np.isin(m[:, 1], list(star)), 0])
                n_free = len({int(d) for e in cells for d in t.elements[e][1] if int(d) in f})
                ok = c in cor and contains(t.partition, cor[c], g_h.corners[list(star)].reshape(-1, 2))
                inside.append(ok)
                bounds.append(min(n_free, q) if ok else n_free)
            upper = min(sum(bounds), q) if all(inside) else sum(bounds)
            local += max(own - upper, 0)
        return max(glob, local)

    def trace_nodes(self, k: int, cells: int) -> int:
        return SQUARE_TRIG.trace_nodes(k, cells)

    def multiplier_cells(self, n1: int, n2: int, choice: str = "omega2") -> int:
        return SQUARE_TRIG.multiplier_cells(n1, n2, choice)


TRIANGULATED = TriangulatedSquare()
"""Γ = (0, 1)² × {1} of unstructured and perturbed tetrahedral meshes."""
