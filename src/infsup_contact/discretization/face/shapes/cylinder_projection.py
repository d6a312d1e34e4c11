"""The mortar coupling by normal projection on the cylinder (:mod:`.cylinder`), hexahedral bodies.

As on the arc (:mod:`..segment.projection`, whose formulas these are), the integral runs over the
discrete surface of the side that carries G_h (the slave), the other side (the master) evaluated
where the line through the slave's point along the slave's averaged nodal normal meets the
master's surface:

    B_slave[j, d] = ∫_{Γ_h^s} μ_j φ^s_d dS,      B_master[j, d] = ∫_{Γ_h^s} μ_j (φ^m_d ∘ P) dS.

On a structured hexahedral body both Φ and its tensor-product interpolant leave y alone, so each
side's discrete Γ is a product: a degree-k curve p(x) in the (X, Z) plane (read from the face
elements, :func:`face_curve`) times the line y. Its normals lie in that plane, so P(x, y) =
(P_x(x), y) with P_x the arc's 1D projection of the two curves, and dS = |p_s'(x)| dx dy. The
clipping of the projected master cells against the slave cells and G_h is then a tensor
refinement: in x the slave's breakpoints, G_h's (its pieces') and the pre-images P_x⁻¹ of the
master's; in y the union of all three partitions. Each rectangle gets the tensor Gauss rule, in x
:data:`~..segment.projection.EXTRA_POINTS` points above the degree of μ φ (P_x and |p_s'| are not
polynomials), in y exact. Where the slave's normal misses the master (near x = 0, 1) the master
contributes nothing. On matching meshes the two surfaces are the same and P the identity.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ....errors import InputError
from ...segment.interface import SEGMENT
from ...segment.projection import EXTRA_POINTS, curve_nodes, fit_curve, preimages, project
from .cylinder import Cylinder
from ..partitions.tensor_grid import merge_breakpoints

TOL = 1e-12
"""Breakpoints closer than this are one (as :meth:`~.square.Square.common_refinement` merges them)."""


def face_curve(trace, k: int):
    """The x-curve (a :class:`~..segment.projection.SideCurve` in (X, Z)) of a side's discrete Γ,
    read from the maps of its face elements in the first row of y cells (the surface is a
    product, module docstring: every row gives the same curve; tested)."""
    mesh, part = trace.fes.mesh, trace.partition
    xs, y0, y1 = np.asarray(part.xs, float), part.ys[0], part.ys[1]
    by_cell = {}
    for verts, _, el in trace.elements:
        lo, hi = verts.min(axis=0), verts.max(axis=0)
        if abs(lo[1] - y0) < TOL and abs(hi[1] - y1) < TOL:
            by_cell[int(np.argmin(np.abs(xs - lo[0])))] = (verts, el)
    u, points = curve_nodes(k), []
    for e in range(len(xs) - 1):
        verts, el = by_cell[e]
        x = np.column_stack([xs[e] + u * (xs[e + 1] - xs[e]), np.full(len(u), 0.5 * (y0 + y1))])
        ref = trace.gamma._reference(verts, x)
        trafo = mesh.GetTrafo(el)
        points.append(np.array([np.asarray(trafo(a, b).point)[[0, 2]] for a, b in ref]))
    return fit_curve(xs, points, k)


def _same(a, b) -> bool:
    return all(len(p) == len(q) and np.allclose(p, q, rtol=0, atol=TOL) for p, q in ((a.xs, b.xs), (a.ys, b.ys)))


@dataclass(frozen=True)
class ProjectedCylinder(Cylinder):
    """The cylinder as side ``side`` of a pair coupled by projection sees it: both sides' x-curves
    and trace partitions (:func:`project_pair`), and the coupling points of the module docstring."""

    curves: tuple = field(default=(), compare=False, repr=False)
    partitions: tuple = field(default=(), compare=False, repr=False)
    side: int = 0

    def slave_of(self, g_h) -> int:
        """0 (Ω1) when G_h is Ω1's trace and not Ω2's, else 1 (Ω2)."""
        p1, p2 = self.partitions
        return 0 if _same(g_h, p1) and not _same(g_h, p2) else 1

    def coupling_points(self, trace, space, degree: int) -> tuple:
        pieces = space.pieces
        if pieces is None:
            raise InputError("space", "a face space polynomial on the rectangles of a tensor partition",
                             got=space.name)
        slave = self.slave_of(space.breakpoints)
        s, m = self.curves[slave], self.curves[1 - slave]
        xs = merge_breakpoints(np.concatenate([s.breakpoints, pieces.xs, preimages(s, m, m.breakpoints)]), TOL)
        ys = merge_breakpoints(np.concatenate([p.ys for p in self.partitions] + [pieces.ys]), TOL)
        x, wx = SEGMENT.quadrature(xs, degree + 2 * EXTRA_POINTS)  # degree // 2 + 1 + EXTRA_POINTS points
        y, wy = SEGMENT.quadrature(ys, degree)
        wx = wx * np.linalg.norm(s.point(x)[1], axis=1)  # dS = |p_s'(x)| dx dy
        points = _grid(x, y)
        if self.side == slave:
            return points, points, np.outer(wx, wy).ravel()
        px = project(s, m, x)
        inside = (px >= 0.0) & (px <= 1.0)  # the normal misses the master's surface: no master there
        return points, _grid(np.clip(px, 0.0, 1.0), y), np.outer(wx * inside, wy).ravel()

    def proven_kernel(self, space, k: int, traces, dim_w: int) -> int:
        """The count of matching meshes (identical surfaces, P = id); else only dim M − n1 − n2 (the
        rank of Bᵀ is at most the number of Γ dofs): the projected traces do not share W1 ∩ W2."""
        p1, p2 = (t.partition for t in traces)
        if _same(p1, p2):
            return super().proven_kernel(space, k, traces, dim_w)
        return max(space.dim - sum(len(t.gamma_dofs) for t in traces), 0)

    def paired(self, sides: list) -> list:
        return sides


def _grid(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The tensor grid of points (x_i, y_j), x-major, (n, 2): :meth:`~.square.Square.quadrature`'s order."""
    X, Y = np.meshgrid(x, y, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel()])


def project_pair(cylinder: Cylinder, sides: list) -> list:
    """The two sides with traces whose Γ is the :class:`ProjectedCylinder` of the pair (fresh
    caches: the master's basis is asked at projected points)."""
    k = int(sides[0].trace.fes.globalorder)
    curves = tuple(face_curve(s.trace, k) for s in sides)
    partitions = tuple(s.trace.partition for s in sides)
    out = []
    for i, s in enumerate(sides):
        view = ProjectedCylinder(boundary=cylinder.boundary, z=cylinder.z, cell=cylinder.cell, width=cylinder.width,
                                 radius=cylinder.radius, coupling=cylinder.coupling, curves=curves,
                                 partitions=partitions, side=i)
        out.append(replace(s, trace=replace(s.trace, gamma=view, basis_cache={}, sparse_cache={})))
    return out
