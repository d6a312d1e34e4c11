"""Plane-strain linear elasticity through the model seam (the paper's Section 2 setting).

Two bodies Ω1 (below) and Ω2 (above) meet on the flat Γ = (0,1)×{1}, normal n = e_y
(pointing from Ω1 into Ω2). Displacements are vector continuous P_k, v = (v_x, v_y), and the
energy at unit Young's modulus is

    a(u, v) = ∫ 2 μ̂ ε(u):ε(v) + λ̂ div u div v,  μ̂ = 1/(2(1+ν)),  λ̂ = ν/((1+ν)(1−2ν)),

so that A_i = E_i K_i: the material scale c_i of the contract (:mod:`.contract`) is E_i and ν
belongs to the model instance (:func:`elastic_model`).

Frictionless contact: the multiplier is the normal pressure on Γ and
b(v, μ) = ∫_Γ (v2·n − v1·n) μ = ∫_Γ (v_{2,y} − v_{1,y}) μ, the membranes' b (eq. (3.5)) applied
to the normal components. **Sign**: A_1 u_1 = F_1 − B_1ᵀ λ and A_2 u_2 = F_2 + B_2ᵀ λ, so a
pressure λ ≥ 0 pushes Ω1 down and Ω2 up — the bodies apart — and λ = −σ_yy on Γ (compression
positive), as λ = −c ∂u/∂x_2 for the membranes.

The Γ-reduced engine needs X_i = (A_i⁻¹)_nn, the normal-normal block of the inverse on the Γ
dofs of both components. The free dofs are ordered [interior, Γ tangential, Γ normal]: with
both components of Γ last, the Schur complement onto the Γ normal dofs alone (eliminating the
tangential ones with the interior) is exactly ((A⁻¹)_ΓΓ)_nn⁻¹ — block elimination — so
:func:`~infsup_contact.models.contract.factorized_side` with the normal dofs as its Γ block gives
the interface operator unchanged (tested against the nn block of the full Γ Schur inverse).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
import ngsolve
import scipy.sparse as sp

from ..discretization.segment.meshes import DIRICHLET
from ..discretization.spaces.gammas import gamma_of
from .contract import PAPER_GAMMA, Body, MaterialParam, Model
from .plane_strain import E_RANGE, NU_RANGE, check_modulus, check_nu, lame  # noqa: F401 (the model's material law)
from .contract import SideOperator, factorized_side

@dataclass(frozen=True)
class ElasticSpace:
    """V_{h,i} = (continuous P_k)² as an NGSolve product space.

    Attributes
    ----------
    fes : ngsolve.FESpace
        The product space; component 0 (x) dofs first, then component 1 (y).
    fx, fy : ngsolve.H1
        The component spaces with their own Dirichlet boundaries.
    offset_y : int
        Product-space number of the first y dof (= fx.ndof).
    """

    fes: object
    fx: object
    fy: object
    offset_y: int


def elastic_space(mesh, k: int, x_dirichlet: str = "dir", y_dirichlet: str = "dir") -> ElasticSpace:
    """Vector P_k with v_x = 0 on ``x_dirichlet`` and v_y = 0 on ``y_dirichlet`` (NGSolve
    boundary-name regexps; clamped: both ``dir``)."""
    fx = ngsolve.H1(mesh, order=k, dirichlet=x_dirichlet)
    fy = ngsolve.H1(mesh, order=k, dirichlet=y_dirichlet)
    return ElasticSpace(ngsolve.FESpace([fx, fy]), fx, fy, fx.ndof)


def strain(u):
    """ε(u) as a 2×2 NGSolve coefficient matrix of a product-space (u_x, u_y)."""
    ux, uy = u
    gx, gy = ngsolve.grad(ux), ngsolve.grad(uy)
    exy = 0.5 * (gx[1] + gy[0])
    return ngsolve.CoefficientFunction((gx[0], exy, exy, gy[1]), dims=(2, 2))


def elastic_stiffness(space: ElasticSpace, nu: float) -> sp.csr_matrix:
    """K = ∫ 2μ̂ ε(u):ε(v) + λ̂ div u div v at E = 1, on all dofs of the product space."""
    mu, lam = lame(nu)
    u, v = space.fes.TnT()
    eu, ev = strain(u), strain(v)
    div_u = ngsolve.grad(u[0])[0] + ngsolve.grad(u[1])[1]
    div_v = ngsolve.grad(v[0])[0] + ngsolve.grad(v[1])[1]
    a = ngsolve.BilinearForm(space.fes)
    a += (2.0 * mu * ngsolve.InnerProduct(eu, ev) + lam * div_u * div_v) * ngsolve.dx
    a.Assemble()
    mat = a.mat
    data, cols, rows = (np.array(arr, copy=True) for arr in mat.CSR())  # copies: NGSolve owns them
    return sp.csr_matrix((data, cols, rows), shape=(mat.height, mat.width))


def gamma_dofs_both(space: ElasticSpace, gamma) -> tuple:
    """(tangential, normal) free Γ dofs in product-space numbering, each sorted by dof, on the
    interface ``gamma`` (:class:`~infsup_contact.discretization.gamma.interface.Interface`)."""
    tx = gamma.trace(space.fx).gamma_dofs
    ty = gamma.trace(space.fy).gamma_dofs + space.offset_y
    return tx, ty


def free_order(space: ElasticSpace, gamma) -> tuple:
    """Free product-space dofs ordered [interior, Γ tangential, Γ normal], and the normal
    component's :class:`GammaTrace` on ``gamma`` (its dofs numbered in ``space.fy``, as the
    coupling matrices B_i see them)."""
    trace = gamma.trace(space.fy)
    free_mask = np.concatenate([np.array(space.fx.FreeDofs(), dtype=bool),
                                np.array(space.fy.FreeDofs(), dtype=bool)])
    tx, ty = gamma_dofs_both(space, gamma)
    on_gamma = np.zeros(len(free_mask), dtype=bool)
    on_gamma[tx] = on_gamma[ty] = True
    free = np.concatenate([np.flatnonzero(free_mask & ~on_gamma), tx, ty])
    return free, trace, len(tx)


@dataclass(frozen=True)
class ElasticSide(SideOperator):
    """A :class:`SideOperator` of an elastic body plus what the elastic scenes need.

    Attributes (beyond SideOperator's)
    ----------
    space : ElasticSpace
        The product space (``trace.fes`` is its normal component only).
    n_tangential : int
        Number of free tangential Γ dofs (placed just before the normal ones).
    stiffness_all : scipy.sparse.csr_matrix
        K on every product-space dof (for loads from prescribed displacements).
    nu : float
    """

    space: ElasticSpace | None = None
    n_tangential: int = 0
    stiffness_all: sp.csr_matrix | None = None
    nu: float = 0.3

    def grid_function(self, values_free: np.ndarray, dirichlet: np.ndarray | None = None):
        """u_h as an NGSolve GridFunction of the product space: ``values_free`` on the free
        dofs (order of ``free``), ``dirichlet`` (all dofs, optional) elsewhere."""
        gf = ngsolve.GridFunction(self.space.fes)
        vec = np.zeros(self.space.fes.ndof) if dirichlet is None else np.array(dirichlet, dtype=float)
        vec[self.free] = values_free
        gf.vec.FV().NumPy()[:] = vec
        return gf


def side_operator(mesh, k: int, nu: float = 0.3, x_dirichlet: str = "dir", y_dirichlet: str = "dir",
                  route: str = "auto") -> ElasticSide:
    """One elastic body factorized once (E = 1), Γ dofs of both components last, the normal
    ones at the very end; its Γ Schur complement is that of the normal dofs (see the module
    docstring), ``route`` as in :func:`~infsup_contact.la.schur.gamma_factorization`. ``mesh``: a
    :class:`~.contract.Body` (its mesh and Γ), or a bare mesh of the paper's (Γ: :data:`PAPER_GAMMA`)."""
    nu = check_nu(nu)
    mesh, gamma = (mesh.mesh, mesh.interface) if isinstance(mesh, Body) else (mesh, gamma_of(PAPER_GAMMA))
    space = elastic_space(mesh, k, x_dirichlet, y_dirichlet)
    free, trace, n_t = free_order(space, gamma)
    K_all = elastic_stiffness(space, nu)
    base = factorized_side(trace, free, K_all[free][:, free].tocsc(), route)
    return ElasticSide(base.trace, base.free, base.stiffness, base.schur, base.solve, base.steklov,
                       space=space, n_tangential=n_t, stiffness_all=K_all, nu=nu)


def scene_side(scene, mesh, k: int, nu: float = 0.3, x_dirichlet: str = "dir",
               y_dirichlet: str = "dir") -> ElasticSide:
    """The side of a contact scene: the scene's ``supports`` (x, y Dirichlet boundaries) where it
    has them (the patch test's rollers), else the model's."""
    x_dirichlet, y_dirichlet = getattr(scene, "supports", None) or (x_dirichlet, y_dirichlet)
    return side_operator(mesh, k, nu, x_dirichlet, y_dirichlet)


def load(side: ElasticSide, scene, i: int):
    """(F_i, u_{D,i}): the lift u_{D,i} prescribes u_y = ``scene.far_displacement_y[i]`` on the
    far face (boundary ``dir``), so F_i = −E_i (K u_{D,i}) on the free dofs (no body force)."""
    mesh = side.space.fes.mesh
    gf = ngsolve.GridFunction(side.space.fes)
    gf.components[1].Set(scene.far_displacement_y[i], definedon=mesh.Boundaries(DIRICHLET))
    lift = gf.vec.FV().NumPy().copy()
    e = (scene.c1, scene.c2)[i]
    return -e * (side.stiffness_all @ lift)[side.free], lift


def field(side: ElasticSide, values: np.ndarray, lift=None):
    """u_{i,h} as a GridFunction of the product space (:meth:`ElasticSide.grid_function`)."""
    return side.grid_function(values, lift)


def interpolate_on(side: ElasticSide, components) -> np.ndarray:
    """Coefficients (all dofs) of the interpolant of (u_x, u_y) = ``components``."""
    return interpolate(side.space, *components)


def elastic_model(nu: float = 0.3, x_dirichlet: str = "dir", y_dirichlet: str = "dir") -> Model:
    """The plane-strain model with Poisson ratio ν (both bodies), clamped on ∂Ω_i∖Γ by
    default (the paper's geometry, where the H^{-1/2}_00(Γ) norm applies as is)."""
    nu = check_nu(nu)
    bc = dict(nu=nu, x_dirichlet=x_dirichlet, y_dirichlet=y_dirichlet)
    return Model("elastic", partial(side_operator, **bc),
                 f"two plane-strain elastic bodies, vector P_k, nu = {nu:g}, frictionless normal contact",
                 scene_side=partial(scene_side, **bc), load=load, field=field, interpolate=interpolate_on,
                 params=PARAMS, components=2)


PARAMS = (MaterialParam("nu", 0.3, check_nu, "-1 < nu < 0.5", "Poisson ratio of both bodies"),
          MaterialParam("E1", 1.0, check_modulus, "1e-150 <= E <= 1e150", "Young's modulus of Ω1", side=0),
          MaterialParam("E2", 1.0, check_modulus, "1e-150 <= E <= 1e150", "Young's modulus of Ω2", side=1))
"""The elastic bodies' material flags: ν builds the model (K_i), E_i is the scale c_i of side i."""


ELASTIC = elastic_model(0.3)
"""The elastic model at ν = 0.3, clamped on ∂Ω_i∖Γ (registered in ``MODELS``)."""


def interpolate(space: ElasticSpace, ux, uy) -> np.ndarray:
    """Product-space coefficient vector of the interpolant of (ux, uy) (NGSolve coefficients)."""
    gf = ngsolve.GridFunction(space.fes)
    gf.components[0].Set(ux)
    gf.components[1].Set(uy)
    return gf.vec.FV().NumPy().copy()

