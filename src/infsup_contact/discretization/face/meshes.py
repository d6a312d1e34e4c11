"""Unstructured and perturbed meshes of the 3D bodies Ω1 = (0,1)³, Ω2 = (0,1)²×(1,2).

Families beside ``structured`` (``ngsolve.meshes.MakeStructured3DMesh``, built in
:func:`infsup_contact.models.membranes3d.subdomain_mesh`):

unstructured
    Netgen's tetrahedral mesh of the OCC box with maxh = 1/N (``netgen.occ.Box``,
    ``OCCGeometry.GenerateMesh``), each body meshed on its own: the two Γ faces are different
    triangulations (non-matching even for N1 = N2; Netgen is deterministic for a given geometry
    and maxh, so the meshes are reproducible). Tetrahedra only.
perturbed
    The structured mesh with every vertex moved by a seeded uniform shift U(−αh, αh) in each
    coordinate direction in which it is not on a boundary plane of the box (h = 1/N, α ≤ 1/5;
    ``|shift|_∞ ≤ αh``): the box's planes, Γ's among them, are kept. Tetrahedra: the Γ vertices
    move in the plane too (their shifts drawn from a stream of (seed, N) only, so N1 = N2 gives
    matching perturbed faces; the other vertices' from (seed, N, side)); the trace is then a
    general triangulation (:class:`~.face.shapes.triangulated_square.TriangulatedSquare`). Hexahedra: the Γ
    vertices do not move (only off-Γ vertices do), so the face stays a tensor grid and its
    interface :class:`~.face.shapes.square.Square`; only the bodies' interiors are perturbed, and only in z
    (the direction normal to Γ): NGSolve's hexahedra with vertices moved in two directions at
    once do not keep the box's volume (measured: 1.0022 for N = 3), those moved in one do.

Boundary names as the structured builder's: ``gamma`` (Γ), ``dir`` (the far face), ``side``.
Both builders check the mesh: every tetrahedron positively oriented, volume 1.
"""
from __future__ import annotations

import numpy as np
import ngsolve

from ...errors import InputError
from ..segment.meshes import DIRICHLET, check_perturbation

GAMMA, FAR, LATERAL = "gamma", DIRICHLET, "side"


def unstructured_box(n: int, side: int) -> ngsolve.Mesh:
    """Netgen tetrahedral mesh of Ω_side with maxh = 1/N, faces named gamma / dir / side."""
    from netgen.occ import Box, OCCGeometry, Pnt, Z

    z0 = 0.0 if side == 1 else 1.0
    box = Box(Pnt(0.0, 0.0, z0), Pnt(1.0, 1.0, z0 + 1.0))
    box.faces.name = LATERAL
    top, bottom = box.faces.Max(Z), box.faces.Min(Z)
    (top if side == 1 else bottom).name = GAMMA
    (bottom if side == 1 else top).name = FAR
    mesh = ngsolve.Mesh(OCCGeometry(box).GenerateMesh(maxh=1.0 / n))
    check_volume(mesh, f"family unstructured, N = {n}, side {side}")
    return mesh


def perturb_points(ngmesh, n: int, side: int, alpha: float, seed: int, hexes: bool) -> None:
    """Move the vertices of a structured mesh of Ω_side in place (module docstring): tetrahedra
    in every free direction, Γ's vertices in its plane; hexahedra off Γ and in z only."""
    move_gamma = not hexes
    check_perturbation(alpha, seed)
    h, z0 = 1.0 / n, (0.0 if side == 1 else 1.0)
    z_gamma = 1.0
    inner = np.random.default_rng([seed, n, side]).uniform(-alpha * h, alpha * h, size=(n + 1, n + 1, n + 1, 3))
    face = np.random.default_rng([seed, n, 0]).uniform(-alpha * h, alpha * h, size=(n + 1, n + 1, 2))
    for p in ngmesh.Points():
        x = np.array([p[0], p[1], p[2]])
        i, j, l = (int(v) for v in np.rint(np.array([x[0], x[1], x[2] - z0]) * n))
        free = (np.abs(x - np.rint(x)) > 1e-12)  # off the planes x, y, z ∈ {0, 1, 2}
        on_gamma = abs(x[2] - z_gamma) < 1e-12
        if on_gamma and not move_gamma:
            continue
        d = np.zeros(3)
        d[:2] = face[i, j] if on_gamma else inner[i, j, l, :2]
        d[2] = 0.0 if on_gamma else inner[i, j, l, 2]
        for c in range(3):
            if free[c] and (c == 2 or not hexes):
                p[c] += float(d[c])


def check_volume(mesh: ngsolve.Mesh, about: str) -> None:
    """:class:`InputError` unless every tetrahedron is positively oriented with the same sign
    and the volumes sum to 1 (hexahedra: the volume only)."""
    vol = ngsolve.Integrate(ngsolve.CoefficientFunction(1.0), mesh)
    signs = []
    for el in mesh.Elements(ngsolve.VOL):
        if len(el.vertices) == 4:
            p = np.array([mesh[v].point for v in el.vertices])
            signs.append(np.linalg.det(p[1:] - p[0]))
    signs = np.array(signs)
    if abs(vol - 1.0) > 1e-10 or (len(signs) and not (np.all(signs > 0) or np.all(signs < 0))):
        raise InputError("mesh", f"a valid mesh of volume 1 ({about}: volume {vol:.12g}, "
                         f"{int(np.sum(signs * np.sign(signs.sum()) <= 0)) if len(signs) else 0} inverted tetrahedra)")
