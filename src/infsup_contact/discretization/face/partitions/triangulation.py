"""General triangulations of the face Γ = (0, 1)² and their common refinement.

A :class:`Triangulation` is a vertex array and a triangle array: the trace on Γ of any
tetrahedral mesh (Netgen's unstructured meshes, perturbed structured ones), not only the
structured Kuhn split of :mod:`.face.shapes.square`. The coupling ∫_Γ v_i μ of a trace on one triangulation
and a multiplier on another is polynomial on every piece of their *common refinement*, the
overlay whose cells are the nonempty intersections T1 ∩ T2 of a triangle of each (convex
polygons). The intersections are computed with shapely (GEOS; ``STRtree`` for the candidate
pairs, ``intersection`` for the polygons), not by hand, and every polygon is fanned into
triangles from its first vertex, which keeps the parents (the triangle of each input
containing it) for the point location of the quadrature points (:func:`locate`).

Lagrange lattices (:func:`lattice`): the P_s nodes Σ_v α_v X_v / s (|α| = s) of every triangle,
glued by coordinates, give the continuous numbering of the P_s spaces
(:mod:`.face.spaces.unstructured`) and the trace counts of :class:`~.face.shapes.triangulated_square.TriangulatedSquare`.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ....errors import InputError
from ..spaces.triangles import local_lattice

#: Relative area below which an intersection polygon is a touching, not a cell.
AREA_TOL = 1e-12
#: Chunk of points located at once by :func:`locate` (memory ~ chunk × triangles).
_LOCATE_CHUNK = 2048


@dataclass(frozen=True, eq=False)
class Triangulation:
    """Triangles of Γ: ``points`` (nv, 2) and ``triangles`` (nt, 3) vertex indices,
    counter-clockwise. ``parents`` (nt, m): for a common refinement, the triangle of each of
    its m input triangulations containing each triangle (None for a trace)."""

    points: np.ndarray
    triangles: np.ndarray
    parents: np.ndarray | None = None

    def __post_init__(self):
        p, t = np.asarray(self.points, float), np.asarray(self.triangles, int)
        if p.ndim != 2 or p.shape[1] != 2 or t.ndim != 2 or t.shape[1] != 3 or len(t) < 1:
            raise InputError("triangulation", "points (nv, 2) and at least one triangle (nt, 3)",
                             got=(p.shape, t.shape))
        c = p[t]
        area = 0.5 * ((c[:, 1, 0] - c[:, 0, 0]) * (c[:, 2, 1] - c[:, 0, 1])
                      - (c[:, 1, 1] - c[:, 0, 1]) * (c[:, 2, 0] - c[:, 0, 0]))
        t = np.where((area < 0)[:, None], t[:, [0, 2, 1]], t)  # counter-clockwise
        object.__setattr__(self, "points", p)
        object.__setattr__(self, "triangles", t)

    @property
    def cells(self) -> int:
        return len(self.triangles)

    def interior_points(self, per: int) -> np.ndarray:
        """A barycentric grid of points strictly inside every triangle, (n, 2)."""
        i, j = np.meshgrid(np.arange(per), np.arange(per), indexing="ij")
        keep = (i + j) < per
        a, b = (i[keep] + 0.31) / (per + 1), (j[keep] + 0.29) / (per + 1)  # a, b > 0, a + b < 1
        c = np.asarray(self.points)[np.asarray(self.triangles)]
        pts = c[:, 0, None] + a[None, :, None] * (c[:, 1, None] - c[:, 0, None]) \
            + b[None, :, None] * (c[:, 2, None] - c[:, 0, None])
        return pts.reshape(-1, 2)

    @cached_property
    def corners(self) -> np.ndarray:
        """Vertex coordinates (nt, 3, 2)."""
        return self.points[self.triangles]

    @cached_property
    def areas(self) -> np.ndarray:
        c = self.corners
        return 0.5 * ((c[:, 1, 0] - c[:, 0, 0]) * (c[:, 2, 1] - c[:, 0, 1])
                      - (c[:, 1, 1] - c[:, 0, 1]) * (c[:, 2, 0] - c[:, 0, 0]))

    @property
    def key(self) -> bytes:
        return self.points.tobytes() + b"|" + self.triangles.tobytes()

    @property
    def nominal_n(self) -> int:
        """Cells per direction of the structured grid with as many triangles (2 N² ≈ nt)."""
        return max(int(round(np.sqrt(self.cells / 2.0))), 1)


def from_elements(vertex_sets, tol: float = 1e-12, order: bool = False):
    """The triangulation of a list of triangles given by their vertex coordinates (3, 2),
    vertices closer than ``tol`` merged (a trace's boundary elements), in a canonical order
    (points sorted, each triangle from its smallest vertex counter-clockwise, triangles sorted):
    equal triangulations have equal keys. ``order``: also return the input index of every
    triangle."""
    corners = np.array([np.asarray(v, float) for v in vertex_sets])
    if corners.ndim != 3 or corners.shape[1:] != (3, 2):
        raise InputError("mesh", "triangular boundary elements on Γ", got=corners.shape)
    points, index = glue(corners.reshape(-1, 2), tol)
    tri = Triangulation(points, index.reshape(-1, 3)).triangles  # counter-clockwise
    tri = np.array([np.roll(r, -int(np.argmin(r))) for r in tri])
    perm = np.lexsort(tri.T[::-1])
    out = Triangulation(points, tri[perm])
    return (out, perm) if order else out


def glue(x: np.ndarray, tol: float = 1e-12) -> tuple[np.ndarray, np.ndarray]:
    """Unique points of ``x`` (n, 2) up to ``tol`` (rounded to a grid of spacing ``tol``, exact
    for the vertices of one mesh) and the index of each point among them."""
    key = np.rint(np.asarray(x, float) / max(tol, 1e-15)).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return np.asarray(x, float)[first], inverse.ravel()


def barycentric(corners: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Barycentric coordinates (n, T, 3) of points x (n, 2) in triangles ``corners`` (T, 3, 2)."""
    a, e1, e2 = corners[:, 0], corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    d = x[:, None, :] - a[None]
    l1 = (d[..., 0] * e2[None, :, 1] - d[..., 1] * e2[None, :, 0]) / det[None]
    l2 = (e1[None, :, 0] * d[..., 1] - e1[None, :, 1] * d[..., 0]) / det[None]
    return np.stack([1.0 - l1 - l2, l1, l2], axis=-1)


def locate(tri: Triangulation, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(triangle index (n,), barycentric coordinates (n, 3)) of points x (n, 2): the triangle
    whose smallest barycentric coordinate is largest (inside, or nearest for round-off);
    :class:`InputError` for a point farther than 1e-9 outside every triangle."""
    x = np.asarray(x, float).reshape(-1, 2)
    idx = np.zeros(len(x), dtype=int)
    lam = np.zeros((len(x), 3))
    corners = tri.corners
    lo, hi = corners.min(axis=1), corners.max(axis=1)
    for start in range(0, len(x), _LOCATE_CHUNK):
        xc = x[start:start + _LOCATE_CHUNK]
        box = np.all((xc[:, None, :] >= lo[None] - 1e-9) & (xc[:, None, :] <= hi[None] + 1e-9), axis=2)
        cand = np.flatnonzero(box.any(axis=0))
        if not box.any(axis=1).all():
            raise InputError("points", "points of Γ inside the triangulation", got=xc[~box.any(axis=1)][:3])
        lc = barycentric(corners[cand], xc)
        score = np.where(box[:, cand], lc.min(axis=2), -np.inf)
        best = np.argmax(score, axis=1)
        if np.any(score[np.arange(len(xc)), best] < -1e-9):
            raise InputError("points", "points of Γ inside the triangulation", got=xc[score.max(axis=1) < -1e-9][:3])
        idx[start:start + len(xc)] = cand[best]
        lam[start:start + len(xc)] = lc[np.arange(len(xc)), best]
    return idx, lam


def lattice(tri: Triangulation, s: int, tol: float = 1e-10) -> tuple[np.ndarray, np.ndarray]:
    """The continuous P_s Lagrange lattice: node coordinates (nn, 2) and the global node of every
    local node (nt, nloc) in :func:`~.face.spaces.triangles.local_lattice` order (s ≥ 1)."""
    alpha = local_lattice(s).astype(float) / s  # (nloc, 3) barycentric
    pts = np.einsum("la,tac->tlc", alpha, tri.corners)
    nodes, inverse = glue(pts.reshape(-1, 2), tol)
    return nodes, inverse.reshape(tri.cells, -1)


def on_boundary(x: np.ndarray, tol: float = 1e-10) -> np.ndarray:
    """Whether points (n, 2) lie on ∂Γ, the boundary of the unit square."""
    x = np.asarray(x, float).reshape(-1, 2)
    return np.any((np.abs(x) < tol) | (np.abs(x - 1.0) < tol), axis=1)


def interior_nodes(tri: Triangulation, s: int, clamped: bool = True) -> int:
    """dim of continuous P_s on ``tri`` vanishing on ∂Γ: the lattice nodes off ∂Γ (all of them
    when not ``clamped``)."""
    nodes, _ = lattice(tri, s)
    return int(np.sum(~on_boundary(nodes))) if clamped else len(nodes)


def _polygons(tri: Triangulation):
    import shapely

    return shapely.polygons(tri.corners)


def overlay(a: Triangulation, b: Triangulation, tol: float = 1e-12) -> Triangulation:
    """The common refinement of two triangulations: every intersection T_a ∩ T_b of positive
    area (candidates from a shapely ``STRtree``, polygons from ``shapely.intersection``),
    fanned from its first vertex; ``parents`` = (triangle of a, triangle of b) per triangle
    (the parents of a refinement input are carried along)."""
    import shapely

    pa, pb = _polygons(a), _polygons(b)
    tree = shapely.STRtree(pb)
    ia, ib = tree.query(pa, predicate="intersects")
    inter = shapely.intersection(pa[ia], pb[ib])
    area = shapely.area(inter)
    keep = area > AREA_TOL * np.minimum(a.areas[ia], b.areas[ib])
    corners, parents = [], []
    for poly, i, j in zip(inter[keep], ia[keep], ib[keep]):
        geoms = getattr(poly, "geoms", [poly])  # a GeometryCollection may carry touching lines
        for g in geoms:
            if g.geom_type != "Polygon" or g.area <= AREA_TOL * min(a.areas[i], b.areas[j]):
                continue
            ring = np.asarray(g.exterior.coords)[:-1]
            for m in range(1, len(ring) - 1):
                t = np.array([ring[0], ring[m], ring[m + 1]])
                e1, e2 = t[1] - t[0], t[2] - t[0]
                if abs(e1[0] * e2[1] - e1[1] * e2[0]) > 2 * AREA_TOL * g.area:
                    corners.append(t)
                    parents.append((i, j))
    corners = np.array(corners)
    points, index = glue(corners.reshape(-1, 2), tol)
    par = np.array(parents, dtype=int)
    pa_old = a.parents if a.parents is not None else np.arange(a.cells)[:, None]
    pb_old = b.parents if b.parents is not None else np.arange(b.cells)[:, None]
    return Triangulation(points, index.reshape(-1, 3), np.hstack([pa_old[par[:, 0]], pb_old[par[:, 1]]]))


def matched_interior_nodes(a: Triangulation, b: Triangulation, k: int, tol: float = 1e-10,
                           clamped: bool = True) -> int:
    """Nodes of the P_k lattice of ``a`` (off ∂Γ if ``clamped``) whose every triangle of ``a`` is
    also a triangle of ``b`` (same vertex set): the nodal functions there lie in both continuous
    P_k spaces, so this is a lower bound of dim(W_a ∩ W_b), exact when a = b."""
    def keys(t):
        c = np.rint(t.corners / tol).astype(np.int64)
        c = np.sort(c.view([("x", np.int64), ("y", np.int64)]).reshape(t.cells, 3), axis=1)
        return {row.tobytes() for row in c}

    kb = keys(b)
    ca = np.rint(a.corners / tol).astype(np.int64)
    ca = np.sort(ca.view([("x", np.int64), ("y", np.int64)]).reshape(a.cells, 3), axis=1)
    matched = np.array([row.tobytes() in kb for row in ca])
    nodes, glob = lattice(a, k)
    bad = np.zeros(len(nodes), dtype=bool)
    np.logical_or.at(bad, glob[~matched].ravel(), True)
    return int(np.sum(~bad & (~on_boundary(nodes) if clamped else True)))


CORNERS = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
"""The corners of Γ = (0, 1)²."""


def corner_triangles(tri: Triangulation, tol: float = 1e-12) -> dict:
    """{corner index: triangle} for the corners of Γ with exactly one triangle of ``tri``, whose
    other two vertices lie on the two sides of ∂Γ through that corner (a corner triangle: a
    continuous function vanishing on ∂Γ is (x − c_x)(y − c_y) times a polynomial of degree k − 2
    there)."""
    out = {}
    for i, c in enumerate(CORNERS):
        at = np.flatnonzero(np.any(np.all(np.abs(tri.corners - c) < tol, axis=2), axis=1))
        if len(at) != 1:
            continue
        others = [v for v in tri.corners[at[0]] if np.abs(v - c).max() >= tol]
        on_x = [abs(v[0] - c[0]) < tol for v in others]
        on_y = [abs(v[1] - c[1]) < tol for v in others]
        if sorted(on_x) == [False, True] and sorted(on_y) == [False, True]:
            out[i] = int(at[0])
    return out


def contains(tri: Triangulation, t: int, points: np.ndarray, tol: float = 1e-12) -> bool:
    """Whether the triangle ``t`` of ``tri`` contains every point (n, 2)."""
    return bool(barycentric(tri.corners[t:t + 1], np.asarray(points, float)).min() >= -tol)
