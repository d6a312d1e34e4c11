"""Frictionless contact (4.1) of two plane-strain bodies with prescribed far-face displacements
and an initial gap g0 on Γ — the solve shared by the patch test and the Hertz scene.

With A_i = E_i K_i (:mod:`infsup_contact.models.elastic`), Dirichlet lifts u_{D,i} (loads
F_i = −A_i u_{D,i} on the free dofs) and the weighted initial gap G_j = ∫_Γ μ_j g0, the
Γ-reduced LCP is g = G + B_2 u_2 − B_1 u_1 = G + g_F + K λ, λ ≥ 0, g ≥ 0, λ∘g = 0, with
K = Σ_i B_i X_i B_iᵀ / E_i the interface operator of β_h; u_i is recovered by one solve per
body with the factorization that produced X_i. Sign: a pressure λ ≥ 0 pushes Ω1 down and Ω2
up (:mod:`infsup_contact.models.elastic`).
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve
import numpy as np

from ..discretization import meshes, registry
from ..discretization.coupling import coupling_matrix, quadrature_on, union_breakpoints
from ..models.elastic import side_operator
from ..models.schur import interface_operator
from ..solvers.pdas import PdasResult, solve_pdas


@dataclass
class ElasticContact:
    """A solved elastic contact problem.

    Attributes
    ----------
    sides : list of ElasticSide
    space : MultiplierSpace
    lam : ndarray
        Multiplier dofs.
    u : list of ndarray
        Product-space coefficient vectors of u_{1,h}, u_{2,h} (Dirichlet values included).
    pdas : PdasResult
    E : tuple
    K : ndarray
        The interface operator Σ_i B_i X_i B_iᵀ / E_i.
    """

    sides: list
    space: object
    lam: np.ndarray
    u: list
    pdas: PdasResult
    E: tuple
    K: np.ndarray

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """λ_h(x)."""
        return self.space.evaluate(x) @ self.lam

    def grid_functions(self) -> list:
        out = []
        for s, vec in zip(self.sides, self.u):
            gf = ngsolve.GridFunction(s.space.fes)
            gf.vec.FV().NumPy()[:] = vec
            out.append(gf)
        return out

    def resultant(self) -> float:
        """P = ∫_Γ λ_h (exact Gauss on G_h)."""
        x, w = quadrature_on(self.space.breakpoints, self.space.degree + 1)
        return float(w @ self.pressure(x))


def weighted_gap(space, g0, degree: int) -> np.ndarray:
    """G_j = ∫_Γ μ_j g0 by Gauss–Legendre exact for g0 polynomial of ``degree``."""
    x, w = quadrature_on(union_breakpoints(space.breakpoints), space.degree + degree)
    return (space.evaluate(x) * w[:, None]).T @ g0(x)


@dataclass
class ElasticPair:
    """Two factorized bodies with their Dirichlet lifts: everything of a solve that does not
    depend on the multiplier space, built once and shared by every case on the pair.

    Attributes
    ----------
    meshes : tuple
        (mesh1, mesh2).
    k : int
    E : tuple
    sides : list of ElasticSide
        One factorization per body, Γ last (:func:`~infsup_contact.models.elastic.side_operator`).
    lifts, F, u0 : lists of ndarray
        Dirichlet lifts u_{D,i}, loads F_i = −A_i u_{D,i} on the free dofs, and A_i⁻¹ F_i.
    """

    meshes: tuple
    k: int
    E: tuple
    sides: list
    lifts: list
    F: list
    u0: list


def elastic_pair(mesh1, mesh2, k: int, nu: float, E, x_dirichlet: str, y_dirichlet: str,
                 top_displacement: float) -> ElasticPair:
    """Factorize both bodies and apply the far-face data: u = 0 on Ω1's ``dir`` boundary,
    u_y = −``top_displacement`` (u_x = 0 where x is Dirichlet) on Ω2's ``dir`` boundary."""
    sides = [side_operator(m, k, nu, x_dirichlet, y_dirichlet) for m in (mesh1, mesh2)]
    lifts = []
    for s, mesh, value in zip(sides, (mesh1, mesh2), (0.0, -top_displacement)):
        gf = ngsolve.GridFunction(s.space.fes)
        gf.components[1].Set(value, definedon=mesh.Boundaries(meshes.DIRICHLET))
        lifts.append(gf.vec.FV().NumPy().copy())
    F = [-e * (s.stiffness_all @ L)[s.free] for s, L, e in zip(sides, lifts, E)]
    u0 = [s.solve(Fi) / e for s, Fi, e in zip(sides, F, E)]
    return ElasticPair((mesh1, mesh2), k, tuple(E), sides, lifts, F, u0)


def solve_elastic_contact(pair: ElasticPair, case: str, g0=None, g0_degree: int = 2) -> ElasticContact:
    """Solve (4.1) on ``pair`` with multipliers of ``case`` on G_h = trace of Ω2 and the initial
    gap ``g0(x)`` (polynomial of ``g0_degree``; None: no gap)."""
    sides, E = pair.sides, pair.E
    space = registry.case_space(case, pair.k, meshes.multiplier_breakpoints(*pair.meshes, "omega2"))
    Bs = [coupling_matrix(s.trace, space, pair.k) for s in sides]
    K = interface_operator(Bs, sides, E)
    ng = [B.shape[1] for B in Bs]
    gF = Bs[1] @ pair.u0[1][-ng[1]:] - Bs[0] @ pair.u0[0][-ng[0]:]
    G = np.zeros(space.dim) if g0 is None else weighted_gap(space, g0, g0_degree)
    res = solve_pdas(K, G + gF)
    u = []
    for sign, s, Fi, B, e, L in zip((-1.0, 1.0), sides, pair.F, Bs, E, pair.lifts):
        rhs = Fi.copy()
        rhs[s.ndof - B.shape[1]:] += sign * (B.T @ res.lam)
        vec = L.copy()
        vec[s.free] = s.solve(rhs) / e
        u.append(vec)
    return ElasticContact(sides, space, res.lam, u, res, E, K)
