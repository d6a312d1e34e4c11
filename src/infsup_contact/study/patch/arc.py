"""The contact patch test on the arc: the membranes' (:mod:`.membranes`) with Γ curved.

Ω1 = {R − 1 < r < R} and Ω2 = {R < r < R + 1}, 0 < θ < 1/R (:mod:`infsup_contact.discretization.segment.arc`),
the paper's blocks mapped and curved at the body's degree: u1 = 0 on r = R − 1, u2 = −δ on r = R + 1
(boundary ``dir``), the radial sides θ = 0, 1/R natural, frictionless contact on Γ (r = R).

**Exact solution.** u_i = u_i(r) meets the lateral conditions; −c_i Δu_i = 0 makes it
a + b ln r; with contact active u1(R) = u2(R) and the flux continuous, c1 u1'(R) = c2 u2'(R) = q/R:

    u1 = (q/c1) ln(r/(R − 1)),   u2 = −δ + (q/c2) ln(r/(R + 1)),
    q = −δ / (ln(R/(R − 1))/c1 + ln((R + 1)/R)/c2),   λ = −c1 ∂u1/∂r (R) = −q/R > 0,

a uniform normal pressure on Γ; R → ∞ gives the flat test's λ = δ/(1/c1 + 1/c2).

**Prediction (stated before the run).** At R = ∞ this is the flat test: λ_h = λ to round-off iff
1 ∈ M_h. At finite R, u is not in V_h (ln r, and the bodies are only isoparametric images of the
annuli), so no space reproduces λ: every space holding the constants converges, λ_h → λ, and T3
(zero at Γ's ends) keeps an O(1) error at the ends. The table measures how close, per radius,
coupling, case and mesh.

Not in the ledger: :func:`arc_patch_rows` is run by the DAG's arc study only where the config asks
(its rows are a table), and by hand (docs/models.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import ngsolve
import numpy as np

from ...discretization.gamma.constants import spans_constants
from ...discretization.segment.arc import Arc, check_arc_options
from ...discretization.spaces.gammas import arc_of
from ...errors import InputError, check_prestress
from ...models import make_model
from ...models.contract import Body
from ...contact.contact import contact_pair, solve_contact_on
from ..contact.blocks import PressedBlocks, block_mesh
from . import table

SCENE = "arc-patch"
DELTA = 1e-2


@dataclass(frozen=True)
class ArcBlocks(PressedBlocks):
    """The pressed blocks on the arc: the paper's blocks, curved (module docstring)."""

    arc: Arc = Arc()

    def mesh_pair(self, family: str, n1: int, n2: int, **_) -> tuple:
        return Body(block_mesh(n1, 1), self.arc), Body(block_mesh(n2, 2), self.arc)


def patch_scene(radius: float, coupling: str = "exact", c=(1.0, 1.0), delta: float = DELTA) -> ArcBlocks:
    """The data: u prescribed on ``dir`` only, Ω2's far side moved in by ``delta``."""
    check_arc_options("arc", radius, coupling)
    if not (np.isfinite(delta) and 0.0 < delta < 1.0):
        raise InputError("delta", "0 < delta < 1", got=delta)
    c1, c2 = (check_prestress(key, v) for key, v in (("c1", c[0]), ("c2", c[1])))
    return ArcBlocks(SCENE, c1, c2, float(delta), ("dir",), arc=arc_of("arc", radius, coupling))


def exact_pressure(radius: float, delta: float, c) -> float:
    """λ = −q/R (module docstring); δ/(1/c1 + 1/c2) at R = ∞."""
    if math.isinf(radius):
        return delta / (1.0 / c[0] + 1.0 / c[1])
    R = float(radius)
    return delta / (R * (math.log(R / (R - 1.0)) / c[0] + math.log1p(1.0 / R) / c[1]))


def exact_displacements(radius: float, delta: float, c) -> tuple:
    """(u1, u2) as NGSolve coefficient functions of the curved bodies' coordinates (centre (0, 1 − R))."""
    if math.isinf(radius):
        lam = exact_pressure(radius, delta, c)
        return -lam / c[0] * ngsolve.y, -delta + lam / c[1] * (2.0 - ngsolve.y)
    R = float(radius)
    q = -exact_pressure(R, delta, c) * R
    r = ngsolve.sqrt(ngsolve.x ** 2 + (ngsolve.y + R - 1.0) ** 2)
    return q / c[0] * ngsolve.log(r / (R - 1.0)), -delta + q / c[1] * ngsolve.log(r / (R + 1.0))


def solve_arc_patch(case: str, k: int, n1: int, n2: int, scene: ArcBlocks, per_interval: int = 12, pair=None) -> dict:
    """One row: max |λ_h − λ|/λ on Γ, max nodal |u_h − I_h u|/δ, 1 ∈ M_h, the kernel of K."""
    pair = pair or contact_pair(scene, k, "structured", n1, n2, make_model("membranes"))
    sol = solve_contact_on(pair, case, "omega2", time_floor=False)
    space, gamma, c, R = sol.space, sol.gamma, pair.c, scene.arc.radius
    lam = exact_pressure(R, scene.d, c)
    x = gamma.sample(gamma.common_refinement(space.breakpoints, *(s.trace.partition for s in sol.sides)),
                     per_interval, upper=1.0 - 1e-15)
    lam_err = float(np.max(np.abs(sol.pressure(x) - lam)) / lam)
    interior = ~gamma.at_boundary(space.breakpoints, x)
    lam_err_interior = float(np.max(np.abs(sol.pressure(x[interior]) - lam)) / lam) if interior.any() else math.nan
    u_err = max(float(np.max(np.abs(gf.vec.FV().NumPy() - pair.model.interpolate(s, (u,)))))
                for s, gf, u in zip(sol.sides, sol.u, exact_displacements(R, scene.d, c))) / scene.d
    G, _ = gamma.gram(space, "L2")
    return dict(scene=SCENE, radius=R, coupling=scene.arc.coupling, case=case, k=k, N1=n1, N2=n2, c1=c[0], c2=c[1],
                pressure=lam, kernel_dim=table.kernel_dim(sol.K, G), lambda_max_rel_error=lam_err,
                lambda_interior_rel_error=lam_err_interior, u_max_rel_error=u_err, holds_constants=spans_constants(space))


def arc_patch_rows(cases, ks, pairs, radii, couplings=("exact",), c=(1.0, 1.0), delta: float = DELTA) -> list:
    """:func:`solve_arc_patch` for every radius × coupling, case defined for each k and pair."""
    rows = []
    for radius in radii:
        for coupling in couplings:
            scene = patch_scene(radius, coupling, c, delta)
            rows += table.patch_rows(lambda k, n1, n2: contact_pair(scene, k, "structured", n1, n2,
                                                                    make_model("membranes")),
                                     lambda case, k, n1, n2, pair: solve_arc_patch(case, k, n1, n2, scene, pair=pair),
                                     cases, ks, pairs)
    return rows
