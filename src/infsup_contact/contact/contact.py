"""The discrete contact problem (4.1) on a mesh pair, solved on Γ and recovered in Ω, for
every model and scene.

With b(v, μ) = μᵀ(B_2 v_2 − B_1 v_1), the first line of (4.1) reads
A_1 u_1 = F_1 − B_1ᵀ λ and A_2 u_2 = F_2 + B_2ᵀ λ, so the weighted gaps are
g = G + B_2 u_2 − B_1 u_1 = G + g_F + K λ with g_F = B A⁻¹ F, G_j = ∫_Γ μ_j g0 the scene's
initial gap (if any) and K = Σ_i B_i X_i B_iᵀ, the interface operator already computed for
β_h. The active-set iteration works on (K, G + g_F) only; u_h is recovered by one solve per
side with the factorization that produced X_i (:func:`solve_on_gamma`).

What differs between models — the sides of a scene, the loads F_i and Dirichlet lifts, the
field u_h is recovered into — comes from the model (:mod:`infsup_contact.models.contract`);
what differs between scenes — meshes, material scales c_i, data, initial gap — from the scene.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import ngsolve
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..discretization.segment import meshes, multipliers
from ..discretization.spaces import registry
from ..errors import InputError
from .pdas import PdasResult, solve_pdas
from ..discretization.gamma.coupling import coupling_matrix
from ..models import DEFAULT_MODEL
from ..models.contract import B_SIGN
from ..solvers.interface_operator import interface_operator
from ..solvers.request import NO_OPTIONS, MeshOptions

FLAT_GAMMAS = (None, "segment", "square")
"""The Γ options of the flat interfaces (unset, the segment, the face), the only ones of the contact scenes."""


@dataclass
class ContactSolution:
    """A solved instance of (4.1).

    Attributes
    ----------
    space : SegmentSpace
        M_h; ``lam`` are its dof values (nodal, so the cone is lam >= 0).
    sides : list of SideOperator
    u : list of ngsolve.GridFunction
        u_{1,h}, u_{2,h} (Dirichlet lifts included), as the model's ``field`` makes them.
    lam : ndarray
    pdas : PdasResult
    c : tuple
        Material scales (c1, c2) (E1, E2 for elastic bodies).
    K : ndarray
        The interface operator Σ_i B_i X_i B_iᵀ / c_i.
    t_solve : float
        Interface operator + active set + recovery, seconds.
    t_linear_solve : float
        One sparse direct solve of the linear saddle-point system with the contact set
        known (:func:`linear_saddle_solve`, the floor a contact solve is compared with),
        seconds.
    """

    space: multipliers.SegmentSpace
    sides: list
    u: list
    lam: np.ndarray
    pdas: PdasResult
    c: tuple
    K: np.ndarray
    t_solve: float = float("nan")
    t_linear_solve: float = float("nan")

    @property
    def ndof(self) -> int:
        return sum(s.ndof for s in self.sides) + self.space.dim

    @property
    def gamma(self):
        """Γ, the interface of the sides (:mod:`infsup_contact.discretization.gamma.interface`)."""
        return self.sides[0].trace.gamma

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """λ_h(x)."""
        return self.space.evaluate(x) @ self.lam

    def resultant(self) -> float:
        """P = ∫_Γ λ_h (exact Gauss on G_h)."""
        x, w = self.gamma.quadrature(self.space.breakpoints, self.space.degree + 1)
        return float(w @ self.pressure(x))


def contact_qp(sides, Bs, F, c=(1.0, 1.0)):
    """Assemble (A, B, F) of the contact QP from the two sides of a contact problem.

    Parameters
    ----------
    sides : sequence of two objects with ``stiffness`` (csc, free dofs, Γ last) and
        ``trace.gamma_dofs`` — :class:`~infsup_contact.models.contract.SideOperator`.
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


def weighted_gap(gamma, space, g0, degree: int) -> np.ndarray:
    """G_j = ∫_Γ μ_j g0 by the quadrature of Γ (``gamma``) exact for g0 polynomial of ``degree``."""
    x, w = gamma.quadrature(gamma.common_refinement(space.breakpoints), space.degree + degree)
    return (space.evaluate(x) * w[:, None]).T @ g0(x)


@dataclass
class ContactPair:
    """What a contact solve on one mesh pair needs before the multiplier space is chosen:
    the factorized sides, the loads F_i, the lifts and the unconstrained displacements
    u0_i = A_i⁻¹F_i.

    Every multiplier case on the pair shares it (:func:`solve_contact_on`); building it
    is most of a solve's cost on the finer meshes, and none of it depends on M_h.

    Attributes
    ----------
    meshes : tuple of ngsolve.Mesh or Body
        What the model's ``side_operator`` takes (a 3D model's builder returns a Body: mesh and Γ).
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
    model : Model
        Who made the sides and recovers u_h.
    lifts : list
        Dirichlet lifts u_{D,i} on all dofs (None: homogeneous).
    gap : callable or None
        The scene's initial gap g0(x) on Γ, polynomial of degree ``gap_degree``.
    gap_degree : int
    """

    meshes: tuple
    sides: list
    F: list
    u0: list
    c: tuple
    k: int
    seconds: float
    model: object = None
    lifts: list = None
    gap: object = None
    gap_degree: int = 0


def check_flat_gamma(flags=None, gamma=None) -> None:
    """:class:`InputError` naming the key unless Γ is flat: contact scenes are built on the segment
    and the face only (β_h and the verdicts take the arc and the cylinder). ``flags``: the command
    line's (``gamma``, ``radius``, ``coupling``, before Γ is resolved); ``gamma``: a request's
    resolved Γ (an Interface; None: the model's flat one)."""
    if gamma is not None:  # a resolved Γ: the curved shapes have a radius
        gamma = type(gamma).__name__.lower() if hasattr(gamma, "radius") else None
    else:
        gamma = getattr(flags, "gamma", None)
    if gamma not in FLAT_GAMMAS:
        raise InputError("gamma", f"{', '.join(FLAT_GAMMAS[1:])} (contact scenes on the arc and the cylinder are "
                         "not built: beta and verdict take --gamma arc, cylinder)", got=gamma)
    for key in ("radius", "coupling"):
        if getattr(flags, key, None) is not None:
            raise InputError(key, "unset (contact scenes: a flat Γ; beta and verdict take --gamma arc, cylinder)",
                             got=getattr(flags, key))


def contact_pair(scene, k: int, family: str, n1: int, n2: int, model=None,
                 mesh: MeshOptions = NO_OPTIONS, gamma=None) -> ContactPair:
    """Mesh, factorize and load both sides of ``scene`` with ``model`` (default: the registry's,
    the paper's membranes; see :class:`ContactPair`); the scene's ``mesh_pair`` where it has
    one (structured blocks of the elastic scenes), else the model's mesh builder where it has
    one (``Model.mesh``: the 3D bodies, ``mesh`` options such as ``element``), else the family's.
    The builders take the options as keywords (the model contract); ``gamma``, the request's Γ,
    must be flat (None; :func:`check_flat_gamma`)."""
    model = DEFAULT_MODEL if model is None else model
    build = getattr(scene, "mesh_pair", None)
    kw = mesh.kwargs()
    check_flat_gamma(gamma=gamma)  # flat: the builders' own Γ
    if build is not None:
        mesh_pair = build(family, n1, n2, **kw)
    elif model.mesh is not None:
        mesh_pair = tuple(model.subdomain_mesh(family, n, side, **kw) for n, side in ((n1, 1), (n2, 2)))
    else:
        mesh_pair = meshes.mesh_pair(family, n1, n2, **kw)
    c = (scene.c1, scene.c2)
    t0 = time.perf_counter()
    sides = [model.side_for(scene, m, k) for m in mesh_pair]
    sides = sides[0].trace.gamma.paired(sides)  # a Γ coupled by projection ties the two
    F, lifts = zip(*(model.load(s, scene, i) for i, s in enumerate(sides)))
    u0 = [s.solve(Fi) / ci for s, Fi, ci in zip(sides, F, c)]
    return ContactPair(tuple(mesh_pair), sides, list(F), u0, c, k, time.perf_counter() - t0, model,
                       list(lifts), getattr(scene, "initial_gap", None), getattr(scene, "initial_gap_degree", 0))


def solve_on_gamma(pair: ContactPair, space, time_floor: bool = False) -> ContactSolution:
    """Solve (4.1) on a built pair with the multiplier space ``space``: B_i, K, the gaps, PDAS
    and the recovery of u_h by the model — the one Γ solve of every model and scene."""
    t0 = time.perf_counter()
    sides, c, F = pair.sides, pair.c, pair.F
    Bs = [coupling_matrix(s.trace, space, pair.k) for s in sides]
    K = interface_operator(Bs, sides, c)
    ng = [B.shape[1] for B in Bs]
    g0 = Bs[1] @ pair.u0[1][-ng[1]:] - Bs[0] @ pair.u0[0][-ng[0]:]
    if pair.gap is not None:
        g0 = weighted_gap(sides[0].trace.gamma, space, pair.gap, pair.gap_degree) + g0
    pdas = solve_pdas(K, g0)
    lifts = pair.lifts or [None] * len(sides)
    u = []
    for sign, s, Fi, B, ci, lift in zip(B_SIGN, sides, F, Bs, c, lifts):
        rhs = Fi.copy()
        rhs[s.ndof - B.shape[1]:] += sign * (B.T @ pdas.lam)  # Γ dofs are the last block
        u.append(pair.model.field(s, s.solve(rhs) / ci, lift))
    t_solve = pair.seconds + time.perf_counter() - t0
    t_floor = linear_saddle_time(sides, Bs, c, F, pdas.active) if time_floor else float("nan")
    return ContactSolution(space, sides, u, pdas.lam, pdas, c, K, t_solve, t_floor)


def solve_contact_on(pair: ContactPair, case: str, multiplier_mesh: str = "omega2",
                     time_floor: bool = True) -> ContactSolution:
    """Solve (4.1) on a built pair with the multipliers of ``case`` (a registry id) on the
    multiplier mesh ``multiplier_mesh``.

    ``t_solve`` of the result is the pair's build time plus this call's: the cost of one
    solve from meshes to u_h, whether or not the pair was shared.
    """
    registry.check_case(case, pair.k)
    t0 = time.perf_counter()
    gamma = pair.sides[0].trace.gamma
    space = registry.case_space(case, pair.k, gamma.multiplier_partition(*(s.trace.partition for s in pair.sides),
                                                                         multiplier_mesh), gamma)
    t_space = time.perf_counter() - t0
    sol = solve_on_gamma(pair, space, time_floor)
    sol.t_solve += t_space  # building M_h is part of this case's solve
    return sol


def solve_contact(scene, case: str, k: int, family: str, n1: int, n2: int,
                  multiplier_mesh: str = "omega2", time_floor: bool = True, model=None,
                  mesh: MeshOptions = NO_OPTIONS) -> ContactSolution:
    """Solve (4.1) for a scene (``scenes.scene``) with the multipliers of ``case`` (a registry
    id); ``model`` gives the side operators, loads and u_h (:mod:`infsup_contact.models.contract`)."""
    registry.check_case(case, k)
    pair = contact_pair(scene, k, family, n1, n2, model=model, mesh=mesh)
    return solve_contact_on(pair, case, multiplier_mesh, time_floor)


def gamma_values(sol: ContactSolution, x: np.ndarray):
    """u_{1,h}, u_{2,h} on Γ at points x of Γ (its interior), via point evaluation: one value
    per point (shape ``x.shape`` on the segment, ``x.shape[:-1]`` on a face, ``gamma.dim`` = 2)."""
    x = np.asarray(x, dtype=float)
    out = []
    where = sol.gamma.embed(x)
    shape = x.shape if sol.gamma.dim == 1 else x.shape[:-1]
    for gf, side in zip(sol.u, sol.sides):
        mesh = side.trace.fes.mesh
        out.append(np.asarray(gf(mesh(*where))).reshape(shape))
    return out


def lambda_values(sol: ContactSolution, x: np.ndarray) -> np.ndarray:
    """λ_h(x); ``sol`` may be a saved reference (space and lam only, study.contact.rows)."""
    return sol.space.evaluate(x) @ sol.lam
