"""The elastic scenes' data: two blocks pressed together by a prescribed far-face displacement,
with an optional initial gap on Γ — the scene shared by the patch test (:mod:`.patch`) and
the Hertz scene (:mod:`.hertz`).

Ω1 = (0,1)² and Ω2 = (0,1)×(1,2) on structured meshes; u = 0 on Ω1's bottom, u_y = −d on Ω2's
top (``dir``); the lateral sides ``side`` (x = 0, 1) are either on rollers (u_x = 0: the patch
test) or traction free (Hertz). The model (:mod:`infsup_contact.models.contract`) turns the
data into Dirichlet lifts u_{D,i} and loads F_i = −A_i u_{D,i}; the shared Γ solve
(:func:`~infsup_contact.contact.contact.solve_on_gamma`) adds the weighted initial gap
G_j = ∫_Γ μ_j g0 and solves g = G + g_F + K λ, λ ≥ 0, g ≥ 0, λ∘g = 0.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import ngsolve

from ...discretization.segment import meshes

SIDE = "side"
"""Boundary name of the lateral sides x = 0, 1."""


def block_mesh(n: int, side: int) -> ngsolve.Mesh:
    """The structured N×N mesh of Ω_side with boundaries ``gamma``, ``side`` (x = 0, 1) and
    ``dir`` (the bottom of Ω1, the top of Ω2)."""
    points, triangles = meshes.structured_arrays(n, side)
    segs = []
    for a, b, label in meshes.boundary_segments(points, side):
        x = points[[a, b], 0]
        if label == meshes.DIRICHLET and x[0] == x[1] and x[0] in (0.0, 1.0):
            label = SIDE
        segs.append((a, b, label))
    mesh = meshes.mesh_from_arrays(points, triangles, segs)
    meshes.check_mesh(mesh, 1.0, f"family structured (patch test), N = {n}, side {side}")
    return mesh


@dataclass(frozen=True)
class PressedBlocks:
    """Two elastic blocks, Ω2's top moved down by ``d`` (a contact scene).

    Attributes
    ----------
    name : str
        The scene's registry id.
    c1, c2 : float
        Young's moduli E1, E2 (the material scales of the model contract).
    d : float
        Downward displacement of Ω2's top.
    supports : tuple of str
        NGSolve boundary regexps where u_x and u_y vanish (or are prescribed).
    initial_gap : callable or None
        Initial gap g0(x) on Γ (numpy), a polynomial of degree ``initial_gap_degree`` (not
        ``gap``: a manufactured scene's ``gap`` is its exact solution's).
    initial_gap_degree : int
    """

    name: str
    c1: float
    c2: float
    d: float
    supports: tuple
    initial_gap: Callable | None = None
    initial_gap_degree: int = 0

    @property
    def far_displacement_y(self) -> tuple:
        """u_y on the far face ``dir`` of Ω1, Ω2."""
        return (0.0, -self.d)

    def mesh_pair(self, family: str, n1: int, n2: int, **_) -> tuple:
        """The structured blocks with N1, N2 segments on Γ (``family`` is structured: the
        CLI and the registry refuse any other)."""
        return block_mesh(n1, 1), block_mesh(n2, 2)
