"""Meshes of the two membranes Ω1 = (0,1)×(0,1) and Ω2 = (0,1)×(1,2) (paper, Fig. 4).

One NGSolve mesh per subdomain, with boundary names ``gamma`` (Γ = (0,1)×{1}) and
``dir`` (the rest of ∂Ω_i, where u_i = 0, eq. (3.1)). A family and (N1, N2), the numbers
of segments on Γ of the Ω1 and Ω2 meshes, address a mesh pair; N1 ≠ N2 is non-matching.

Families
--------
structured
    N × N equal squares, each split by its lower-left → upper-right diagonal.
perturbed
    structured, interior nodes moved by a seeded uniform shift of amplitude α·h;
    Γ nodes move only along x, identically on both sides when N1 = N2. α <= 1/5
    (:data:`ALPHA_MAX`): every triangle keeps at least 1 − 4α of its area and an angle of
    at least 3.9° (:func:`perturbation_bounds`), for every seed.
unstructured
    netgen's advancing-front mesher with maxh = 1/N, reproducible (netgen is
    deterministic for a given geometry and maxh); N is then the segment count on Γ.
"""
from __future__ import annotations

import numpy as np
import ngsolve
from netgen import meshing
from netgen.geom2d import SplineGeometry

from ...errors import InputError
from ..gamma.interface import MULTIPLIER_MESHES  # noqa: F401  (the choices of G_h)
from .interface import SEGMENT

FAMILIES = ("structured", "perturbed", "unstructured")
GAMMA, DIRICHLET = SEGMENT.boundary, "dir"
SYMMETRY_X, SYMMETRY_Y = "side_x0", "side_y0"
"""Boundary names of the lateral faces x = 0 and y = 0 of the 3D elastic bodies' meshes
(:mod:`infsup_contact.models.elastic3d`): the symmetry planes of the elastic face patch test
(:mod:`infsup_contact.study.patch.elastic3d`), named here so that the scene need not import
the model."""


def check_mesh_args(family: str, n: int, key: str = "N") -> None:
    """Raise :class:`InputError` for an unknown family or a segment count below 1."""
    if family not in FAMILIES:
        raise InputError("family", ", ".join(FAMILIES), got=family)
    if not isinstance(n, (int, np.integer)) or n < 1:
        raise InputError(key, "an integer >= 1", got=n)


ALPHA_MAX = 0.2
"""Largest perturbation amplitude α (× h) of the perturbed family.

Bound, for every seed (:func:`perturbation_bounds`): a triangle of the structured mesh is a
right isosceles triangle with legs h, and each of its vertices moves by at most αh in each
coordinate. Twice its signed area, (x1 − x0)(y2 − y0) − (x2 − x0)(y1 − y0), is affine in each
coordinate separately, so its minimum over the box of displacements is at a corner: it is
(1 − 4α)·h², i.e. the signed area ratio is >= 1 − 4α, which reaches 0 (a degenerate
triangle) at α = 1/4. At α = 1/5 the ratio is >= 0.2 and every angle is >= 3.9° (the angle
at a vertex is arcsin(2A / (|a| |b|)) with A at least its minimum and the edges at most
their maxima; the smallest angle of a triangle is acute). Measured over seeds 0..199,
N = 4..32 and both sides (``workflow/scripts/alpha_bound.py``), the smallest ratio is 0.24 at α = 0.2
(smallest angle 13.6°), 0.05 at α = 0.25 and −0.13 at α = 0.3: random draws stay inside the
bound, and larger α does invert triangles."""
ALPHA_RANGE = (0.0, ALPHA_MAX)
"""Allowed α, both ends included (the config schema states the same)."""
ALPHA_ALLOWED = (f"a finite number in [0, {ALPHA_MAX:g}] (larger amplitudes can invert triangles: "
                 "the worst signed area is 1 - 4*alpha of the unperturbed one)")


def perturbation_bounds(alpha: float) -> tuple[float, float]:
    """Worst case, over every displacement the perturbed family can draw at amplitude α, of a
    triangle's signed area ratio (perturbed / unperturbed) and a lower bound of its smallest
    angle in degrees (nan where the area can vanish). See :data:`ALPHA_MAX`."""
    import itertools

    tri = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])  # (ll, lr, ur); (ll, ur, ul) is its mirror
    corners = [tri + alpha * np.reshape(c, (3, 2)) for c in itertools.product((-1.0, 1.0), repeat=6)]
    area2 = min(float(signed_areas(p, np.array([[0, 1, 2]]))[0]) * 2 for p in corners)
    edge_max = np.max([np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1) for p in corners], axis=0)
    if area2 <= 0:
        return area2, float("nan")
    # angle at vertex v between its two edges (edges i = v_i -> v_{i+1})
    sines = [area2 / (edge_max[a] * edge_max[b]) for a, b in ((2, 0), (0, 1), (1, 2))]
    return area2, float(np.degrees(np.arcsin(min(1.0, min(sines)))))


def check_perturbation(alpha, seed) -> None:
    """:class:`InputError` unless 0 <= α <= :data:`ALPHA_MAX` (finite) and the seed is an
    integer >= 0 (numpy); None stands for the mesh builder's default (valid by construction)."""
    if alpha is not None and (isinstance(alpha, bool) or not isinstance(alpha, (int, float, np.integer, np.floating))
                              or not ALPHA_RANGE[0] <= alpha <= ALPHA_RANGE[1]):
        raise InputError("alpha", ALPHA_ALLOWED, got=alpha)
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0):
        raise InputError("seed", "an integer >= 0 (a numpy seed)", got=seed)


def signed_areas(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Signed areas of triangles (counter-clockwise positive) from vertex coordinates."""
    p = np.asarray(points, dtype=float)[np.asarray(triangles)]  # (n, 3, 2)
    a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])


def check_mesh(mesh: ngsolve.Mesh, area: float, about: str) -> None:
    """Every element positively oriented and the element areas summing to ``area``.

    The signed areas come from the vertex coordinates (numpy); the total area is NGSolve's
    ``Integrate(1, mesh)``, which sums |det J|: an inverted element makes it exceed the body's
    area, and a missing one makes it fall short.

    Raises
    ------
    InputError
        key ``mesh``, ``about`` naming the family, N, side, seed and α.
    """
    points = np.asarray(mesh.ngmesh.Coordinates())[:, :2]
    triangles = np.asarray(mesh.ngmesh.Elements2D().NumPy()["nodes"])[:, :3] - 1  # netgen: 1-based
    areas = signed_areas(points, triangles)
    ref = area / max(len(areas), 1)
    if not len(areas) or areas.min() <= 1e-12 * ref:
        worst = float(areas.min()) / ref if len(areas) else float("nan")
        raise InputError("mesh", f"positively oriented triangles ({about}: {int(np.sum(areas <= 1e-12 * ref))} "
                         f"inverted or degenerate, smallest signed area {worst:.3g} x the mean)")
    total = float(ngsolve.Integrate(1, mesh))
    if not abs(total - area) <= 1e-10 * area:
        raise InputError("mesh", f"elements covering the body ({about}: their areas sum to {total!r}, "
                         f"the body's area is {area!r})")


def structured_arrays(n: int, side: int):
    """Vertices and triangles of the structured N×N mesh of Ω_side.

    Returns
    -------
    points : ndarray (n_v, 2)
    triangles : ndarray (n_t, 3) of vertex indices, counter-clockwise
    """
    y0 = 0.0 if side == 1 else 1.0
    s = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(s, y0 + s, indexing="xy")
    points = np.column_stack([X.ravel(), Y.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="xy")
    ll = (j * (n + 1) + i).ravel()
    lr, ul, ur = ll + 1, ll + n + 1, ll + n + 2
    # diagonal from lower-left to upper-right: (ll, lr, ur) and (ll, ur, ul)
    triangles = np.vstack([np.column_stack([ll, lr, ur]), np.column_stack([ll, ur, ul])])
    return points, triangles


def boundary_segments(points: np.ndarray, side: int, tol: float = 1e-12):
    """Boundary edges of the structured/perturbed square, split into Γ and the rest.

    Returns a list of (v_a, v_b, name) with the domain on the left of a → b.
    """
    y0 = 0.0 if side == 1 else 1.0
    n = int(round(np.sqrt(len(points)))) - 1
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)  # idx[row j, col i]
    bottom, top = idx[0, :], idx[-1, ::-1]
    right, left = idx[:, -1], idx[::-1, 0]
    gamma_row = "top" if side == 1 else "bottom"
    segs = []
    for name, chain in (("bottom", bottom), ("right", right), ("top", top), ("left", left)):
        label = GAMMA if name == gamma_row else DIRICHLET
        segs += [(int(a), int(b), label) for a, b in zip(chain[:-1], chain[1:])]
    del y0, tol
    return segs


def mesh_from_arrays(points, triangles, segments) -> ngsolve.Mesh:
    """An NGSolve mesh from vertex/triangle arrays and named boundary segments.

    Uses netgen's vectorized AddPoints / AddRegion / AddElements (no per-element loop).
    """
    ngmesh = meshing.Mesh(dim=2)
    ngmesh.AddPoints(np.column_stack([points, np.zeros(len(points))]).astype(float))
    omega = ngmesh.AddRegion("omega", dim=2)
    ngmesh.AddElements(dim=2, index=omega, data=np.asarray(triangles, dtype=np.int32), base=0)
    extra = sorted({label for _, _, label in segments} - {GAMMA, DIRICHLET})  # e.g. the patch test's sides
    for name in (GAMMA, DIRICHLET, *extra):
        edges = np.array([(a, b) for a, b, label in segments if label == name], dtype=np.int32)
        ngmesh.AddElements(dim=1, index=ngmesh.AddRegion(name, dim=1), data=edges, base=0)
    return ngsolve.Mesh(ngmesh)


def perturb(points: np.ndarray, n: int, side: int, alpha: float, seed: int) -> np.ndarray:
    """Move interior nodes by U(−αh, αh)², Γ nodes only along x (shared seed per N)."""
    h = 1.0 / n
    out = points.copy()
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    interior = idx[1:-1, 1:-1].ravel()
    rng = np.random.default_rng([seed, n, side])
    out[interior] += rng.uniform(-alpha * h, alpha * h, size=(len(interior), 2))
    # Γ shift drawn from a stream that depends on N only, so matching meshes stay matching
    gamma_row = idx[-1, 1:-1] if side == 1 else idx[0, 1:-1]
    shift = np.random.default_rng([seed, n, 0]).uniform(-alpha * h, alpha * h, size=n - 1)
    out[gamma_row, 0] += shift
    return out


def unstructured_mesh(n: int, side: int) -> ngsolve.Mesh:
    """netgen mesh of Ω_side with maxh = 1/N and exactly N equal segments on Γ."""
    y0 = 0.0 if side == 1 else 1.0
    geo = SplineGeometry()
    corners = [(0, y0), (1, y0), (1, y0 + 1), (0, y0 + 1)]
    pts = [geo.AppendPoint(*c) for c in corners]
    gamma_edge = 2 if side == 1 else 0  # top edge of Ω1, bottom edge of Ω2
    for e in range(4):
        name = GAMMA if e == gamma_edge else DIRICHLET
        geo.Append(["line", pts[e], pts[(e + 1) % 4]], bc=name, leftdomain=1, rightdomain=0,
                   maxh=(1.0 / n if e == gamma_edge else 1e99))
    ngmesh = geo.GenerateMesh(maxh=1.0 / n)
    return ngsolve.Mesh(ngmesh)


def subdomain_mesh(family: str, n: int, side: int, *, alpha: float = 0.2, seed: int = 0,
                   checked: bool = False) -> ngsolve.Mesh:
    """The mesh of Ω_side (side = 1 or 2) of a family with N segments on Γ, checked
    (:func:`check_mesh`: positive orientation, element areas summing to |Ω_side| = 1).
    ``checked``: the family, N, seed and α were checked by a request (a validated
    :class:`~infsup_contact.solvers.request.BetaRequest`) and are not checked again."""
    if not checked:
        check_mesh_args(family, n)
    about = f"family {family}, N = {n}, side {side}"
    if family == "unstructured":
        mesh = unstructured_mesh(n, side)
    else:
        points, triangles = structured_arrays(n, side)
        if family == "perturbed":
            if not checked:
                check_perturbation(alpha, seed)
            points = perturb(points, n, side, alpha, seed)
            about += f", seed {seed}, alpha {alpha:g}"
        mesh = mesh_from_arrays(points, triangles, boundary_segments(points, side))
    check_mesh(mesh, 1.0, about)
    return mesh


def mesh_pair(family: str, n1: int, n2: int, **kwargs):
    """(mesh of Ω1 with N1 segments on Γ, mesh of Ω2 with N2 segments on Γ)."""
    check_mesh_args(family, n1, "N1")
    check_mesh_args(family, n2, "N2")
    return subdomain_mesh(family, n1, 1, **kwargs), subdomain_mesh(family, n2, 2, **kwargs)


def multiplier_breakpoints(mesh1, mesh2, choice: str = "omega2", tol: float = 1e-12) -> np.ndarray:
    """Partition G_h of Γ of a mesh pair (:meth:`~.gamma.interface.Interface.multiplier_partition_of`
    of the paper's segment)."""
    return SEGMENT.multiplier_partition_of(mesh1, mesh2, choice, tol)


def mesh_quality(mesh: ngsolve.Mesh) -> dict:
    """Element diameters, angles (degrees) and element count of a triangle mesh."""
    pts = np.array([v.point for v in mesh.vertices])
    tris = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ngsolve.VOL)])
    p = pts[tris]  # (n, 3, 2)
    edges = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 1], p[:, 0] - p[:, 2]], axis=1)
    lengths = np.linalg.norm(edges, axis=2)
    angles = []
    for a, b in ((0, 2), (1, 0), (2, 1)):  # angle at vertex between the two incident edges
        cos = -np.einsum("nd,nd->n", edges[:, a], edges[:, b]) / (lengths[:, a] * lengths[:, b])
        angles.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
    angles = np.stack(angles, axis=1)
    return dict(h_max=float(lengths.max()), h_min=float(lengths.min()), min_angle=float(angles.min()),
                max_angle=float(angles.max()), n_elements=int(len(tris)), n_vertices=int(len(pts)))
