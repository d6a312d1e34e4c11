"""The 3D elastic contact patch test on the face Γ = (0,1)²×{1}.

Two isotropic linear-elastic bodies, Ω1 = (0,1)³ (Young's modulus E1) and Ω2 = (0,1)²×(1,2)
(E2), Poisson ratio ν, on non-matching structured meshes (N1 ≠ N2 cells per direction on Γ),
frictionless contact on Γ with b(v, μ) = ∫_Γ (v_{2,z} − v_{1,z}) μ
(:mod:`infsup_contact.models.elastic3d`). Supports, chosen so that the exact solution is a
uniaxial compression:

* far faces (``dir``): u_z = 0 on z = 0 of Ω1, u_z = −δ on z = 2 of Ω2, u_x, u_y free;
* the lateral faces x = 0 and y = 0 (symmetry planes, :data:`~infsup_contact.discretization.segment.meshes.SYMMETRY_X`,
  ``SYMMETRY_Y``): u_x = 0 and u_y = 0 respectively, the other components free;
* the lateral faces x = 1 and y = 1: traction free.

These fix the rigid modes of each body minimally (u_z on the far face: the z translation and
the rotations about x and y; u_x on x = 0: the x translation and the rotation about z; u_y on
y = 0: the y translation), so K_2 is invertible although Ω2 is held in z by contact only.

**Exact solution.** σ = −p e_z ⊗ e_z in both bodies (Hooke's law: ε_zz = −p/E_i,
ε_xx = ε_yy = ν p/E_i), so

    u_1 = (ν p x/E1, ν p y/E1, −p z/E1),
    u_2 = (ν p x/E2, ν p y/E2, −p/E1 − p (z − 1)/E2),   p = δ / (1/E1 + 1/E2),

(u_{2,z}(2) = −δ fixes p). Every support condition holds (u_x = 0 on x = 0, u_y = 0 on y = 0,
zero shear traction on every face, zero traction on x = 1, y = 1), the gap u_{2,z} − u_{1,z} is 0
on Γ, and λ = −σ_zz = p > 0 with zero tangential traction: contact active, frictionless (for
E1 ≠ E2 the tangential displacements jump across Γ: the bodies slip). The contact problem is
monotone and u is unique, so this is it.

**Prediction (stated before the run).** u_i is linear, so it lies in every V_{h,i} (vector
Q_k / P_k, k ≥ 1) and its z traces coincide (B(u_2 − u_1) = 0). If 1 ∈ M_h, (u, p·1) satisfies
the discrete system exactly — B_iᵀ(p 1) are the consistent nodal forces of the uniform
traction and A_i u_i = F_i ∓ B_iᵀ(p 1) by Green's formula — so λ_h = p and u_h = u to
round-off on non-matching faces iff 1 ∈ M_h, computed on the space the solve uses
(:func:`~infsup_contact.discretization.gamma.constants.spans_constants`); T3 (vanishing on ∂Γ)
fails. The z traces do not vanish on ∂Γ (u_z is free on the lateral faces), as in the
membranes' face patch test (:mod:`.face`), whose solve and measures this scene shares
(:func:`~.face_patch.solve_face_patch` with this scene's data).

**Outcome** (k = 1, 2, 3; hexahedra and tetrahedra; N1:N2 = 4:5; E = (1, 1) and (1, 3),
ν = 0.3; G_h = trace of Ω2; 76 rows, an exploratory run outside the DAG, the test
``tests/models/test_elastic3d.py`` pins the rule on 3:4): every space holding the constants reproduces
λ to 1e-14..6e-10 (R5.4 on tetrahedra the largest) and u to ≤ 1e-13 of δ, T3 fails (λ error
1.2–2.4, u error 3e-2..0.16 δ) — as predicted, with one exception shared with the membranes'
face patch test (same failure there, λ error 1): DUAL at k = 1 on tetrahedra (dim M = the
interior nodes of G_h) fails although the registry's ``contains_constants(1)`` (the segment's
answer) says it holds the constants; computed on the face space itself, 1 ∉ M_h, which is now
the prediction: on triangles the boundary modification keeps
Σ ψ = 1 only where a triangle has a live node, and the two corner triangles with all three
vertices on ∂Γ (the diagonal split at the corners (1, 0) and (0, 1)) have none, so λ_h = 0
there (error 1; at k = 2 their edge midpoints are live and DUAL passes). R5.4 at k = 1 on
tetrahedra has a one-mode kernel and still passes.
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve
import numpy as np

from ...discretization.segment.meshes import DIRICHLET, SYMMETRY_X, SYMMETRY_Y
from ...errors import InputError
from ...models import make_model
from ...models.plane_strain import check_modulus, check_nu
from ...contact.contact import contact_pair
from ...solvers.request import MeshOptions
from .face import DELTA, solve_face_patch
from ..contact.registry import ELASTIC_FACE_PATCH
from . import table

SCENE = ELASTIC_FACE_PATCH.id
"""This scene's registry id (:mod:`..scene_registry` declares it and its model)."""
SUPPORTS = (SYMMETRY_X, SYMMETRY_Y, DIRICHLET)
"""Where u_x, u_y, u_z are prescribed (NGSolve boundary regexps)."""


@dataclass(frozen=True)
class CompressedCubes:
    """The elastic face patch test's data (a contact scene of the 3D elastic bodies).

    Attributes
    ----------
    name : str
        The scene's registry id.
    c1, c2 : float
        Young's moduli E1, E2 (the model contract's material scales).
    nu : float
        Poisson ratio of both bodies.
    d : float
        Downward displacement δ of Ω2's far face.
    supports : tuple of str
        x, y, z Dirichlet boundaries (:data:`SUPPORTS`).
    """

    name: str
    c1: float
    c2: float
    nu: float
    d: float
    supports: tuple = SUPPORTS

    @property
    def far_displacement(self) -> tuple:
        """u_z on the far face of Ω1, Ω2."""
        return (0.0, -self.d)

    @property
    def pressure(self) -> float:
        """p = δ / (1/E1 + 1/E2) = −σ_zz (module docstring)."""
        return self.d / (1.0 / self.c1 + 1.0 / self.c2)

    def exact(self) -> tuple:
        """(u1, u2) as vector NGSolve coefficient functions (module docstring)."""
        p, nu = self.pressure, self.nu
        x, y, z = ngsolve.x, ngsolve.y, ngsolve.z
        u1 = ngsolve.CoefficientFunction((nu * p * x / self.c1, nu * p * y / self.c1, -p * z / self.c1))
        u2 = ngsolve.CoefficientFunction((nu * p * x / self.c2, nu * p * y / self.c2,
                                          -p / self.c1 - p * (z - 1.0) / self.c2))
        return u1, u2

    def exact_values(self, i: int, points: np.ndarray) -> np.ndarray:
        """u_{i+1} at ``points`` (n, 3), shape (n, 3): :meth:`exact` in numpy."""
        p, nu, c = self.pressure, self.nu, (self.c1, self.c2)[i]
        x, y, z = np.asarray(points, float).T
        uz = -p * z / self.c1 if i == 0 else -p / self.c1 - p * (z - 1.0) / self.c2
        return np.column_stack([nu * p * x / c, nu * p * y / c, uz])


def patch_scene(E=(1.0, 1.0), nu: float = 0.3, delta: float = DELTA) -> CompressedCubes:
    """The scene's data with moduli ``E``, Poisson ratio ``nu`` and far-face displacement ``delta``."""
    if not (np.isfinite(delta) and 0.0 < delta < 1.0):
        raise InputError("delta", "0 < delta < 1", got=delta)
    E = tuple(check_modulus(e, key) for e, key in zip(E, ("E1", "E2")))
    return CompressedCubes(SCENE, E[0], E[1], check_nu(nu), float(delta))


def patch_pair(k: int, n1: int, n2: int, E=(1.0, 1.0), nu: float = 0.3, delta: float = DELTA,
               element: str = "hex", model=None):
    """Both factorized bodies of the scene (shared by every case); ``model``: the scene's
    model built with ``nu`` (default from the registry)."""
    model = make_model(ELASTIC_FACE_PATCH.models[0], nu=nu) if model is None else model
    return contact_pair(patch_scene(E, nu, delta), k, "structured", n1, n2, model, MeshOptions(element=element))


def solve_elastic_face_patch(case: str, k: int, n1: int, n2: int, E=(1.0, 1.0), nu: float = 0.3,
                             delta: float = DELTA, element: str = "hex", pair=None, **kwargs) -> dict:
    """One row of :func:`~.face_patch.solve_face_patch` for this scene (its ``c1``, ``c2`` named
    ``E1``, ``E2``, as the 2D elastic patch test's; ``nu`` added); ``pair``: :func:`patch_pair` of the same arguments, to share it across cases."""
    scene = patch_scene(E, nu, delta)
    if pair is None:
        pair = patch_pair(k, n1, n2, E, nu, delta, element)
    row = solve_face_patch(case, k, n1, n2, E, delta, element, pair=pair, scene=scene, **kwargs)
    return {{"c1": "E1", "c2": "E2"}.get(key, key): value for key, value in row.items()} | dict(nu=scene.nu)


def elastic_face_patch_rows(cases, ks, pairs, E=(1.0, 1.0), nu: float = 0.3, delta: float = DELTA,
                            element: str = "hex", model=None) -> list:
    """:func:`solve_elastic_face_patch` for every case defined for each k and every (N1, N2)
    (:func:`.table.patch_rows`)."""
    return table.patch_rows(lambda k, n1, n2: patch_pair(k, n1, n2, E, nu, delta, element, model),
                            lambda case, k, n1, n2, pair: solve_elastic_face_patch(case, k, n1, n2, E, nu, delta,
                                                                                   element, pair=pair),
                            cases, ks, pairs)
