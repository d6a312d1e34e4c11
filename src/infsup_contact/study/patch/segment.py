"""The contact patch test of the plane-strain elastic pair.

Two blocks Ω1 = (0,1)² and Ω2 = (0,1)×(1,2) on non-matching structured meshes (N1 ≠ N2
segments on Γ), lateral sides x = 0, 1 on rollers (u_x = 0, free to slide vertically), the
bottom of Ω1 fixed and the top of Ω2 moved down by δ (u = (0, −δ)): Ω2 is held by contact
only, and a prescribed displacement keeps K_2 invertible where a top pressure would leave a
floating body. The exact solution is a uniform compression, σ_yy = −p in both blocks, u_x = 0,

    u_{1,y} = −p y / M_1,   u_{2,y} = −p / M_1 − p (y − 1) / M_2,   p = δ / (1/M_1 + 1/M_2),

with the plane-strain constrained moduli M_i = E_i (1 − ν)/((1 + ν)(1 − 2ν)): linear, so in
every V_h, and the contact pressure is λ = p on all of Γ.

**The cases' counterparts for traces that do not vanish at Γ's ends.** The rollers leave
u_y free at Γ's ends, so the normal traces span all of continuous P_k on the partition
(dim N k + 1), not the space vanishing at the ends of the paper's clamped bodies. The paper's
rule "multipliers of the traces' degree with the traces' end condition" (Thm 3) then gives
M^1_k — the space the paper calls R5.2, whose two zero modes came only from the two end values
clamped traces cannot see. Likewise the dual basis: DUAL (P_{k−1} modification next to the
ends, built to vanish with clamped traces) has the counterpart DUAL-ALL (a dual function on
every node). T4, R5.4, T5 and the user space P0-2h carry no end condition and are their own
counterparts. Which contain the constants: all but T3 (zero at the ends). Which have a
structural kernel here: none (dim M_h <= N k + 1 = dim of the Ω2 trace space for every case
on G_h = trace of Ω2); the measured ``kernel_dim`` (eigenvalues of K below 1e-8 × the largest,
against the L²(Γ) Gram matrix) is reported per row.

**Prediction (stated before the run).** λ_h = p and u_h = u whenever 1 ∈ M_h and K has no
kernel: then (u, p) satisfies the discrete system exactly (Bᵀ(p 1) are the consistent nodal
forces of the uniform traction, and B(u_2 − u_1) = 0 since the traces coincide), and the
solution is unique. So every case passes except T3, which cannot represent λ = p at Γ's ends:
its error sits in the two end intervals of G_h, and the mesh-ratio seams do not matter (a
constant is transferred exactly by any mortar projection).

**Outcome** (results/tables/elastic_patch.csv): as predicted for the passing spaces (errors
1e-16..1e-12, no kernel) and for T3's failure, but T3's error is not confined to the end
intervals: it is a boundary layer of a few intervals (error 1 in the end interval, 0.4–0.7
in the rest of [0, 1/4] at every refinement) whose tail decays fast into the middle half
(k = 1, 5:4: 0.75, 0.055, 0.0013, 0.00012 at N2 = 4, 16, 32, 64 — an exploratory run outside
the DAG; the DAG's pairs and the ledger claim ``elastic-patch-T3-layer-*`` record the trend). With the ratios 5:4
and 7:3 nearly every interval of G_h holds an Ω1 node that is not one of its nodes, so seams
are everywhere; the passing spaces show no error at any of them.
"""
from __future__ import annotations

import time

import ngsolve
import numpy as np

from ...discretization.segment import meshes
from ...discretization.spaces import registry
from ...models import make_model
from ...models.plane_strain import check_modulus, check_nu
from ...contact.contact import contact_pair, solve_contact_on
from ..contact.blocks import SIDE, PressedBlocks
from ..contact.registry import PATCH
from . import table

SCENE = PATCH.id
"""This scene's registry id (:mod:`..scene_registry` declares it and the models it is defined for)."""
SCENE_MODELS = PATCH.models
"""The models the scene is defined for (the first is its default)."""
X_DIRICHLET, Y_DIRICHLET = f"{meshes.DIRICHLET}|{SIDE}", meshes.DIRICHLET
"""Rollers on the lateral sides (u_x = 0), far faces clamped in x, prescribed in y."""
PASS_RTOL = 1e-10
"""λ_h = p and u_h = u to this relative accuracy count as passing (the issue's 1e-10)."""


DELTA = 1e-2
"""Default downward displacement of Ω2's top in the patch test."""


def patch_scene(E=(1.0, 1.0), delta: float = DELTA) -> PressedBlocks:
    """The patch test's data: rollers on the sides, Ω2's top moved down by ``delta``, no gap."""
    return PressedBlocks(SCENE, E[0], E[1], delta, (X_DIRICHLET, Y_DIRICHLET))


def constrained_modulus(E: float, nu: float) -> float:
    """M = E (1 − ν)/((1 + ν)(1 − 2ν)): σ_yy = M ε_yy when ε_xx = 0 (plane strain)."""
    return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))


def exact_pressure(delta: float, nu: float, E) -> float:
    """p = δ / (1/M_1 + 1/M_2) (unit heights)."""
    return delta / sum(1.0 / constrained_modulus(e, nu) for e in E)


def _where(gamma, x, g):
    """Masks of sample points x: in an end interval of G_h (partition g of ``gamma``), elsewhere within
    1/4 of an end, in the middle half [1/4, 3/4]. (With the ratios 5:4 and 7:3 every interval
    of G_h away from the common nodes holds an Ω1 node that is not a node of G_h: seams are
    everywhere, so the split is by distance from the ends.)"""
    ends = gamma.at_boundary(g, x)
    middle = (x >= 0.25) & (x <= 0.75) & ~ends
    return ends, ~(ends | middle), middle


def patch_rows(cases, ks, pairs, nu=0.3, E=(1.0, 1.0)) -> list:
    """:func:`solve_patch` for every case defined for each k and every (N1, N2) pair
    (:func:`.table.patch_rows`)."""
    return table.patch_rows(lambda k, n1, n2: patch_pair(k, n1, n2, nu, E),
                            lambda case, k, n1, n2, pair: solve_patch(case, k, n1, n2, nu, E, pair=pair),
                            cases, ks, pairs)


def patch_pair(k: int, n1: int, n2: int, nu: float, E, delta: float = DELTA):
    """The factorized blocks of the patch test (top of Ω2 moved down by ``delta``)."""
    return contact_pair(patch_scene(E, delta), k, "structured", n1, n2, make_model(SCENE_MODELS[0], nu=nu))


def solve_patch(case: str, k: int, n1: int, n2: int, nu: float = 0.3, E=(1.0, 1.0), delta: float = DELTA,
                per_interval: int = 12, pair=None) -> dict:
    """Solve the patch test for one case; one row of measures. ``pair``: :func:`patch_pair` of
    the same (k, n1, n2, nu, E, delta), to reuse the factorizations across cases.

    Returns
    -------
    dict
        ``lambda_max_rel_error`` (max |λ_h − p|/p over Γ, sampled ``per_interval`` points per
        interval of the union of both traces and G_h, ends included), split into
        ``lambda_end_rel_error`` (the end intervals of G_h), ``lambda_near_end_rel_error``
        (the rest of [0, 1/4] ∪ [3/4, 1]) and ``lambda_middle_rel_error`` ([1/4, 3/4]);
        ``u_max_rel_error`` (max nodal |u_h − u|/δ, both bodies);
        ``passes`` (both below :data:`PASS_RTOL`); ``kernel_dim`` of K; PDAS iterations.
    """
    nu = check_nu(nu)
    E = tuple(check_modulus(e, key) for e, key in zip(E, ("E1", "E2")))
    registry.check_case(case, k)
    for key, n in (("N1", n1), ("N2", n2)):
        meshes.check_mesh_args("structured", n, key)
    t0 = time.perf_counter()
    if pair is None:
        pair = patch_pair(k, n1, n2, nu, E, delta)
    sol = solve_contact_on(pair, case, "omega2", time_floor=False)
    sides, space, res = sol.sides, sol.space, sol.pdas
    gamma, g = sol.gamma, space.breakpoints
    p = exact_pressure(delta, nu, E)
    M1, M2 = (constrained_modulus(e, nu) for e in E)
    exact = (-p * ngsolve.y / M1, -p / M1 - p * (ngsolve.y - 1.0) / M2)
    u_err = max(np.max(np.abs(gf.vec.FV().NumPy() - pair.model.interpolate(s, (0.0, uy)))) / delta
                for s, gf, uy in zip(sides, sol.u, exact))
    K = sol.K
    x = gamma.sample(gamma.common_refinement(g, *(s.trace.partition for s in sides)), per_interval,
                     upper=1.0 - 1e-15)
    err = np.abs(space.evaluate(x) @ res.lam - p) / p
    ends, near, middle = _where(gamma, x, g)
    G, _ = gamma.gram(space, "L2")
    lam_err = float(err.max())
    return dict(scene=SCENE, case=case, k=k, family="structured", N1=n1, N2=n2, E1=E[0], E2=E[1], nu=nu,
                delta=delta, p=p, dim_M=space.dim, kernel_dim=table.kernel_dim(K, G),
                iterations=res.iterations, n_active=int(res.active.sum()), nonunique=bool(res.nonunique),
                lambda_max_rel_error=lam_err,
                lambda_end_rel_error=float(err[ends].max()),
                lambda_near_end_rel_error=float(err[near].max()) if near.any() else np.nan,
                lambda_middle_rel_error=float(err[middle].max()) if middle.any() else np.nan,
                u_max_rel_error=float(u_err), passes=bool(lam_err < PASS_RTOL and u_err < PASS_RTOL),
                seconds=time.perf_counter() - t0)
