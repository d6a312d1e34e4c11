"""Γ a circular arc of radius R and length 1: the paper's segment, curved.

The bodies are Ω1 = {R − 1 < r < R} and Ω2 = {R < r < R + 1}, 0 < θ < 1/R, each of unit
thickness, so that R = ∞ is the paper's two squares. Each body is the image of the paper's mesh
of its square (every family: structured, perturbed, unstructured) under the polar map

    Φ(x, y) = ((R − 1 + y) sin(x/R), (R − 1 + y) cos(x/R) − R + 1),

which takes Γ = (0, 1) × {1} to the arc r = R (centre (0, 1 − R)) and the square's x to the arc
length s = x. The curved mesh is isoparametric: NGSolve's ``SetDeformation`` by the interpolant
of Φ − id in continuous P_k, the body's own degree (:meth:`Arc.curve`), so the vertices lie on the
arc and the discrete Γ of each side is a degree-k curve through them.

Everything on Γ is parametrized by the arc length s ∈ (0, 1) (the reference x): partitions,
multiplier spaces, the L² norm and the H^{-1/2}_00 norm, which is the segment's in s — an
equivalent norm of the arc's, exact for R → ∞. How the sides are coupled is the ``coupling``:

``exact``
    Both traces mapped to the exact arc by arc length (vertex to vertex, the reference
    parametrization): b(v, μ) = ∫_0^1 (v_2 − v_1) μ ds, the segment's coupling, exact.
``projection``
    As mortar codes do it: the integral over the discretized side that carries G_h (the
    slave: Ω2 for ``omega2`` and ``union``, Ω1 for ``omega1``), its trace and μ at the slave's
    point, the other side's trace at the point hit along the slave's averaged nodal normal
    (:mod:`.projection`).

R = ∞ builds the paper's meshes unchanged; ``exact`` then is the paper's β_h, bit for bit.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ...errors import InputError
from .interface import Segment

GAMMAS = ("segment", "arc")
"""The Γ of the 2D membranes: the paper's segment, or the arc of radius R."""
COUPLINGS = ("exact", "projection")
"""How the sides are coupled on the arc (module docstring)."""
RADIUS_ALLOWED = "a number R > 1, or inf (the flat segment)"
"""R = 1 would make Ω1 a sector whose square map collapses its far side into the centre."""
MOMENT_BONUS_INTORDER = 8
"""Orders beyond NGSolve's default with which the dual interpolation integrates the moments of Φ − id
(not a polynomial): at the default the curved bodies' S_i sit ~6e-11 (relative; k = 2) from the
documented interpolant's, two more orders reach round-off (docs/models.md, the arc)."""


def check_curved_options(gamma, radius, coupling, gammas=GAMMAS, radius_allowed: str = RADIUS_ALLOWED) -> None:
    """:class:`InputError` naming the key: ``gamma`` in ``gammas`` (flat, curved); with the curved one a
    radius R > 1 (inf allowed) and a coupling in :data:`COUPLINGS` (None: ``exact``); without it neither
    (the arc's options; the cylinder's, :mod:`..face.shapes.cylinder`, with its own names)."""
    curved = gammas[-1]
    if gamma not in (None,) + tuple(gammas):
        raise InputError("gamma", ", ".join(gammas), got=gamma)
    if gamma != curved:
        for key, value in (("radius", radius), ("coupling", coupling)):
            if value is not None:
                raise InputError(key, f"only with gamma {curved} (--gamma {curved})", got=value)
        return
    if radius is None or isinstance(radius, bool) or not isinstance(radius, (int, float, np.number)) \
            or not radius > 1:
        raise InputError("radius", f"{radius_allowed} (required with gamma {curved})", got=radius)
    if coupling not in (None,) + COUPLINGS:
        raise InputError("coupling", ", ".join(COUPLINGS), got=coupling)


def check_arc_options(gamma, radius, coupling) -> None:
    """:func:`check_curved_options` of the 2D membranes' Γ (:data:`GAMMAS`)."""
    check_curved_options(gamma, radius, coupling)


@dataclass(frozen=True)
class Arc(Segment):
    """Γ the arc of radius ``radius`` and length 1, parametrized by arc length (module docstring).

    Attributes
    ----------
    radius : float
        R > 1, or inf (the paper's segment).
    coupling : str
        One of :data:`COUPLINGS`.
    pairing : callable or None
        ``pairing(arc, sides) -> sides`` ties the two sides' traces for ``projection``
        (:func:`.projection.project_pair`): given by the Γ table
        (:mod:`infsup_contact.discretization.spaces.gammas`), which pairs the shape with its
        projection, so that this module does not import the projection's.
    """

    radius: float = math.inf
    coupling: str = "exact"
    pairing: Callable | None = field(default=None, compare=False, repr=False)

    @property
    def curved(self) -> bool:
        return math.isfinite(self.radius)

    def polar_map(self):
        """Φ − id as an NGSolve coefficient function of the square's (x, y) (module docstring)."""
        import ngsolve

        R = float(self.radius)
        r, half = R - 1.0 + ngsolve.y, ngsolve.sin(ngsolve.x / (2.0 * R))
        # r cos θ − R + 1 − y = −2 r sin²(θ/2): no cancellation of R against R at a large radius
        return ngsolve.CF((r * ngsolve.sin(ngsolve.x / R) - ngsolve.x, -2.0 * r * half * half))

    def curve(self, mesh, k: int) -> None:
        """Make ``mesh`` (a square of the paper's) the isoparametric image of its body under Φ:
        its deformation is the P_k interpolant of Φ − id, by NGSolve's dual (moment) interpolation, so
        that an edge's curve depends on the edge alone: the two sides of matching meshes share their
        discrete Γ exactly (the default ``Set`` projects element by element, and the sides' curves
        then differ by ~1e-6); the moments of the non-polynomial Φ integrated to round-off
        (:data:`MOMENT_BONUS_INTORDER`). Nothing on a flat Γ."""
        import ngsolve

        if not self.curved:
            return
        mesh.UnsetDeformation()  # Φ is a map of the square: never of an already curved mesh
        deformation = ngsolve.GridFunction(ngsolve.VectorH1(mesh, order=int(k)))
        deformation.Set(self.polar_map(), dual=True, bonus_intorder=MOMENT_BONUS_INTORDER)
        mesh.SetDeformation(deformation)

    def embed(self, x):
        """Points of the exact arc at arc lengths ``x`` (the body's coordinates)."""
        x = np.asarray(x, dtype=float)
        if not self.curved:
            return super().embed(x)
        R = float(self.radius)
        return R * np.sin(x / R), 1.0 - 2.0 * R * np.sin(x / (2.0 * R)) ** 2

    def paired(self, sides: list) -> list:
        """With ``projection`` on a curved arc, the sides' traces tied to each other
        (:attr:`pairing`, :func:`.projection.project_pair`); else as built."""
        if self.coupling != "projection":
            return sides
        if self.pairing is None:  # a caller's slip: the Γ table builds a projected arc with its pairing
            raise TypeError("an Arc coupled by projection is built by the Γ table (spaces.gammas.gamma_of), "
                            "which gives it its pairing")
        return self.pairing(self, sides)

