"""The contact patch test of the paper's membranes (2D, scalar): the analogue of the elastic
pair's (:mod:`.segment`) and of the 3D face's (:mod:`.face`).

Two membranes Ω1 = (0,1)² and Ω2 = (0,1)×(1,2), −c_i Δu_i = 0, on non-matching structured
meshes (N1 ≠ N2 segments on Γ, :func:`~..contact.blocks.block_mesh`): u1 = 0 on Ω1's bottom,
u2 = −δ on Ω2's top (boundary ``dir``), the lateral sides x = 0, 1 (boundary ``side``) natural
(∂u_i/∂n = 0), frictionless contact on Γ with b(v, μ) = ∫_Γ (v2 − v1) μ
(:mod:`infsup_contact.models.contract`, n = e_y).

**Exact solution.** u_i = u_i(y) meets the lateral conditions, −c_i u_i'' = 0 makes it affine;
with contact active on Γ (zero gap) u1(1) = u2(1), and the multiplier enters
A_1 u_1 = F_1 − B_1ᵀλ, A_2 u_2 = F_2 + B_2ᵀλ, so λ = −c1 ∂u1/∂y = −c2 ∂u2/∂y (flux continuity):

    λ = δ / (1/c1 + 1/c2) > 0,   u1 = −(λ/c1) y,   u2 = −δ + (λ/c2)(2 − y),

uniform on Γ; λ > 0 with zero gap satisfies the complementarity, and u is unique.

**Prediction (stated before the run)**, as for the elastic pair (:mod:`.segment`, whose
docstring names the counterparts for traces that do not vanish at Γ's ends): u is linear, so
it lies in every V_{h,i}, and its traces coincide, B(u2 − u1) = 0. If 1 ∈ M_h, (u, λ·1)
solves the discrete system exactly (B_iᵀ(λ 1) are the consistent nodal fluxes, Green's
formula) and its coefficients lie in every registered cone, so λ_h = λ and u_h = u to
round-off whatever the seams; if 1 ∉ M_h, λ_h ≠ λ. The natural lateral sides leave the Γ
traces free at Γ's ends, so the spaces' end conditions do not matter: every case holding the
constants passes, T3 (zero at Γ's ends) fails. The column ``predicted`` is 1 ∈ M_h computed
on the space the solve builds
(:func:`~infsup_contact.discretization.gamma.constants.spans_constants`), never read off a case id.

**Outcome** (k = 1, 2, 3; N1:N2 = 5:4 and 7:3; c = (1, 3); every registered case, 38 rows; an
exploratory run outside the DAG, ``tests/study/test_membranes_patch.py`` pins the rule): as
predicted in every row. R5.2, T4, R5.4, T5, DUAL and DUAL-ALL hold the constants and reproduce
λ to ≤ 3e-13 and u to ≤ 2e-13 δ; T3 fails with λ error 1 (it vanishes at Γ's ends) and u error
4e-2..1e-1 δ. No row has a kernel (``kernel_dim`` 0).

Not in the workflow (the ledger stays as it is): :func:`membranes_patch_rows` is run by hand
(docs/models.md).
"""
from __future__ import annotations

import time

import ngsolve
import numpy as np

from ...discretization.gamma.constants import spans_constants
from ...discretization.segment import meshes
from ...discretization.spaces import registry
from ...errors import InputError, check_prestress
from ...models import make_model
from ...contact.contact import contact_pair, solve_contact_on
from ..contact.blocks import PressedBlocks
from . import table

SCENE = "membranes-patch"
"""The scene's name in its rows (not a registered scene: the workflow does not run it)."""
MODEL = "membranes"
DELTA = 1e-2
"""Default downward displacement δ of Ω2's top."""
PASS_RTOL = 1e-8
"""λ_h = λ and u_h = u to this relative accuracy count as passing."""


def patch_scene(c=(1.0, 1.0), delta: float = DELTA) -> PressedBlocks:
    """The data: u prescribed on ``dir`` only (the lateral sides natural), Ω2's top moved down by
    ``delta``, no initial gap; ``c`` = (c1, c2) the prestresses."""
    if not (np.isfinite(delta) and 0.0 < delta < 1.0):
        raise InputError("delta", "0 < delta < 1", got=delta)
    c1, c2 = (check_prestress(key, v) for key, v in (("c1", c[0]), ("c2", c[1])))
    return PressedBlocks(SCENE, c1, c2, float(delta), (meshes.DIRICHLET,))


def exact_pressure(delta: float, c) -> float:
    """λ = δ / (1/c1 + 1/c2) (unit heights)."""
    return delta / (1.0 / c[0] + 1.0 / c[1])


def exact_displacements(delta: float, c) -> tuple:
    """(u1, u2) as NGSolve coefficient functions of y (module docstring)."""
    lam = exact_pressure(delta, c)
    return -lam / c[0] * ngsolve.y, -delta + lam / c[1] * (2.0 - ngsolve.y)


def patch_pair(k: int, n1: int, n2: int, c=(1.0, 1.0), delta: float = DELTA):
    """Both factorized membranes of the scene (one per body, shared by every case)."""
    return contact_pair(patch_scene(c, delta), k, "structured", n1, n2, make_model(MODEL))


def solve_membranes_patch(case: str, k: int, n1: int, n2: int, c=(1.0, 1.0), delta: float = DELTA,
                          per_interval: int = 12, pair=None) -> dict:
    """Solve the patch test for one case on G_h = trace of Ω2; one row of measures. ``pair``:
    :func:`patch_pair` of the same (k, n1, n2, c, delta), to reuse the factorizations.

    Returns
    -------
    dict
        ``lambda_max_rel_error`` = max |λ_h − λ|/λ at ``per_interval`` points of every interval of
        the common refinement of G_h and both traces (ends included); ``u_max_rel_error`` = max
        nodal |u_h − I_h u| / δ over both bodies; ``passes`` (both below :data:`PASS_RTOL`);
        ``predicted`` (1 ∈ M_h on the built space); ``kernel_dim`` of K; PDAS iterations.
    """
    registry.check_case(case, k)
    for key, n in (("N1", n1), ("N2", n2)):
        meshes.check_mesh_args("structured", n, key)
    t0 = time.perf_counter()
    if pair is None:
        pair = patch_pair(k, n1, n2, c, delta)
    c = pair.c
    sol = solve_contact_on(pair, case, "omega2", time_floor=False)
    space, gamma, res = sol.space, sol.gamma, sol.pdas
    lam = exact_pressure(delta, c)
    x = gamma.sample(gamma.common_refinement(space.breakpoints, *(s.trace.partition for s in sol.sides)),
                     per_interval, upper=1.0 - 1e-15)
    lam_err = float(np.max(np.abs(sol.pressure(x) - lam)) / lam)
    u_err = max(float(np.max(np.abs(gf.vec.FV().NumPy() - pair.model.interpolate(s, (u,)))))
                for s, gf, u in zip(sol.sides, sol.u, exact_displacements(delta, c))) / delta
    G, _ = gamma.gram(space, "L2")
    return dict(scene=SCENE, case=case, k=k, family="structured", N1=n1, N2=n2, c1=c[0], c2=c[1],
                delta=delta, pressure=lam, dim_M=space.dim, kernel_dim=table.kernel_dim(sol.K, G),
                nonunique=bool(res.nonunique), iterations=res.iterations, n_active=int(res.active.sum()),
                lambda_max_rel_error=lam_err, u_max_rel_error=u_err,
                passes=bool(lam_err < PASS_RTOL and u_err < PASS_RTOL), predicted=spans_constants(space),
                seconds=time.perf_counter() - t0)


def membranes_patch_rows(cases, ks, pairs, c=(1.0, 1.0), delta: float = DELTA) -> list:
    """:func:`solve_membranes_patch` for every case defined for each k and every (N1, N2) pair
    (:func:`.table.patch_rows`)."""
    return table.patch_rows(lambda k, n1, n2: patch_pair(k, n1, n2, c, delta),
                            lambda case, k, n1, n2, pair: solve_membranes_patch(case, k, n1, n2, c, delta,
                                                                                pair=pair),
                            cases, ks, pairs)
