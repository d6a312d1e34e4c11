"""Linear elasticity of two 3D bodies through the model seam: the elastic bodies through the
same model contract as the membranes.

Ω1 = (0,1)³ and Ω2 = (0,1)²×(1,2) meet on the face Γ = (0,1)²×{1}, normal n = e_z (from Ω1
into Ω2). Displacements are continuous vector Q_k on hexahedra or P_k on tetrahedra (NGSolve
``VectorH1``, its components numbered in blocks x, y, z), on the structured meshes of the 3D
membranes (:func:`~infsup_contact.models.membranes3d.subdomain_mesh`). The energy at unit
Young's modulus is

    a(u, v) = ∫ 2 μ̂ ε(u):ε(v) + λ̂ div u div v,  μ̂ = 1/(2(1+ν)),  λ̂ = ν/((1+ν)(1−2ν))

(the Lamé constants of :func:`~infsup_contact.models.plane_strain.lame`, which plane strain takes
from the 3D law as they are), so A_i = E_i K_i: the contract's material scale c_i is E_i and ν
belongs to the model instance (:func:`elastic3d_model`); the material flags and their checks
are the 2D elastic model's (:data:`~infsup_contact.models.elastic.PARAMS`).

**Frictionless contact.** b(v, μ) = ∫_Γ (v2·n − v1·n) μ = ∫_Γ (v_{2,z} − v_{1,z}) μ, so B_i sees
the z-component dofs on Γ only: the side's trace (``trace.fes``) is the z component. The free
dofs are ordered [interior, Γ x, Γ y, Γ z]; eliminating the tangential Γ dofs with the interior
(block elimination), the Schur complement onto the Γ z dofs is ((A⁻¹)_ΓΓ)_zz⁻¹, the zz block
of the full Γ Steklov inverse, exactly as the 2D model does with its normal dofs
(:mod:`.elastic`): :func:`~infsup_contact.models.contract.factorized_side` with the z dofs as its
Γ block gives the interface operator unchanged. **Sign**: A_1 u_1 = F_1 − B_1ᵀ λ,
A_2 u_2 = F_2 + B_2ᵀ λ (:data:`~.contract.B_SIGN`), λ = −σ_zz on Γ (compression positive).

**Supports.** β_h clamps all of ∂Ω_i∖Γ (:data:`BETA_DIRICHLET`, as the 3D membranes), so the
z trace vanishes on ∂Γ and W_h, the structural kernel count dim M − dim W and the
H^{-1/2}_00(Γ) norm are those of the membranes. A contact scene gives its ``supports``: one
NGSolve boundary regexp per component (x, y, z). The lateral faces x = 0 and y = 0 carry their
own names (:data:`SYMMETRY_X`, :data:`SYMMETRY_Y`: symmetry planes u_x = 0, u_y = 0 of the
elastic face patch test, :mod:`infsup_contact.study.patch.elastic3d`); the other two keep
``side``.

**Loads** (contract): a scene's far-face displacement ``far_displacement[i]`` is u_z on Ω_i's
far face (the Dirichlet lift u_{D,i}, x and y lifts 0); no body force, F_i = −E_i K_i u_{D,i}.

**Measured** (β_h in H^{-1/2}_00(Γ), hexahedra, ν = 0.3, E1 = E2 = 1; exploratory runs of
``infsup-contact beta --model elastic3d``, outside the DAG): the kernels are those of the 3D
membranes case by case (they are kernels of the couplings, which see the same z traces), and on
matching meshes the dimension count max(dim M − dim W, 0). The β_h of the stable spaces are
those of the membranes times ~1.3–1.4 (T3, k = 2: 1.466 / 1.073 at N = 4), and flat from
N = 4 to 6. As ν → 1/2, β_h → 0 like √(1 − 2ν) for every space alike (k = 2, N = 4: 0.75,
0.26, 0.084 at ν = 0.49, 0.499, 0.4999): a clamped incompressible body keeps ∫_Γ u_z = 0, so
the normal compliance of a uniform pressure vanishes — a property of the continuous problem
at fixed E, not of M_h.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
import ngsolve
import scipy.sparse as sp

from ..discretization.segment.meshes import SYMMETRY_X, SYMMETRY_Y
from ..errors import InputError
from .contract import Model
from .elastic import PARAMS
from .membranes3d import ELEMENTS, FAMILIES_3D, FAR, LATERAL, face_gamma
from .membranes3d import subdomain_mesh as cube_mesh
from .plane_strain import check_nu, lame
from .contract import Body, SideOperator, factorized_side

BETA_DIRICHLET = f"{FAR}|{LATERAL}|{SYMMETRY_X}|{SYMMETRY_Y}"
"""All of ∂Ω_i∖Γ (an NGSolve boundary regexp): where β_h's sides vanish, every component."""
CLAMPED = (BETA_DIRICHLET,) * 3
"""Supports (x, y, z) of β_h: u = 0 on ∂Ω_i∖Γ."""


def subdomain_mesh(family: str, n: int, side: int, *, element: str = "hex", width: float = 1.0,
                   alpha: float = 0.2, seed: int = 0) -> Body:
    """The mesh of the 3D membranes (:func:`~infsup_contact.models.membranes3d.subdomain_mesh`,
    same arguments, families and checks) with the lateral faces x = 0 and y = 0 renamed
    :data:`SYMMETRY_X` and :data:`SYMMETRY_Y` (found by their vertices)."""
    body = cube_mesh(family, n, side, element=element, width=width, alpha=alpha, seed=seed)
    mesh = body.mesh
    names = {}
    for el in mesh.Elements(ngsolve.BND):
        if el.mat != LATERAL or el.index in names:
            continue
        p = np.array([mesh[v].point for v in el.vertices])
        if np.all(p[:, 0] == 0.0):
            names[el.index] = SYMMETRY_X
        elif np.all(p[:, 1] == 0.0):
            names[el.index] = SYMMETRY_Y
    if sorted(names.values()) != [SYMMETRY_X, SYMMETRY_Y]:
        raise InputError("mesh", "lateral faces x = 0 and y = 0 each on one boundary index", got=names)
    ngmesh = mesh.ngmesh
    for index, name in names.items():
        ngmesh.SetBCName(index, name)
    return Body(ngsolve.Mesh(ngmesh), body.interface)


def vector_space(mesh, k: int, supports=CLAMPED):
    """V_{h,i}: continuous vector Q_k / P_k with u_x, u_y, u_z = 0 on ``supports`` (x, y, z
    boundary regexps). Component j's dofs are j · (component ndof) + its own numbers."""
    if len(supports) != 3:
        raise InputError("supports", "three NGSolve boundary regexps (x, y, z)", got=supports)
    return ngsolve.VectorH1(mesh, order=k, dirichletx=supports[0], dirichlety=supports[1],
                            dirichletz=supports[2])


def offsets(fes) -> np.ndarray:
    """First product-space dof of each component (blocks x, y, z)."""
    return np.concatenate([[0], np.cumsum([c.ndof for c in fes.components])[:-1]])


def elastic_stiffness(fes, nu: float) -> sp.csr_matrix:
    """K = ∫ 2μ̂ ε(u):ε(v) + λ̂ div u div v at E = 1, on all dofs of ``fes``."""
    mu, lam = lame(nu)
    u, v = fes.TnT()
    a = ngsolve.BilinearForm(fes)
    a += (2.0 * mu * ngsolve.InnerProduct(ngsolve.Sym(ngsolve.Grad(u)), ngsolve.Sym(ngsolve.Grad(v)))
          + lam * ngsolve.div(u) * ngsolve.div(v)) * ngsolve.dx
    a.Assemble()
    mat = a.mat
    data, cols, rows = (np.array(arr, copy=True) for arr in mat.CSR())  # copies: NGSolve owns them
    return sp.csr_matrix((data, cols, rows), shape=(mat.height, mat.width))


def free_order(fes, gamma) -> tuple:
    """Free dofs ordered [interior, Γ x, Γ y, Γ z] (product numbering), the z component's
    :class:`~infsup_contact.discretization.gamma.interface.GammaTrace` on ``gamma`` (its dofs numbered
    in the component, as B_i sees them) and the number of tangential Γ dofs."""
    off = offsets(fes)
    traces = [gamma.trace(c) for c in fes.components]
    on_gamma = [t.gamma_dofs + o for t, o in zip(traces, off)]
    is_gamma = np.zeros(fes.ndof, dtype=bool)
    is_gamma[np.concatenate(on_gamma)] = True
    interior = np.flatnonzero(np.array(fes.FreeDofs(), dtype=bool) & ~is_gamma)
    return np.concatenate([interior, *on_gamma]), traces[2], len(on_gamma[0]) + len(on_gamma[1])


@dataclass(frozen=True)
class Elastic3DSide(SideOperator):
    """A :class:`SideOperator` of a 3D elastic body plus what its scenes need.

    Attributes (beyond SideOperator's)
    ----------
    fes : ngsolve.VectorH1
        The displacement space (``trace.fes`` is its z component).
    n_tangential : int
        Free Γ dofs of x and y (placed just before the z ones).
    stiffness_all : scipy.sparse.csr_matrix
        K on every dof (loads from prescribed displacements).
    nu : float
    """

    fes: object = None
    n_tangential: int = 0
    stiffness_all: sp.csr_matrix | None = None
    nu: float = 0.3


def side_operator(body: Body, k: int, nu: float = 0.3, supports=CLAMPED, route: str = "auto",
                  gamma=None, keep_factor: bool = False) -> Elastic3DSide:
    """One elastic body factorized once (E = 1), Γ dofs of x, y, z last, the z ones at the very
    end; its Γ Schur complement is that of the z dofs (module docstring). ``route`` as in
    :func:`~infsup_contact.la.schur.gamma_factorization`; ``body`` the mesh and its Γ
    (:func:`subdomain_mesh`), ``gamma`` another interface to take the trace on; ``keep_factor``: the
    factorization that gives S also serves the solves (a scene's side)."""
    nu = check_nu(nu)
    fes = vector_space(body.mesh, k, supports)
    free, trace, n_t = free_order(fes, body.interface if gamma is None else gamma)
    K_all = elastic_stiffness(fes, nu)
    base = factorized_side(trace, free, K_all[free][:, free].tocsc(), route, keep_factor)
    return Elastic3DSide(base.trace, base.free, base.stiffness, base.schur, base.solve, base.steklov,
                         fes=fes, n_tangential=n_t, stiffness_all=K_all, nu=nu)


def scene_side(scene, body: Body, k: int, nu: float = 0.3) -> Elastic3DSide:
    """The side of a contact scene: its ``supports`` (x, y, z regexps) where it has them, else
    clamped on ∂Ω_i∖Γ."""
    return side_operator(body, k, nu, getattr(scene, "supports", None) or CLAMPED, keep_factor=True)


def load(side: Elastic3DSide, scene, i: int):
    """(F_i, u_{D,i}): the lift prescribes u_z = ``scene.far_displacement[i]`` on the far face
    where u_z is a support (0 elsewhere), F_i = −E_i (K u_{D,i}) on the free dofs."""
    fes = side.fes
    gf = ngsolve.GridFunction(fes)
    gf.components[2].Set(float(scene.far_displacement[i]), definedon=fes.mesh.Boundaries(FAR))
    lift = gf.vec.FV().NumPy().copy()
    lift[np.array(fes.FreeDofs(), dtype=bool)] = 0.0  # only the supports carry the lift
    e = (scene.c1, scene.c2)[i]
    return -e * (side.stiffness_all @ lift)[side.free], lift


def field(side: Elastic3DSide, values: np.ndarray, lift=None):
    """u_{i,h} as a GridFunction of the vector space: ``values`` on the free dofs (order of
    ``side.free``), ``lift`` (or 0) elsewhere."""
    gf = ngsolve.GridFunction(side.fes)
    vec = np.zeros(side.fes.ndof) if lift is None else np.array(lift, dtype=float)
    vec[side.free] = values
    gf.vec.FV().NumPy()[:] = vec
    return gf


def interpolate(side: Elastic3DSide, components) -> np.ndarray:
    """Coefficients (all dofs) of the interpolant of (u_x, u_y, u_z) = ``components``."""
    gf = ngsolve.GridFunction(side.fes)
    gf.Set(ngsolve.CoefficientFunction(tuple(components)))
    return gf.vec.FV().NumPy().copy()


def elastic3d_model(nu: float = 0.3) -> Model:
    """The 3D elastic bodies with Poisson ratio ν (both), clamped on ∂Ω_i∖Γ for β_h."""
    nu = check_nu(nu)
    return Model("elastic3d", partial(side_operator, nu=nu),
                 f"two 3D linear-elastic bodies (0,1)^3 and (0,1)^2x(1,2), vector Q_k (hex) or P_k (tet), "
                 f"nu = {nu:g}, frictionless contact on the face Γ = (0,1)^2x{{1}} (--element)",
                 scene_side=partial(scene_side, nu=nu), load=load, field=field, interpolate=interpolate,
                 params=PARAMS, components=3, mesh=subdomain_mesh, mesh_options=(("element", ELEMENTS),),
                 families=FAMILIES_3D, dim=3, interface=face_gamma)


ELASTIC3D = elastic3d_model(0.3)
"""The 3D elastic model at ν = 0.3 (registered in ``MODELS``)."""
