"""Γ a part of a cylinder of radius R and area 1: the face (0, 1)² × {1}, curved in x.

The bodies are the images of the 3D membranes' boxes Ω1 = (0,1)³ and Ω2 = (0,1)²×(1,2) under

    Φ(x, y, z) = ((R − 1 + z) sin(x/R), y, (R − 1 + z) cos(x/R) − R + 1),

the arc's polar map (:mod:`..segment.arc`) in (x, z) times the identity in y: Γ (z = 1) goes to
the cylinder r = R about the axis {X = 0, Z = 1 − R} along y, x to the arc length, and R = ∞ is
the flat face. Ω1 = {R − 1 < r < R}, Ω2 = {R < r < R + 1}, 0 < θ < 1/R, 0 < y < 1. The curved
mesh is isoparametric: NGSolve's ``SetDeformation`` by the interpolant of Φ − id in the body's
own Q_k / P_k (:meth:`Cylinder.curve`), with dual (interpolating) degrees of freedom, so the
vertices lie on Φ's image and the volume and area errors fall as h^{2k} (tested).

Everything on Γ is parametrized by (arc length, y) ∈ (0, 1)², the reference face: partitions,
multiplier spaces, the L² norm (the cylinder's area element is ds dy, so this L² is the
cylinder's) and the H^{-1/2}_00 norm of the parameter square, an equivalent norm of the
cylinder's, exact for R → ∞. How the sides are coupled is the ``coupling``:

``exact``
    Both traces mapped to the exact cylinder by (arc length, y): the flat face's coupling, exact
    (tetrahedra too).
``projection``
    As mortar codes do it: the integral over the slave's discrete surface, the master evaluated
    where the slave's averaged nodal normal meets it (:mod:`.cylinder_projection`; hexahedra).

R = ∞ builds the flat meshes unchanged; ``exact`` then gives the flat face's β_h bit for bit.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ....errors import InputError
from ...segment.arc import MOMENT_BONUS_INTORDER, check_curved_options
from .square import Square

GAMMAS = ("square", "cylinder")
"""The Γ of the 3D membranes: the flat face, or the part of the cylinder of radius R."""
RADIUS_MAX = 1e8
"""Largest finite R: the map's displacement (~ s²/(2R)) is computed from R-sized numbers and is
lost to round-off for a huge R (DUAL-Q9, k = 2, N = 2: R = 1e20 and 1e300 gave β_h = 0 where the
flat face gives 1.13875; R = 1e8 and 1e12 gave the flat face's β_h to 12 digits). Beyond 1e8 the
face is flat to 1e-8: inf says so exactly."""
RADIUS_ALLOWED = f"a number R in (1, {RADIUS_MAX:g}], or inf (the flat face)"
"""R = 1 would collapse Ω1's far face onto the cylinder's axis; above :data:`RADIUS_MAX` round-off."""
DEFAULT_COUPLING = "exact"
"""The coupling of a cylinder whose request names none."""


def check_cylinder_options(gamma, radius, coupling) -> None:
    """:class:`InputError` naming the key (:func:`~..segment.arc.check_curved_options` with
    :data:`GAMMAS`): with ``cylinder`` a radius R > 1 (inf allowed) and a coupling in
    :data:`~..segment.arc.COUPLINGS` or none; without it neither."""
    check_curved_options(gamma, radius, coupling, GAMMAS, RADIUS_ALLOWED)
    if gamma == GAMMAS[-1] and math.isfinite(radius) and radius > RADIUS_MAX:
        raise InputError("radius", f"{RADIUS_ALLOWED} (required with gamma cylinder)", got=radius)


@dataclass(frozen=True)
class Cylinder(Square):
    """Γ the part of the cylinder of radius ``radius``, parametrized by (arc length, y) (module docstring).

    Attributes
    ----------
    radius : float
        R > 1, or inf (the flat face).
    coupling : str
        One of :data:`~..segment.arc.COUPLINGS`.
    """

    radius: float = math.inf
    coupling: str = DEFAULT_COUPLING
    pairing: Callable | None = field(default=None, compare=False, repr=False)
    """``pairing(cylinder, sides) -> sides`` for ``projection`` (:func:`.cylinder_projection.project_pair`),
    given by the Γ table (:mod:`infsup_contact.discretization.spaces.gammas`), so that this module
    does not import its subclass's."""

    @property
    def curved(self) -> bool:
        return math.isfinite(self.radius)

    def cylinder_map(self):
        """Φ − id as an NGSolve coefficient function of the boxes' (x, y, z) (module docstring)."""
        import ngsolve

        R = float(self.radius)
        r = R - 1.0 + ngsolve.z
        return ngsolve.CF((r * ngsolve.sin(ngsolve.x / R) - ngsolve.x, 0.0,
                           r * ngsolve.cos(ngsolve.x / R) - R + 1.0 - ngsolve.z))

    def curve(self, mesh, k: int) -> None:
        """Make ``mesh`` (a box of the 3D membranes) the isoparametric image of its body under Φ:
        its deformation is the interpolant of Φ − id in the body's degree-k space. The dual
        degrees of freedom interpolate (vertex values exact); NGSolve's default ``Set`` is a
        local projection that moves the vertices off the cylinder and loses the h^{2k} rate.
        Nothing on a flat Γ."""
        import ngsolve

        if not self.curved:
            return
        mesh.UnsetDeformation()  # the map is of the box's coordinates, not of a curved mesh's
        deformation = ngsolve.GridFunction(ngsolve.VectorH1(mesh, order=int(k)))
        deformation.Set(self.cylinder_map(), dual=True, bonus_intorder=MOMENT_BONUS_INTORDER)
        mesh.SetDeformation(deformation)

    def embed(self, x):
        """Points of the exact cylinder at (arc length, y) ``x`` (n, 2)."""
        if not self.curved:
            return super().embed(x)
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        R = float(self.radius)
        return R * np.sin(x[:, 0] / R), x[:, 1], R * np.cos(x[:, 0] / R) - R + 1.0

    def paired(self, sides: list) -> list:
        """With ``projection``, the sides' traces tied to each other
        (:func:`.cylinder_projection.project_pair`); else as built."""
        if self.coupling != "projection":
            return sides
        if self.pairing is None:  # a caller's slip: the Γ table builds a projected cylinder with its pairing
            raise TypeError("a Cylinder coupled by projection is built by the Γ table (spaces.gammas.gamma_of), "
                            "which gives it its pairing")
        return self.pairing(self, sides)

