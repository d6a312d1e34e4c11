"""The discrete contact problem (4.1) on a mesh pair, solved on Γ and recovered in Ω.

With b(v, μ) = μᵀ(B_2 v_2 − B_1 v_1), the first line of (4.1) reads
A_1 u_1 = F_1 − B_1ᵀ λ and A_2 u_2 = F_2 + B_2ᵀ λ, so the weighted gaps are
g = B_2 u_2 − B_1 u_1 = g0 + K λ with g0 = B A⁻¹ F and K = Σ_i B_i X_i B_iᵀ, the interface
operator already computed for β_h. The active-set iteration works on (K, g0) only;
u_h is recovered by one solve per side with the factorization that produced X_i.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import ngsolve
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..discretization import meshes, multipliers, registry
from .pdas import PdasResult, solve_pdas
from ..discretization.coupling import coupling_matrix
from ..models.schur import SideOperator, interface_operator
from ..models.membranes import MEMBRANES


@dataclass
class ContactSolution:
    """A solved instance of (4.1).

    Attributes
    ----------
    space : MultiplierSpace
        M_h; ``lam`` are its dof values (nodal, so the cone is lam >= 0).
    sides : list of SideOperator
    u : list of ngsolve.GridFunction
        u_{1,h}, u_{2,h}.
    lam : ndarray
    pdas : PdasResult
    t_solve : float
        Interface operator + active set + recovery, seconds.
    t_linear_solve : float
        One sparse direct solve of the linear saddle-point system with the contact set
        known (:func:`linear_saddle_solve`, the floor a contact solve is compared with),
        seconds.
    """

    space: multipliers.MultiplierSpace
    sides: list
    u: list
    lam: np.ndarray
    pdas: PdasResult
    c: tuple
    t_solve: float
    t_linear_solve: float

    @property
    def ndof(self) -> int:
        return sum(s.ndof for s in self.sides) + self.space.dim


def load_vector(side: SideOperator, f) -> np.ndarray:
    """F_i = ∫ f v on the free dofs of side i, in the order of ``side.free``."""
    fes = side.trace.fes
    lf = ngsolve.LinearForm(fes)
    lf += f * fes.TestFunction() * ngsolve.dx(bonus_intorder=4)
    lf.Assemble()
    return lf.vec.FV().NumPy()[side.free].copy()


def load_vector_from_exact(side: SideOperator, grad_u, c: float, normal_y: float) -> np.ndarray:
    """F_i = (f_i, v) for f_i = −c_i Δu_i, evaluated as c_i(∇u_i, ∇v) − ∫_Γ c_i ∂u_i/∂n v.

    Green's formula makes this identical to ∫ f v for every v ∈ V_h (v = 0 on ∂Ω_i∖Γ). For
    the low-regularity manufactured solutions f has an integrable singularity at x = a
    that quadrature samples badly, while ∇u is bounded: this form keeps F exact to
    quadrature accuracy. ``normal_y`` is the outward normal's y component on Γ (+1 for
    Ω1, −1 for Ω2), given explicitly rather than taken from the mesh.
    """
    fes = side.trace.fes
    v = fes.TestFunction()
    lf = ngsolve.LinearForm(fes)
    lf += c * grad_u * ngsolve.grad(v) * ngsolve.dx(bonus_intorder=6)
    lf += -c * normal_y * grad_u[1] * v * ngsolve.ds("gamma", bonus_intorder=6)
    lf.Assemble()
    return lf.vec.FV().NumPy()[side.free].copy()


def load_vectors(sides, scene) -> list:
    """Load vectors of both sides; from the exact solution where the scene has one."""
    if getattr(scene, "has_exact", False):
        return [load_vector_from_exact(s, g, c, ny) for s, g, c, ny in
                zip(sides, (scene.grad_u1, scene.grad_u2), (scene.c1, scene.c2), (1.0, -1.0))]
    return [load_vector(s, f) for s, f in zip(sides, (scene.f1, scene.f2))]


def contact_qp(sides, Bs, F, c=(1.0, 1.0)):
    """Assemble (A, B, F) of the contact QP from the two sides of a contact problem.

    Parameters
    ----------
    sides : sequence of two objects with ``stiffness`` (csc, free dofs, Γ last) and
        ``trace.gamma_dofs`` — :class:`~infsup_contact.interface.SideOperator`.
    Bs : two dense (m, n_Γ,i) coupling matrices B1, B2.
    F : two load vectors on the free dofs.
    c : (c1, c2).

    Returns
    -------
    A : csc_matrix (n, n)
    B : csr_matrix (m, n) = [−B1, B2] embedded
    F : ndarray (n,)
    """
    A = sp.block_diag([ci * s.stiffness for s, ci in zip(sides, c)], format="csc")
    blocks = []
    for sign, s, Bi in zip((-1.0, 1.0), sides, Bs):
        ng = Bi.shape[1]
        zero = sp.csr_matrix((Bi.shape[0], s.stiffness.shape[0] - ng))
        blocks += [zero, sp.csr_matrix(sign * np.asarray(Bi))]
    B = sp.hstack(blocks, format="csr")
    B.eliminate_zeros()
    return A, B, np.concatenate([np.asarray(f, dtype=float) for f in F])


def linear_saddle_solve(A, B, F, active=None, refine: int = 2):
    """One sparse direct solve of (4.1) with the contact set 𝒜 known (a linear system).

    [[A, B_𝒜ᵀ], [B_𝒜, −εI]] [u; −λ_𝒜] = [F; 0], ε = 1e-12 · max|A|: the floor of any contact
    solve. The matrix is symmetric quasi-definite, hence factorizable without pivoting in
    any symmetric order (Vanderbei, SIAM J. Optim. 5 (1995)); SuperLU in its best symmetric
    order (``MMD_AT_PLUS_A``, symmetric mode, no pivoting). ε keeps the unstable pairs
    (dependent rows of B_𝒜) factorizable at the same cost; ``refine`` steps of iterative
    refinement against the system with ε = 0 remove its O(ε) effect and the growth of
    the unpivoted factorization (as SuperLU's expert driver refines).

    Parameters
    ----------
    A : (n, n) sparse SPD
    B : (m, n) sparse
    F : (n,) array_like
    active : (m,) bool, optional
        The contact set (default: every multiplier).
    refine : int
        Iterative refinement steps.

    Returns
    -------
    u : ndarray (n,)
    lam : ndarray (m,), zero off 𝒜
    """
    B = sp.csr_matrix(B)
    active = np.ones(B.shape[0], dtype=bool) if active is None else np.asarray(active, dtype=bool)
    Ba = B[active]
    n, m = A.shape[0], Ba.shape[0]
    exact = sp.bmat([[A, Ba.T], [Ba, sp.csr_matrix((m, m))]], format="csc")
    eps = 1e-12 * abs(A).max()
    kkt = (exact - sp.diags(np.r_[np.zeros(n), np.full(m, eps)])).tocsc()
    lu = spla.splu(kkt, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options=dict(SymmetricMode=True))
    rhs = np.concatenate([F, np.zeros(m)])
    sol = lu.solve(rhs)
    for _ in range(refine):  # against ε and the growth of an unpivoted factorization
        sol += lu.solve(rhs - exact @ sol)
    lam = np.zeros(B.shape[0])
    lam[active] = -sol[n:]
    return sol[:n], lam


def linear_saddle_time(sides, Bs, c, F, active) -> float:
    """Seconds of :func:`linear_saddle_solve` on the assembled problem of ``sides``
    (loads ``F`` per side, contact set ``active``)."""
    A, B, Fv = contact_qp(sides, Bs, F, c)
    t = time.perf_counter()
    linear_saddle_solve(A, B, Fv, active)
    return time.perf_counter() - t


@dataclass
class ContactPair:
    """What a contact solve on one mesh pair needs before the multiplier space is chosen:
    the factorized sides, the loads F_i and the unconstrained displacements u0_i = A_i⁻¹F_i.

    Every multiplier case on the pair shares it (:func:`solve_contact_on`); building it
    is most of a solve's cost on the finer meshes, and none of it depends on M_h.

    Attributes
    ----------
    meshes : tuple of ngsolve.Mesh
    sides : list of SideOperator
    F : list of ndarray
        Loads on the free dofs of each side.
    u0 : list of ndarray
        A_i⁻¹ F_i / c_i.
    c : tuple
        (c1, c2).
    k : int
        Displacement degree.
    seconds : float
        Wall time of the build (sides, loads, u0), counted in every solve on the pair.
    """

    meshes: tuple
    sides: list
    F: list
    u0: list
    c: tuple
    k: int
    seconds: float


def contact_pair(scene, k: int, family: str, n1: int, n2: int, model=MEMBRANES,
                 **mesh_kwargs) -> ContactPair:
    """Mesh, factorize and load both sides of ``scene`` (see :class:`ContactPair`)."""
    mesh_pair = meshes.mesh_pair(family, n1, n2, **mesh_kwargs)
    c = (scene.c1, scene.c2)
    t0 = time.perf_counter()
    sides = [model.side_operator(m, k) for m in mesh_pair]
    F = load_vectors(sides, scene)
    u0 = [s.solve(Fi) / ci for s, Fi, ci in zip(sides, F, c)]
    return ContactPair(tuple(mesh_pair), sides, F, u0, c, k, time.perf_counter() - t0)


def solve_contact_on(pair: ContactPair, case: str, multiplier_mesh: str = "omega2",
                     time_floor: bool = True) -> ContactSolution:
    """Solve (4.1) on a built pair with the multipliers of ``case`` (a registry id).

    ``t_solve`` of the result is the pair's build time plus this call's: the cost of one
    solve from meshes to u_h, whether or not the pair was shared.
    """
    registry.check_case(case, pair.k)
    t0 = time.perf_counter()
    sides, c, F, k = pair.sides, pair.c, pair.F, pair.k
    space = registry.case_space(case, k, meshes.multiplier_breakpoints(*pair.meshes, multiplier_mesh))
    Bs = [coupling_matrix(s.trace, space, k) for s in sides]
    K = interface_operator(Bs, sides, c)
    ng = [B.shape[1] for B in Bs]
    g0 = Bs[1] @ pair.u0[1][-ng[1]:] - Bs[0] @ pair.u0[0][-ng[0]:]
    pdas = solve_pdas(K, g0)
    u = []
    for sign, s, Fi, B, ci in zip((-1.0, 1.0), sides, F, Bs, c):
        rhs = Fi.copy()
        rhs[s.ndof - B.shape[1]:] += sign * (B.T @ pdas.lam)  # Γ dofs are the last block
        gf = ngsolve.GridFunction(s.trace.fes)
        gf.vec.FV().NumPy()[s.free] = s.solve(rhs) / ci
        u.append(gf)
    t_solve = pair.seconds + time.perf_counter() - t0
    t_floor = linear_saddle_time(sides, Bs, c, F, pdas.active) if time_floor else float("nan")
    return ContactSolution(space, sides, u, pdas.lam, pdas, c, t_solve, t_floor)


def solve_contact(scene, case: str, k: int, family: str, n1: int, n2: int,
                  multiplier_mesh: str = "omega2", time_floor: bool = True, model=MEMBRANES,
                  **mesh_kwargs) -> ContactSolution:
    """Solve (4.1) for a scene (``scenes.scene``) with the multipliers of ``case`` (a registry
    id); ``model`` gives the side operators (:mod:`infsup_contact.models.contract`)."""
    registry.check_case(case, k)
    pair = contact_pair(scene, k, family, n1, n2, model=model, **mesh_kwargs)
    return solve_contact_on(pair, case, multiplier_mesh, time_floor)


def gamma_values(sol: ContactSolution, x: np.ndarray):
    """u_{1,h}, u_{2,h} on Γ at abscissae x (interior of Γ), via point evaluation."""
    x = np.asarray(x, dtype=float)
    out = []
    for gf, side in zip(sol.u, sol.sides):
        mesh = side.trace.fes.mesh
        out.append(np.asarray(gf(mesh(x, np.ones_like(x)))).reshape(x.shape))
    return out


def lambda_values(sol: ContactSolution, x: np.ndarray) -> np.ndarray:
    """λ_h(x)."""
    return sol.space.evaluate(x) @ sol.lam
