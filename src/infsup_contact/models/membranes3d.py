"""The membranes in 3D (issue 28): −c_i Δu_i = f_i on Ω1 = (0,1)³ and Ω2 = (0,1)²×(1,2),
u_i = 0 on ∂Ω_i∖Γ, Γ = (0,1)²×{1} the contact face, b(v, μ) = ∫_Γ (v2 − v1) μ.

The paper's model problem (Section 3) one dimension up: the side operator is the Laplace
stiffness of continuous Q_k (hexahedra) or P_k (tetrahedra) with the Γ dofs last and its Γ
Schur complement (:func:`~infsup_contact.models.schur.factorized_side`; the nested-dissection
ordering is graph based, so it serves 3D meshes as it is). Γ is the face
:class:`~infsup_contact.discretization.square.Square`: the traces are tensor grids, the
multiplier spaces tensor products (:mod:`infsup_contact.discretization.face_spaces`).

Meshes (:func:`subdomain_mesh`, the model's ``mesh`` builder): the structured family only,
N × N × N cells of each body (N = cells per direction on Γ) from
``ngsolve.meshes.MakeStructured3DMesh``: ``element="hex"`` gives hexahedra,
``element="tet"`` the six-tetrahedra (Kuhn) split of every cube, whose faces on Γ are the
rectangles cut by the diagonal from (x_i, y_j) to (x_{i+1}, y_{j+1}) — on both bodies, so the
trace is a tensor grid of triangles (:data:`~infsup_contact.discretization.square.SQUARE_TRIG`).
"""
from __future__ import annotations

import numpy as np
import ngsolve
from ngsolve import meshes as ngmeshes

from ..discretization.square import SQUARE, SQUARE_TRIG
from ..errors import InputError, check_prestress
from .contract import MaterialParam, Model
from .membranes import displacement_space, laplace_stiffness
from .schur import SideOperator, factorized_side

ELEMENTS = ("hex", "tet")
FAMILIES_3D = ("structured",)
#: MakeStructured3DMesh's boundary numbering: back, left, front, right, bottom (z = 0), top (z = 1)
_BOTTOM, _TOP = 4, 5


def subdomain_mesh(family: str, n: int, side: int, *, element: str = "hex", width: float = 1.0) -> ngsolve.Mesh:
    """The N × N × N structured mesh of Ω_side, Γ named ``gamma`` and the rest of ∂Ω_side ``dir``.

    ``width``: the body's extent in x, (0, width) × (0, 1) × (side − 1, side) (the ``mapping`` of
    ``MakeStructured3DMesh`` scales x); 1 is the model's bodies. A narrower Ω2 covers Ω1's face
    partially (:mod:`infsup_contact.study.edge_dropping`); its Γ is then
    ``Square(width=width)``.

    Raises
    ------
    InputError
        For a family other than ``structured``, an element not in :data:`ELEMENTS`, N < 1 or a
        width outside (0, 1].
    """
    if family not in FAMILIES_3D:
        raise InputError("family", f"{', '.join(FAMILIES_3D)} (the 3D model's meshes)", got=family)
    if element not in ELEMENTS:
        raise InputError("element", ", ".join(ELEMENTS), got=element)
    if not isinstance(n, (int, np.integer)) or n < 1:
        raise InputError("N", "an integer >= 1", got=n)
    if not 0.0 < width <= 1.0:
        raise InputError("width", "a width 0 < width <= 1 of the body in x", got=width)
    mapping = None if width == 1.0 else (lambda x, y, z: (width * x, y, z))
    ngmesh = ngmeshes.MakeStructured3DMesh(hexes=element == "hex", nx=int(n), mapping=mapping).ngmesh
    if side == 2:
        for p in ngmesh.Points():
            p[2] += 1.0
    gamma = _TOP if side == 1 else _BOTTOM
    for i in range(6):
        ngmesh.SetBCName(i, SQUARE.boundary if i == gamma else "dir")
    return ngsolve.Mesh(ngmesh)


def face_of(mesh):
    """The interface of a mesh's Γ: quadrilateral faces (hexahedra) or triangles (tetrahedra)."""
    for el in mesh.Elements(ngsolve.BND):
        if el.mat == SQUARE.boundary:
            return SQUARE if len(el.vertices) == 4 else SQUARE_TRIG
    raise InputError("mesh", f"boundary elements named {SQUARE.boundary!r}")


def side_operator(mesh, k: int, route: str = "auto", gamma=None) -> SideOperator:
    """Factorize the Laplace stiffness K_i of Q_k / P_k once, Γ dofs last (c = 1).

    ``gamma``: the interface whose trace is taken (default :func:`face_of` the mesh, the unit
    face; a narrower body passes ``Square(width=...)``)."""
    fes = displacement_space(mesh, k)
    trace = (face_of(mesh) if gamma is None else gamma).trace(fes)
    free_mask = np.array(fes.FreeDofs(), dtype=bool)
    is_gamma = np.zeros(fes.ndof, dtype=bool)
    is_gamma[trace.gamma_dofs] = True
    free = np.concatenate([np.flatnonzero(free_mask & ~is_gamma), trace.gamma_dofs])
    return factorized_side(trace, free, laplace_stiffness(fes)[free][:, free].tocsc(), route)


MEMBRANES3D = Model("membranes3d", side_operator,
                    "two 3D bodies (0,1)^3 and (0,1)^2x(1,2), -c_i Δu_i = f_i, scalar Q_k (hex) or P_k (tet), "
                    "contact face Γ = (0,1)^2x{1}; structured meshes, N cells per direction (--element)",
                    params=tuple(MaterialParam(f"c{i + 1}", 1.0, lambda v, key: check_prestress(key, v),
                                               "1e-150 <= c <= 1e150", f"prestress c{i + 1} of Ω{i + 1}", side=i)
                                 for i in range(2)),
                    mesh=subdomain_mesh, mesh_options=(("element", ELEMENTS),), families=FAMILIES_3D, dim=3)
"""The 3D membranes through the model seam (β_h only: no contact scenes yet)."""
