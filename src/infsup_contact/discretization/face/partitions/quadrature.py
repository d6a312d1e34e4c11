"""Exact quadrature on the face for traces of tetrahedral meshes (P_k on triangles).

The Γ trace of the six-tetrahedra split of a structured grid is P_k on the triangles that the
diagonal from (x_i, y_j) to (x_{i+1}, y_{j+1}) cuts every rectangle into. A multiplier is Q_s on
the rectangles of G_h. Their product is a polynomial (of total degree ≤ k + 2s) on every piece
of a rectangle R of the tensor common refinement of the trace grid and G_h cut by the diagonal
of the trace cell that contains R: at most two convex polygons per rectangle (a triangle and a
pentagon, or two quadrilaterals, or two triangles when the diagonal is R's own). A multiplier
that is P_s on the triangles of G_h (:mod:`.face.spaces.triangles`) is cut by the diagonal of its own
cell as well (at most four pieces per rectangle; the product then has total degree ≤ k + s
on each). Each polygon is
fanned into triangles, each integrated by the collapsed (Duffy) Gauss rule
u = s, v = t(1 − s), Jacobian 1 − s, exact for total degree d with ⌊(d + 1)/2⌋ + 1 points in s and
⌊d/2⌋ + 1 in t.
"""
from __future__ import annotations

import numpy as np

from ...gamma.quadrature import gauss_legendre_01


def duffy_rule(degree: int) -> tuple:
    """(u, v, w) on the reference triangle (0,0), (1,0), (0,1), exact for total degree ``degree``."""
    s, ws = gauss_legendre_01((degree + 1) // 2 + 1)
    t, wt = gauss_legendre_01(degree // 2 + 1)
    S, T = np.meshgrid(s, t, indexing="ij")
    return S.ravel(), (T * (1.0 - S)).ravel(), (np.outer(ws, wt) * (1.0 - s)[:, None]).ravel()


def triangles_rule(tri: np.ndarray, degree: int) -> tuple:
    """Points (n, 2) and weights of the Duffy rule on every triangle of ``tri`` (T, 3, 2)."""
    u, v, w = duffy_rule(degree)
    a, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    det = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    pts = a[:, None, :] + u[None, :, None] * e1[:, None, :] + v[None, :, None] * e2[:, None, :]
    return pts.reshape(-1, 2), (det[:, None] * w[None, :]).ravel()


def _clip(poly: np.ndarray, f: np.ndarray, sign: float) -> np.ndarray:
    """The part of the convex polygon ``poly`` where sign · f ≥ 0 (f: values at its vertices)."""
    out = []
    n = len(poly)
    for i in range(n):
        j = (i + 1) % n
        fi, fj = sign * f[i], sign * f[j]
        if fi >= 0:
            out.append(poly[i])
        if (fi > 0 > fj) or (fi < 0 < fj):
            out.append(poly[i] + fi / (fi - fj) * (poly[j] - poly[i]))
    return np.array(out)


def _diagonal(poly: np.ndarray, grid) -> np.ndarray:
    """Diagonal coordinate at the vertices of ``poly`` (inside one rectangle of ``grid``) of the
    ``grid`` cell containing it: ≥ 0 below the cell's diagonal, ≤ 0 above."""
    gx, gy = np.asarray(grid.xs, float), np.asarray(grid.ys, float)
    c = poly.mean(axis=0)
    ci = min(max(np.searchsorted(gx, c[0]) - 1, 0), len(gx) - 2)
    cj = min(max(np.searchsorted(gy, c[1]) - 1, 0), len(gy) - 2)
    f = (poly[:, 0] - gx[ci]) / (gx[ci + 1] - gx[ci]) - (poly[:, 1] - gy[cj]) / (gy[cj + 1] - gy[cj])
    return np.where(np.abs(f) < 1e-13, 0.0, f)


def split_triangles(refinement, trace, *more) -> np.ndarray:
    """Triangles (T, 3, 2) tiling the face: every rectangle of ``refinement`` (a tensor partition
    refining ``trace`` and every partition in ``more``) cut by the diagonal of the ``trace`` cell
    containing it (and by those of the cells of ``more``, e.g. a triangulated G_h), then fanned."""
    xs, ys = np.asarray(refinement.xs, float), np.asarray(refinement.ys, float)
    tris = []
    for i in range(len(xs) - 1):
        for j in range(len(ys) - 1):
            pieces = [np.array([[xs[i], ys[j]], [xs[i + 1], ys[j]], [xs[i + 1], ys[j + 1]], [xs[i], ys[j + 1]]])]
            for grid in (trace,) + more:
                pieces = [q for p in pieces for sign in (1.0, -1.0)
                          for q in [_clip(p, _diagonal(p, grid), sign)] if len(q) >= 3]
            for poly in pieces:
                for m in range(1, len(poly) - 1):
                    tri = np.array([poly[0], poly[m], poly[m + 1]])
                    e1, e2 = tri[1] - tri[0], tri[2] - tri[0]
                    if abs(e1[0] * e2[1] - e1[1] * e2[0]) > 1e-14 * (xs[i + 1] - xs[i]) * (ys[j + 1] - ys[j]):
                        tris.append(tri)
    return np.array(tris)


def split_rule(refinement, trace, degree: int, *more) -> tuple:
    """Points and weights exact for total degree ``degree`` on every piece of
    :func:`split_triangles` (a P_k trace on ``trace``'s triangles times Q_s on ``refinement``,
    or P_s on the triangles of the partitions ``more``)."""
    return triangles_rule(split_triangles(refinement, trace, *more), degree)
