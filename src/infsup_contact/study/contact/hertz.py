"""The Hertz scene of the plane-strain elastic pair.

Ω1 = (0,1)² below, Ω2 = (0,1)×(1,2) above, on the flat potential contact surface Γ; the
curvature of the upper body is the initial gap g0(x) = (x − 1/2)²/(2R) (the Hertz
approximation), not a curved mesh. Ω1's bottom is fixed, Ω2's top is moved down by d
(u = (0, −d)); the lateral sides are traction free. The resultant P = ∫_Γ λ_h is an output.

Plane-strain Hertz (two half-spaces, 1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2): for a resultant P,
a = sqrt(4PR/(πE*)), p(x) = p0 sqrt(1 − (x − 1/2)²/a²), p0 = 2P/(πa). Hertz assumes
half-spaces, so two errors are kept apart:

* **discretization error** against a fine-mesh solution of the same finite domain
  (structured N_ref, degree k + 1, T3 multipliers — stable for every k): energy error
  ‖u_ref − u_h‖_a, max-pressure error, half-width error, λ in L²(Γ), per case and k, with
  rates fitted by ``np.polyfit``;
* **modeling error** against Hertz for the measured P on the finest mesh, as the contact
  zone shrinks relative to the domain (smaller d: a/W = 0.3 … 0.08, W = 1).

Oscillation of λ_h (the unstable spaces): ``oscillation`` (:func:`profile_measures`) = the
total variation of λ_h on the central half of the contact zone over that of a single hump,
minus 1 — 0 for Hertz's profile, positive for every extra wiggle.

Expectations (written with the code, before the runs): the stable cases (T3, T4, T5, DUAL)
converge with oscillation ~0; R5.4 (one zero mode on matching meshes) oscillates in the
contact zone at every mesh; R5.2 and DUAL-ALL have their zero modes at Γ's ends, outside the
contact zone, so the minimum-norm λ_h does not see them; the modeling error shrinks with a/W.

Outcome: results/tables/elastic_hertz.csv and the ledger (study/claims/elastic.py,
:func:`~infsup_contact.study.claims.elastic.hertz_claims`); the paper's elastic section.
"""
from __future__ import annotations

import time

import ngsolve
import numpy as np

from ...discretization.spaces import registry
from ...models import make_model
from ...models.plane_strain import check_modulus, check_nu, lame
from ...contact.contact import contact_pair, solve_contact_on
from .accuracy import _element_quadrature
from .blocks import PressedBlocks
from .registry import HERTZ

SCENE = HERTZ.id
"""This scene's registry id (:mod:`.scene_registry` declares it and the models it is defined for)."""
SCENE_MODELS = HERTZ.models
"""The models the scene is defined for (the first is its default)."""
X_DIRICHLET = Y_DIRICHLET = "dir"
"""Clamped far faces (Ω1's bottom, Ω2's top), traction-free lateral sides."""
CENTER = 0.5


def combined_modulus(nu: float, E) -> float:
    """E* with 1/E* = Σ (1 − ν²)/E_i."""
    return 1.0 / sum((1.0 - nu * nu) / e for e in E)


def hertz(P: float, R: float, nu: float, E) -> tuple:
    """(a, p0) of plane-strain Hertz for resultant P."""
    a = np.sqrt(4.0 * P * R / (np.pi * combined_modulus(nu, E)))
    return float(a), float(2.0 * P / (np.pi * a))


def hertz_pressure(x, P, R, nu, E):
    a, p0 = hertz(P, R, nu, E)
    return p0 * np.sqrt(np.clip(1.0 - ((np.asarray(x) - CENTER) / a) ** 2, 0.0, None))


def check_geometry(R, d) -> tuple:
    """(R, d) as floats: 0 < R <= 1e6, 0 < d < 1/2; :class:`InputError` naming the key."""
    from ...errors import InputError

    out = []
    for key, value, ok, allowed in (("R", R, lambda v: 0 < v <= 1e6, "a finite radius in (0, 1e6]"),
                                    ("d", d, lambda v: 0 < v < 0.5, "an indentation in (0, 0.5)")):
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise InputError(key, allowed, got=value) from None
        if isinstance(value, bool) or not ok(v):  # NaN fails too
            raise InputError(key, allowed, got=value)
        out.append(v)
    return tuple(out)


def hertz_scene(R: float, d: float, E=(1.0, 1.0)) -> PressedBlocks:
    """The Hertz scene's data: clamped far faces, Ω2's top moved by d, gap (x − 1/2)²/(2R)."""
    return PressedBlocks(SCENE, E[0], E[1], d, (X_DIRICHLET, Y_DIRICHLET),
                         initial_gap=lambda x: (x - CENTER) ** 2 / (2.0 * R), initial_gap_degree=2)


def hertz_pair(k: int, n: int, d: float, nu: float = 0.3, E=(1.0, 1.0), n2: int | None = None, R: float = 1.0):
    """The factorized blocks of the Hertz scene (N segments on Γ for Ω1, ``n2`` (default N) for
    Ω2, top of Ω2 moved by d, gap of radius R), shared by every multiplier case."""
    return contact_pair(hertz_scene(R, d, E), k, "structured", n, n if n2 is None else n2,
                        make_model(SCENE_MODELS[0], nu=nu))


def solve_hertz(case: str, k: int, n: int, R: float, d: float, nu: float = 0.3, E=(1.0, 1.0), n2: int | None = None,
                pair=None):
    """One Hertz solve on structured blocks; ``pair`` from :func:`hertz_pair` with the same
    (k, n, d, nu, E, n2) to reuse the factorizations across cases."""
    nu = check_nu(nu)
    E = tuple(check_modulus(e, key) for e, key in zip(E, ("E1", "E2")))
    R, d = check_geometry(R, d)
    registry.check_case(case, k)
    if pair is None:
        pair = hertz_pair(k, n, d, nu, E, n2, R)
    return solve_contact_on(pair, case, "omega2", time_floor=False)


def hertz_row(case: str, k: int, n1: int, n2: int, R: float, d: float, nu: float = 0.3, E=(1.0, 1.0)) -> dict:
    """One solve and its measures against plane-strain Hertz for the measured P (the CLI row)."""
    t0 = time.perf_counter()
    sol = solve_hertz(case, k, n1, R, d, nu, E, n2=n2)
    m = profile_measures(sol)
    a, p0 = hertz(m["P"], R, nu, E)
    return dict(scene=SCENE, case=case, k=k, family="structured", N1=n1, N2=n2, E1=E[0], E2=E[1], nu=nu, R=R,
                d=d, dim_M=sol.space.dim, iterations=sol.pdas.iterations, nonunique=bool(sol.pdas.nonunique),
                **m, hertz_a=a, hertz_p0=p0, p_max_rel_error_vs_hertz=abs(m["p_max"] - p0) / p0,
                half_width_rel_error_vs_hertz=abs(m["half_width"] - a) / a, seconds=time.perf_counter() - t0)


def sample_points(sol, per_interval: int = 24) -> np.ndarray:
    """``per_interval`` + 1 points per interval of G_h (:meth:`~infsup_contact.discretization.gamma.interface.Interface.sample`)."""
    return sol.gamma.sample(sol.space.breakpoints, per_interval)


def profile_measures(sol, x=None) -> dict:
    """Resultant P, max pressure, contact half-width a_h (half the extent of λ_h > 1e-8 max),
    and the oscillation of λ_h on the central half |x − c| <= a_h/2 of the contact zone: its
    total variation there in excess of a single hump's, (TV − (2 max − λ_h(c − a_h/2) −
    λ_h(c + a_h/2))) / (2 max λ_h) — 0 for Hertz's profile, positive for every extra wiggle
    (the edges, where a P_k multiplier must bend into the square-root edge, are left out)."""
    x = sample_points(sol) if x is None else x
    lam = sol.pressure(x)
    peak = float(lam.max())
    support = x[lam > 1e-8 * peak]
    half = float(0.5 * (support.max() - support.min()))
    mid = 0.5 * (support.max() + support.min())
    lc = lam[np.abs(x - mid) <= 0.5 * half]
    excess = np.sum(np.abs(np.diff(lc))) - (2.0 * lc.max() - lc[0] - lc[-1])
    return dict(P=sol.resultant(), p_max=peak, half_width=half, oscillation=float(max(excess, 0.0) / (2.0 * peak)))


def _strain_data(gf, xy):
    """(∂u_x, ∂u_y) gradients of a product-space GridFunction at physical points xy (located
    in its own mesh)."""
    mesh = gf.space.mesh
    mips = mesh(xy[:, 0], xy[:, 1])
    return tuple(np.asarray(ngsolve.grad(gf.components[j])(mips)).reshape(len(xy), 2) for j in (0, 1))


def reference_data(ref) -> list:
    """Per body: quadrature points and weights of the reference mesh and the reference
    gradients there (computed once per reference)."""
    out = []
    for gref in ref.u:
        xy, w = _element_quadrature(gref.space.mesh, 2 * gref.components[0].space.globalorder)
        out.append((xy, w, _strain_data(gref, xy)))
    return out


def energy_error(sol, ref_data, nu: float) -> float:
    """‖u_ref − u_h‖_a = (Σ E_i ∫ 2μ̂ ε(e):ε(e) + λ̂ (div e)²)^{1/2}, quadrature on the reference
    mesh (exact when the meshes are nested), ``ref_data`` from :func:`reference_data`."""
    mu, lam = lame(nu)
    total = 0.0
    for gf, (xy, w, (bx, by)), e in zip(sol.u, ref_data, sol.c):
        ax, ay = _strain_data(gf, xy)
        dx, dy = ax - bx, ay - by
        exy = 0.5 * (dx[:, 1] + dy[:, 0])
        dens = 2 * mu * (dx[:, 0] ** 2 + dy[:, 1] ** 2 + 2 * exy ** 2) + lam * (dx[:, 0] + dy[:, 1]) ** 2
        total += e * w @ dens
    return float(np.sqrt(max(total, 0.0)))


def lambda_l2_error(sol, ref) -> float:
    """‖λ_ref − λ_h‖_{L²(Γ)} by Gauss on the union of both partitions."""
    gamma = sol.gamma  # tol=0: only equal breakpoints merge (an interval of 1 ulp is kept, as np.union1d)
    x, w = gamma.quadrature(gamma.common_refinement(sol.space.breakpoints, ref.space.breakpoints, tol=0.0),
                            2 * max(sol.space.degree, ref.space.degree) + 2)
    return float(np.sqrt(w @ (sol.pressure(x) - ref.pressure(x)) ** 2))


def discretization_rows(cases, ks, ns, n_ref: int, R: float, d: float, nu=0.3, E=(1.0, 1.0)) -> list:
    """Errors against the fine-mesh reference (degree k + 1, T3, N_ref) of the same domain."""
    rows = []
    for k in ks:
        ref = solve_hertz(registry.REFERENCE_SPACE, k + 1, n_ref, R, d, nu, E)
        rm, rdata = profile_measures(ref), reference_data(ref)
        for n in ns:
            pair = hertz_pair(k, n, d, nu, E, R=R)
            for case in registry.ids_valid_for(k, cases):
                t0 = time.perf_counter()
                sol = solve_hertz(case, k, n, R, d, nu, E, pair=pair)
                m = profile_measures(sol)
                rows.append(dict(
                    study="discretization", case=case, k=k, N=n, N_ref=n_ref, R=R, d=d, nu=nu, E1=E[0], E2=E[1],
                    P=m["P"], p_max=m["p_max"], half_width=m["half_width"], oscillation=m["oscillation"],
                    energy_error=energy_error(sol, rdata, nu),
                    lambda_l2_error=lambda_l2_error(sol, ref),
                    p_max_rel_error=abs(m["p_max"] - rm["p_max"]) / rm["p_max"],
                    half_width_rel_error=abs(m["half_width"] - rm["half_width"]) / rm["half_width"],
                    ref_p_max=rm["p_max"], ref_half_width=rm["half_width"], ref_oscillation=rm["oscillation"],
                    nonunique=bool(sol.pdas.nonunique), seconds=time.perf_counter() - t0))
    return rows


def modeling_rows(case: str, k: int, n: int, R: float, ds, nu=0.3, E=(1.0, 1.0)) -> list:
    """Errors against plane-strain Hertz for the measured P, one row per indentation d.

    ``p_max_rel_error`` compares the peak pressures; ``pressure_sup_rel_error`` is
    max_x |λ_h(x) − p(x)| / p0 over Γ, which also carries the discretization error at the
    edges of the contact zone (few elements per half-width when a/W is small).
    """
    rows = []
    for d in ds:
        sol = solve_hertz(case, k, n, R, d, nu, E)
        m = profile_measures(sol)
        a, p0 = hertz(m["P"], R, nu, E)
        x = sample_points(sol)
        lam_err = np.max(np.abs(sol.pressure(x) - hertz_pressure(x, m["P"], R, nu, E))) / p0
        rows.append(dict(study="modeling", case=case, k=k, N=n, R=R, d=d, nu=nu, E1=E[0], E2=E[1], P=m["P"],
                         p_max=m["p_max"], half_width=m["half_width"], hertz_a=a, hertz_p0=p0,
                         a_over_W=a / 1.0, p_max_rel_error=abs(m["p_max"] - p0) / p0,
                         half_width_rel_error=abs(m["half_width"] - a) / a, pressure_sup_rel_error=float(lam_err),
                         oscillation=m["oscillation"]))
    return rows


def profile_rows(pairs, n: int, R: float, d: float, nu=0.3, E=(1.0, 1.0), per_interval: int = 24) -> list:
    """λ_h(x) on Γ for each (case, k) in ``pairs`` on the N×N blocks, and Hertz's p(x) for the
    measured P of the first pair (the figure's data; ``quantity`` = lambda_h or hertz)."""
    rows = []
    for i, (case, k) in enumerate(pairs):
        sol = solve_hertz(case, k, n, R, d, nu, E)
        x = sample_points(sol, per_interval)
        rows += [dict(case=case, k=k, N=n, R=R, d=d, quantity="lambda_h", x=xi, value=v)
                 for xi, v in zip(x, sol.pressure(x))]
        if i == 0:
            rows += [dict(case="Hertz", k=0, N=n, R=R, d=d, quantity=SCENE, x=xi, value=v)
                     for xi, v in zip(x, hertz_pressure(x, sol.resultant(), R, nu, E))]
    return rows
