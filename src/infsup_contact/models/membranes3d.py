"""The membranes in 3D: −c_i Δu_i = f_i on Ω1 = (0,1)³ and Ω2 = (0,1)²×(1,2),
u_i = 0 on ∂Ω_i∖Γ, Γ = (0,1)²×{1} the contact face, b(v, μ) = ∫_Γ (v2 − v1) μ.

The paper's model problem (Section 3) one dimension up: the side operator is the Laplace
stiffness of continuous Q_k (hexahedra) or P_k (tetrahedra) with the Γ dofs last and its Γ
Schur complement (:func:`~infsup_contact.models.contract.factorized_side`; the nested-dissection
ordering is graph based, so it serves 3D meshes as it is). Γ is the face
:class:`~infsup_contact.discretization.face.shapes.square.Square`: the traces are tensor grids, the
multiplier spaces tensor products (:mod:`infsup_contact.discretization.face.spaces.tensor`) on
hexahedra and P_s on the triangles of G_h on tetrahedra
(:mod:`infsup_contact.discretization.face.spaces.triangles`).

Meshes (:func:`subdomain_mesh`, the model's ``mesh`` builder): the structured family,
N × N × N cells of each body (N = cells per direction on Γ) from
``ngsolve.meshes.MakeStructured3DMesh``: ``element="hex"`` gives hexahedra,
``element="tet"`` the six-tetrahedra (Kuhn) split of every cube, whose faces on Γ are the
rectangles cut by the diagonal from (x_i, y_j) to (x_{i+1}, y_{j+1}) — on both bodies, so the
trace is a tensor grid of triangles (:data:`~infsup_contact.discretization.face.shapes.square.SQUARE_TRIG`).
The ``unstructured`` family (Netgen tetrahedra, maxh = 1/N, each body meshed on its own) and
the ``perturbed`` one (structured, vertices moved; on hexahedra only off Γ and in z, so the
face stays a tensor grid) are built in :mod:`infsup_contact.discretization.face.meshes`; their
tetrahedral faces are general triangulations, Γ
:data:`~infsup_contact.discretization.face.shapes.triangulated_square.TRIANGULATED` (non-matching traces,
common refinement by polygon clipping).

``element="hex20"``: serendipity HEX20 bodies on the same structured cells, assembled by scikit-fem
(:mod:`.hex20`; k = 2; β_h and contact scenes supported on the far face or all of ∂Ω_i∖Γ, u_h
evaluated at points), Γ the QUAD8 face
:data:`~infsup_contact.discretization.face.shapes.serendipity.SERENDIPITY`.

Boundaries: ``gamma`` (Γ), ``dir`` (the far face: z = 0 of Ω1, z = 2 of Ω2) and ``side`` (the
four lateral faces). β_h clamps both (:data:`BETA_DIRICHLET`, the paper's u_i = 0 on ∂Ω_i∖Γ);
a contact scene may clamp fewer (its ``supports``: the face patch test keeps the lateral faces
natural, :mod:`infsup_contact.study.patch.face`).

**Contact** (the model contract, :mod:`.contract`, with n = e_z for e_y): a scene gives its
material scales ``c1``, ``c2``, its far-face displacements ``far_displacement`` (u_i on ``dir``,
a constant per side: the Dirichlet lift u_{D,i}) and its ``supports``; there is no body force,
so F_i = −c_i K_i u_{D,i} on the free dofs (:func:`load`), and λ = −c_i ∂u_i/∂z on Γ.
"""
from __future__ import annotations

import numpy as np
import ngsolve
from ngsolve import meshes as ngmeshes

from ..discretization.segment.meshes import DIRICHLET
from ..discretization.face import meshes as meshes3d
from ..discretization.face.shapes.cylinder import GAMMAS, RADIUS_ALLOWED, Cylinder
from ..discretization.spaces.gammas import cylinder_of
from ..discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from ..discretization.segment.arc import COUPLINGS
from ..discretization.face.shapes.serendipity import SERENDIPITY
from ..discretization.face.shapes.triangulated_square import TRIANGULATED
from ..errors import InputError, check_prestress
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import scipy.sparse as sp

from .contract import Body, MaterialParam, Model, OptionalChoice
from .membranes import field as membrane_field, interpolate as membrane_interpolate, laplace_stiffness
from .contract import SideOperator, extended, factorized_side, mirrored_side
from . import body_symmetry, hex20
from ..la.threaded import as_task, threads

ELEMENTS = ("hex", "tet")
"""Elements of the NGSolve bodies (the 3D elastic model's too)."""
MEMBRANE_ELEMENTS = ELEMENTS + ("hex20",)
"""Elements of the membranes: also serendipity HEX20 (scikit-fem, :mod:`.hex20`; k = 2, structured)."""
FAMILIES_3D = ("structured", "perturbed", "unstructured")
UNSTRUCTURED_ELEMENTS = ("tet",)
"""Elements of the unstructured family (Netgen meshes tetrahedra)."""
#: MakeStructured3DMesh's boundary numbering: back, left, front, right, bottom (z = 0), top (z = 1)
_BOTTOM, _TOP = 4, 5
FAR, LATERAL = DIRICHLET, "side"
"""Boundary names of the far face (z = 0 of Ω1, z = 2 of Ω2) and of the four lateral faces."""
BETA_DIRICHLET = f"{FAR}|{LATERAL}"
"""Where β_h's sides vanish: all of ∂Ω_i∖Γ (an NGSolve boundary regexp)."""


def subdomain_mesh(family: str, n: int, side: int, *, element: str = "hex", width: float = 1.0,
                   alpha: float = 0.2, seed: int = 0, gamma=None) -> Body:
    """The mesh of Ω_side of a family: Γ named ``gamma``, the far face :data:`FAR`, the
    lateral faces :data:`LATERAL`. ``structured``: N × N × N cells; ``unstructured`` (tetrahedra,
    maxh = 1/N) and ``perturbed`` (the structured mesh, vertices moved by U(−αh, αh) per free
    direction, seeded; on hexahedra off Γ and in z only): :mod:`~infsup_contact.discretization.face.meshes`.
    Returned with its Γ (:func:`interface_of`: the general triangulated face for the tetrahedra of
    those two families).

    ``width``: the body's extent in x, (0, width) × (0, 1) × (side − 1, side) (the ``mapping`` of
    ``MakeStructured3DMesh`` scales x); 1 is the model's bodies. A narrower Ω2 covers Ω1's face
    partially (:mod:`infsup_contact.study.face.edge_dropping`); its Γ is then
    ``Square(width=width)``.

    ``gamma``: the request's Γ (:func:`face_gamma`, resolved and checked without a mesh); a
    :class:`~infsup_contact.discretization.face.shapes.cylinder.Cylinder`: the box is built as here
    and curved by :func:`side_operator`, where the body's degree is known; None or the flat face:
    the body's own face.

    Raises
    ------
    InputError
        For a family not in :data:`FAMILIES_3D`, an element not in :data:`MEMBRANE_ELEMENTS` (the
        unstructured family: :data:`UNSTRUCTURED_ELEMENTS`; ``hex20``: structured, width 1), N < 1,
        a width outside (0, 1] (or
        other than 1 for the unstructured and perturbed families), α or seed out of range, a
        cylinder's options (:func:`~infsup_contact.discretization.face.shapes.cylinder.check_cylinder_options`)
        or a body it does not curve.
    """
    if gamma is not None:
        body = subdomain_mesh(family, n, side, element=element, width=width, alpha=alpha, seed=seed)
        return body if gamma == body.interface else Body(body.mesh, gamma)
    if not isinstance(n, (int, np.integer)) or n < 1:
        raise InputError("N", "an integer >= 1", got=n)
    check_body(family, element, width)
    if element == "hex20":
        return hex20.subdomain_mesh(int(n), side)
    if family == "unstructured":
        return Body(meshes3d.unstructured_box(int(n), side), interface_of(family, element))
    mapping = None if width == 1.0 else (lambda x, y, z: (width * x, y, z))
    ngmesh = ngmeshes.MakeStructured3DMesh(hexes=element == "hex", nx=int(n), mapping=mapping).ngmesh
    if side == 2:
        for p in ngmesh.Points():
            p[2] += 1.0
    gamma, far = (_TOP, _BOTTOM) if side == 1 else (_BOTTOM, _TOP)
    for i in range(6):
        ngmesh.SetBCName(i, SQUARE.boundary if i == gamma else FAR if i == far else LATERAL)
    if family == "perturbed":
        meshes3d.perturb_points(ngmesh, int(n), side, alpha, seed, hexes=element == "hex")
    mesh = ngsolve.Mesh(ngmesh)
    if family == "perturbed":
        meshes3d.check_volume(mesh, f"family perturbed, N = {n}, side {side}, seed {seed}, alpha {alpha:g}")
    return Body(mesh, interface_of(family, element))


def check_body(family: str, element: str, width: float = 1.0) -> None:
    """:class:`InputError` naming the key unless the bodies of ``family`` with ``element`` cells and
    ``width`` exist (:func:`subdomain_mesh`'s refusals, without a mesh)."""
    if family not in FAMILIES_3D:
        raise InputError("family", f"{', '.join(FAMILIES_3D)} (the 3D model's meshes)", got=family)
    if element not in MEMBRANE_ELEMENTS:
        raise InputError("element", ", ".join(MEMBRANE_ELEMENTS), got=element)
    if element == "hex20":
        if family != "structured" or width != 1.0:
            raise InputError("family" if family != "structured" else "width",
                             "structured, width 1 (the HEX20 bodies)", got=family if family != "structured" else width)
        return
    if not 0.0 < width <= 1.0 or (family != "structured" and width != 1.0):
        raise InputError("width", "a width 0 < width <= 1 of the body in x (1 for the unstructured and "
                         "perturbed families)", got=width)
    if family == "unstructured" and element not in UNSTRUCTURED_ELEMENTS:
        raise InputError("element", f"{', '.join(UNSTRUCTURED_ELEMENTS)} (the unstructured family)", got=element)


def face_gamma(family: str = "structured", element: str = "hex", width: float = 1.0, gamma=None, radius=None,
               coupling=None, **_) -> object:
    """Γ of the bodies of a request, without a mesh (the model's ``interface``): the face of its
    cells (:func:`interface_of`; HEX20's QUAD8 face), or the cylinder of the options
    (:func:`~infsup_contact.discretization.spaces.gammas.cylinder_of`), refused where the face is no
    tensor grid of :class:`~infsup_contact.discretization.face.shapes.square.Square` (HEX20's QUAD8
    face, the triangulated faces of the perturbed and unstructured tetrahedra) or narrower; the
    bodies checked first (:func:`check_body`)."""
    check_body(family, element, width)
    flat = SERENDIPITY if element == "hex20" else interface_of(family, element)
    if gamma == "cylinder":
        if element == "hex20":
            raise InputError("element", "hex, tet (the bodies curved to the cylinder)", got=element)
        if flat not in (SQUARE, SQUARE_TRIG):
            raise InputError("family", "structured, or perturbed with element hex (the faces curved to the "
                             "cylinder)", got=f"{family} with element {element}")
        if width != 1.0:
            raise InputError("width", "1 (the cylinder's bodies)", got=width)
    return cylinder_of(flat, gamma, radius, coupling) or flat


def interface_of(family: str, element: str):
    """Γ of a body of ``family`` with ``element`` cells: the structured tensor faces (rectangles on
    hexahedra, their Kuhn triangles on tetrahedra), else, where the tetrahedra's face is no longer
    a tensor grid (the perturbed and unstructured families), the general triangulated face."""
    if element == "tet" and family != "structured":
        return TRIANGULATED
    return SQUARE if element == "hex" else SQUARE_TRIG


def displacement_space(mesh, k: int, dirichlet: str = BETA_DIRICHLET):
    """V_{h,i}: continuous Q_k / P_k vanishing on ``dirichlet`` (default all of ∂Ω_i∖Γ)."""
    return ngsolve.H1(mesh, order=k, dirichlet=dirichlet)


@dataclass(frozen=True)
class MembraneSide(SideOperator):
    """A :class:`SideOperator` plus K_i on every dof (``stiffness_all``): the loads of a
    scene's Dirichlet lift, F_i = −c_i K_i u_{D,i} (None on a β_h side, which never solves:
    :func:`load` assembles it where such a side is given a scene)."""

    stiffness_all: sp.csr_matrix | None = None


def side_operator(body: Body, k: int, route: str = "auto", dirichlet: str = BETA_DIRICHLET, gamma=None,
                  keep_factor: bool = False, mirror_of=None) -> MembraneSide:
    """Factorize the Laplace stiffness K_i of Q_k / P_k once, Γ dofs last (c = 1), u_i = 0 on
    ``dirichlet`` (default all of ∂Ω_i∖Γ). With natural lateral faces the Γ dofs on ∂Γ are free:
    the trace spans continuous Q_k / P_k on the partition, ∂Γ included.

    ``body``: the mesh and its Γ (:func:`subdomain_mesh`); ``gamma``: another interface whose trace
    is taken (a narrower body passes ``Square(width=...)``); ``keep_factor``: the factorization that
    gives S also serves the solves (:func:`~.schur.gamma_factorization`; a scene's side). A HEX20
    body (:mod:`.hex20`) is assembled by scikit-fem, u_i = 0 on all of ∂Ω_i∖Γ only (a scene's far face:
    :func:`scene_side`)."""
    if hex20.is_hex20(body):
        if dirichlet != BETA_DIRICHLET or gamma is not None:
            raise InputError("element", "hex, tet (supports other than ∂Ω_i∖Γ, a narrower Γ); hex20 bodies: "
                             "β_h on all of ∂Ω_i∖Γ, a contact scene's far face by scene_side", got="hex20")
        return hex20.side_operator(body, k, route, keep_factor)
    a = _assembled(body, k, dirichlet, gamma, keep_factor)
    base = (factorized_side(a.trace, a.free, a.K, route, keep_factor, a.signature) if mirror_of is None else
            mirrored_side(mirror_of, a.trace, a.free, a.K, a.signature, route, keep_factor))
    return extended(base, MembraneSide, stiffness_all=a.K_all)


@dataclass(frozen=True)
class _Assembled:
    """What NGSolve gives of one body (:func:`_assembled`): its trace on Γ, the free dofs (Γ last),
    K on them, K on every dof (a side that solves) and the dofs' symmetry signature."""

    trace: object
    free: np.ndarray
    K: sp.csc_matrix
    K_all: sp.csr_matrix | None
    signature: np.ndarray | None


def _assembled(body: Body, k: int, dirichlet: str = BETA_DIRICHLET, gamma=None,
               keep_factor: bool = False) -> _Assembled:
    """The NGSolve part of :func:`side_operator` (curving, space, trace, stiffness, signature)."""
    if isinstance(body.interface, Cylinder):
        body.interface.curve(body.mesh, k)  # the isoparametric body: degree k is known here
    fes = displacement_space(body.mesh, k, dirichlet)
    trace = (body.interface if gamma is None else gamma).trace(fes)
    free_mask = np.array(fes.FreeDofs(), dtype=bool)
    is_gamma = np.zeros(fes.ndof, dtype=bool)
    is_gamma[trace.gamma_dofs] = True
    free = np.concatenate([np.flatnonzero(free_mask & ~is_gamma), trace.gamma_dofs])
    # K on every dof serves the loads of a scene's lift (a side that solves); a β_h side never
    # holds it (190 MB a side at k = 2, N = 32: :func:`load` would assemble it again)
    K_all = laplace_stiffness(fes) if keep_factor else None
    K = K_all[free][:, free].tocsc() if keep_factor else laplace_stiffness(fes, free)
    signature = body_symmetry.ngsolve_signature(fes)
    return _Assembled(trace, free, K, K_all, None if signature is None else signature[free])


def matching_pair(body1: Body, make_body2, k: int) -> tuple:
    """(side 1, side 2) of a matching pair (``Model.matching_pair``): the sides
    :func:`side_operator` and :func:`mirror_side` give, bit for bit, with side 1's factorization
    (PARDISO, numpy; no NGSolve) in a thread of its own beside this thread's mesh and stiffness of
    body 2 (NGSolve, in one thread at a time as ever) and its search for the mirror (k = 2,
    N = 48: about 8 s of side 2's one-core work beside side 1's 40 s on two). This thread runs as
    one task (:func:`~infsup_contact.la.threaded.as_task`: one BLAS thread, NGSolve's assembly
    serial, bit for bit its task manager's). HEX20 and curved bodies, or a request on one
    thread: one side after the other."""
    if hex20.is_hex20(body1) or isinstance(body1.interface, Cylinder) or threads() < 2:
        side1 = side_operator(body1, k)
        return side1, mirror_side(side1, make_body2(), k)
    a1 = _assembled(body1, k)
    n_gamma = len(a1.trace.gamma_dofs)
    with ThreadPoolExecutor(1, thread_name_prefix="infsup-side1") as pool:
        factorized = pool.submit(factorized_side, a1.trace, a1.free, a1.K, signature=a1.signature)
        with as_task():
            a2 = _assembled(make_body2(), k)
            sigma = body_symmetry.mirror_permutation(a1.signature, a1.K, a2.signature, a2.K, n_gamma)
        side1 = extended(factorized.result(), MembraneSide, stiffness_all=None)
    side2 = mirrored_side(side1, a2.trace, a2.free, a2.K, a2.signature, sigma=sigma)
    return side1, extended(side2, MembraneSide, stiffness_all=None)


def mirror_side(side1, body: Body, k: int):
    """Ω2's β_h side of a matching pair from Ω1's ``side1`` (``Model.mirror_side``): built as
    :func:`side_operator` (or :func:`.hex20.side_operator`) with ``mirror_of``, so that where a mirror
    maps the bodies (checked entry by entry on K, :func:`~.contract.mirrored_side`) Ω1's
    factorization serves, else Ω2 is factorized on its own. Either factorization uses the body's
    symmetries where they are checked on K (:func:`~.contract.factorized_side`: parity parts)."""
    if hex20.is_hex20(body):
        return hex20.side_operator(body, k, mirror_of=side1)
    return side_operator(body, k, mirror_of=side1)


def scene_side(scene, body: Body, k: int):
    """The side of a contact scene: u_i prescribed on the scene's ``supports`` (an NGSolve
    boundary regexp; the face patch test: the far face only), else on all of ∂Ω_i∖Γ. A HEX20 body
    (:mod:`.hex20`) takes the far face alone or all of ∂Ω_i∖Γ; other supports are refused naming
    ``element``."""
    supports = getattr(scene, "supports", None) or BETA_DIRICHLET
    if hex20.is_hex20(body):
        names = set(supports.split("|")) if isinstance(supports, str) else None
        if names not in ({FAR}, {FAR, LATERAL}):
            raise InputError("element", f"hex, tet (the scene's supports {supports!r}; hex20 bodies take "
                             f"{FAR!r} or {BETA_DIRICHLET!r})", got="hex20")
        return hex20.scene_side(body, k, lateral=LATERAL in names)
    return side_operator(body, k, dirichlet=supports, keep_factor=True)


def load(side, scene, i: int):
    """(F_i, u_{D,i}): the lift u_{D,i} = ``scene.far_displacement[i]`` on the far face (0 on the
    other supports), F_i = −c_i (K_i u_{D,i}) on the free dofs (no body force)."""
    c = (scene.c1, scene.c2)[i]
    if hex20.is_hex20_side(side):
        return hex20.load(side, scene.far_displacement[i], c)
    fes = side.trace.fes
    gf = ngsolve.GridFunction(fes)
    gf.Set(float(scene.far_displacement[i]), definedon=fes.mesh.Boundaries(FAR))
    lift = gf.vec.FV().NumPy().copy()
    lift[np.array(fes.FreeDofs(), dtype=bool)] = 0.0  # only the supports carry the lift
    K_all = side.stiffness_all if side.stiffness_all is not None else laplace_stiffness(fes)
    return -c * (K_all @ lift)[side.free], lift


def field(side, values: np.ndarray, lift=None):
    """u_{i,h} from its free-dof values and the lift: an NGSolve GridFunction, or on a HEX20 body a
    :class:`~.hex20.Hex20Field` (evaluated at points)."""
    if hex20.is_hex20_side(side):
        return hex20.field(side, values, lift)
    return membrane_field(side, values, lift)


def interpolate(side, components) -> np.ndarray:
    """The interpolant of NGSolve coefficient functions (all dofs); refused on a HEX20 body, whose
    space is not NGSolve's (a scene compares its exact u at points there, ``exact_values``)."""
    if hex20.is_hex20_side(side):
        raise InputError("element", "hex, tet (the interpolant of an NGSolve coefficient function; hex20 "
                         "bodies compare u at points)", got="hex20")
    return membrane_interpolate(side, components)


MEMBRANES3D = Model("membranes3d", side_operator,
                    "two 3D bodies (0,1)^3 and (0,1)^2x(1,2), -c_i Δu_i = f_i, scalar Q_k (hex), P_k (tet) or "
                    "serendipity Q2 (hex20, k = 2), "
                    "contact face Γ = (0,1)^2x{1}; structured, perturbed or unstructured (tet) meshes, "
                    "N cells per direction or maxh = 1/N (--element)",
                    scene_side=scene_side, load=load, field=field, interpolate=interpolate,
                    mirror_side=mirror_side, matching_pair=matching_pair,
                    params=tuple(MaterialParam(f"c{i + 1}", 1.0, lambda v, key: check_prestress(key, v),
                                               "1e-150 <= c <= 1e150", f"prestress c{i + 1} of Ω{i + 1}", side=i)
                                 for i in range(2)),
                    mesh=subdomain_mesh, families=FAMILIES_3D, dim=3,
                    interface=face_gamma, curving=("square", "cylinder"),
                    mesh_options=(("element", MEMBRANE_ELEMENTS), ("gamma", OptionalChoice(GAMMAS)),
                                  ("radius", OptionalChoice(text=RADIUS_ALLOWED + ", with --gamma cylinder",
                                                            above=1.0)),
                                  ("coupling", OptionalChoice(COUPLINGS, filled_when=("gamma", "cylinder")))))
"""The 3D membranes through the model seam (β_h, and contact scenes with far-face displacements)."""
