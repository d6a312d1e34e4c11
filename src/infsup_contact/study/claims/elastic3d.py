"""Ledger claims of the 3D elastic bodies on the contact face (config ``studies.elastic3d``;
``results/tables/elastic3d_beta.csv`` and ``results/tables/elastic3d/patch.csv``), appended to
``results/claims.csv`` like :mod:`.membranes3d`.

Same verdicts as the paper's ledger (:mod:`infsup_contact.criteria.claims`): PASS / FAIL /
INCONCLUSIVE, a kernel decision too close to round-off is INCONCLUSIVE. Every ``predicted``
column is computed here from the registry's properties, the construction of the face spaces and
the config — never from a case id and never from the measured tables. The reasoning
(b(v, μ) = ∫_Γ (v_{2,z} − v_{1,z}) μ, :mod:`infsup_contact.models.elastic3d`):

* **Kernel** (``face-elastic-kernel-<tag>-k<k>-<element>``). β_h² is the smallest eigenvalue of
  (Σ_i B_i X_i B_iᵀ, G) with X_i = S_i⁻¹ SPD, so the kernel is ker B_1ᵀ ∩ ker B_2ᵀ: it depends
  on the couplings only, which see the z traces of vector Q_k / P_k clamped on ∂Ω_i∖Γ — the
  scalar trace spaces of the 3D membranes on the same meshes. Hence on every mesh pair and every ν
  the kernel equals the membranes' (``membranes3d.model``'s, compared wherever the face stage computed
  the same element, k, case and pair) and on matching meshes the dimension count
  max(dim M − dim W, 0) (:func:`.membranes3d.matching_kernel`). Predicted PASS.
* **Bounded** (``face-elastic-bounded-<tag>-k<k>-<element>``): spaces marked stable in the
  registry have β_H > ``claims.beta_floor`` on every mesh at ν = ``elastic3d.nu``, no kernel
  and every kernel decision clear. Predicted PASS (a(·,·) of elasticity at fixed ν is equivalent
  to the membranes' Dirichlet form on each component by Korn's inequality, so the membranes'
  stability carries over).
* **ν → 1/2** (``face-elastic-nu-<tag>-k<k>-<element>-N<n>``): on a fixed mesh β_H ≍ (1 − 2ν)^{1/2}.
  Lower bound: a_ν(v, v) ≤ (2μ̂ + 3λ̂)‖ε(v)‖² = (2μ̂ + 3λ̂) a_0(v, v) ((tr ε)² ≤ 3|ε|²), so
  β_ν ≥ β_0 (2μ̂ + 3λ̂)^{-1/2} with β_0 > 0 where the kernel count is 0, and λ̂ = ν/((1+ν)(1−2ν)).
  Upper bound where 1 ∈ M_h: v_i vanishes on ∂Ω_i∖Γ, so ∫_Γ v_{i,z} = ±∫_{Ω_i} div v_i and
  b(v, 1)² ≤ 2 Σ_i |Ω_i| ‖div v_i‖² ≤ (2/λ̂) Σ_i a_i(v_i, v_i) (|Ω_i| = 1, E_i = 1), i.e.
  β_ν ≤ (2/λ̂)^{1/2}/‖1‖_H. Both
  bounds are C (1 − 2ν)^{1/2}: the slope of log β_H against log(1 − 2ν) tends to 1/2; it is fitted
  (np.polyfit) over ν >= ``nu_sweep.fit_nu_min`` and PASS within ``nu_sweep.slope_tolerance``.
  Predicted PASS where 1 ∈ M_h (:func:`.membranes3d_studies.face_contains_constants`, computed by
  :func:`~infsup_contact.discretization.gamma.constants.spans_constants` on the built face space) and the
  kernel count is 0; without the constants only the lower bound holds (slope ≤ 1/2): a finding.
* **Patch test** (``face-elastic-patch-<tag>-k<k>-<element>``, :mod:`..patch.elastic3d`): the
  uniform compression is reproduced to round-off iff 1 ∈ M_h (spans_constants of the built space)
  and the scene's natural-trace kernel count is 0 (:func:`.membranes3d_studies.patch_prediction`,
  the membranes' face patch rule: the exact solution is linear, its z traces coincide).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ...discretization.spaces.registry import SPACES
from ...criteria.claims import COLUMNS, FAIL, FINDING, INCONCLUSIVE, PASS, close_decisions, close_text, row
from .membranes3d import matching_kernel
from .membranes3d_studies import face_contains_constants, patch_prediction, patch_verdict

REF = "beyond the paper (the 3D elastic bodies on the contact face: docs/models.md, 3D bodies with a contact face)"
PREDICTED_SLOPE = 0.5
"""β_H ≍ (1 − 2ν)^{1/2} on a fixed mesh (module docstring)."""


def claim_id(kind: str, case: str, k: int, element: str, n: int | None = None) -> str:
    """Ledger id: ``face-elastic-<kind>-<tag>-k<k>-<element>[-N<n>]`` (kind kernel | bounded | nu | patch)."""
    return f"face-elastic-{kind}-{SPACES[case].tag}-k{int(k)}-{element}" + ("" if n is None else f"-N{int(n)}")


def nu_prediction(spec, k: int, n: int, gamma) -> str:
    """PASS where 1 ∈ M_h and the matching kernel count is 0 (both bounds), else a finding."""
    if matching_kernel(spec, k, n, gamma) == 0 and face_contains_constants(spec, k, gamma):
        return PASS
    return FINDING


def _membrane_kernels(membranes: pd.DataFrame | None, element: str, k: int, case: str) -> dict:
    """(N1, N2) → (kernel_dim, structural_kernel_dim) of ``membranes3d.model`` (H rows, G_h = trace
    of Ω2)."""
    if membranes is None or not len(membranes):
        return {}
    m = membranes[(membranes.element == element) & (membranes.k == k) & (membranes.case == case)
                  & (membranes.norm == "H") & (membranes.multiplier_mesh == "omega2")]
    return {(int(a), int(b)): (int(d), int(s)) for a, b, d, s in zip(m.N1, m.N2, m.kernel_dim, m.structural_kernel_dim)}


def kernel_check(rows: pd.DataFrame, spec, k: int, gamma, membranes: dict):
    """(verdict, evidence): matching rows against the dimension count, non-matching rows against
    the membranes' kernel on the same pair (pairs the face stage did not compute: not compared)."""
    expect, seen, skipped = [], [], []
    for a, b, d, s in zip(rows.N1, rows.N2, rows.kernel_dim, rows.structural_kernel_dim):
        pair = (int(a), int(b))
        if a == b:
            e = matching_kernel(spec, k, int(b), gamma)
            expect.append((e, e))
        elif pair in membranes:
            expect.append(membranes[pair])
        else:
            skipped.append(pair)
            continue
        seen.append((pair, int(d), int(s)))
    if not seen:
        return INCONCLUSIVE, "no mesh pair with a predicted kernel"
    ok = all(d == e[0] and s == e[1] for (_, d, s), e in zip(seen, expect))
    per_row = dict.fromkeys(f"{p[0]}:{p[1]} {d} vs {e[0]}" for (p, d, _), e in zip(seen, expect))
    text = (f"kernel vs prediction (the count on matching pairs, the membranes' on non-matching ones), "
            f"every ν: {', '.join(per_row)}" + (f"; not compared (no membranes row): {sorted(set(skipped))}"
                                                 if skipped else ""))
    close = close_decisions(rows)
    if len(close):
        return INCONCLUSIVE, f"{text}; {close_text(close)}"
    return (PASS if ok else FAIL), text


def bounded_check(rows: pd.DataFrame, floor: float):
    """β_H > floor with no kernel on every row (one ν), every decision clear."""
    beta, dims = rows.beta.to_numpy(float), rows.kernel_dim.to_numpy(int)
    pairs = " ".join(f"{a}:{b}" for a, b in zip(rows.N1, rows.N2))
    text = f"min β_H = {beta.min():.4g} over {pairs} (floor {floor:g}); kernel dims {sorted(set(dims.tolist()))}"
    close = close_decisions(rows)
    if len(close):
        return INCONCLUSIVE, f"{text}; {close_text(close)}"
    return (PASS if beta.min() > floor and not dims.any() else FAIL), text


def nu_slope(rows: pd.DataFrame, fit_nu_min: float) -> tuple:
    """(slope, number of ν) of log β_H against log(1 − 2ν) over ν >= ``fit_nu_min`` (np.polyfit)."""
    fit = rows[rows.nu >= fit_nu_min].sort_values("nu")
    x, y = np.log(1.0 - 2.0 * fit.nu.to_numpy(float)), fit.beta.to_numpy(float)
    if len(fit) < 2 or np.any(y <= 0):
        return np.nan, len(fit)
    return float(np.polyfit(x, np.log(y), 1)[0]), len(fit)


def nu_check(rows: pd.DataFrame, fit_nu_min: float, tol: float):
    """PASS if the fitted slope is within ``tol`` of 1/2 (INCONCLUSIVE: a kernel or close decision)."""
    slope, n = nu_slope(rows, fit_nu_min)
    fit = rows[rows.nu >= fit_nu_min].sort_values("nu")
    text = (f"slope of log β_H vs log(1 − 2ν) = {slope:.4f} over ν = {', '.join(f'{v:g}' for v in fit.nu)} "
            f"(predicted {PREDICTED_SLOPE:g} ± {tol:g}); β_H = {', '.join(f'{b:.4g}' for b in fit.beta)}")
    close = close_decisions(fit)
    if len(close) or not np.isfinite(slope) or n < 3:
        return INCONCLUSIVE, text + (f"; {close_text(close)}" if len(close) else "; no slope (kernel or < 3 ν)")
    return (PASS if abs(slope - PREDICTED_SLOPE) <= tol else FAIL), text


def face_elastic_claims(beta: pd.DataFrame, patch: pd.DataFrame | None, cfg: dict, fe: dict, interfaces: dict,
                        membranes: pd.DataFrame | None = None) -> pd.DataFrame:
    """Every claim of the elastic face stage.

    Parameters
    ----------
    beta
        ``elastic3d_beta.csv`` (β table columns plus ``model``, ``element``, ``nu``).
    patch
        ``results/tables/elastic3d/patch.csv`` or ``None``.
    cfg
        The ``claims`` config (``beta_floor``).
    fe
        The ``elastic3d`` entry's scenes (``nu``, ``nu_sweep``).
    interfaces
        element → its face interface (:func:`.membranes3d.element_interfaces`).
    membranes
        ``face_beta.csv`` of ``membranes3d.model`` (the kernel comparison), or ``None``.
    """
    sweep, base_nu = fe["nu_sweep"], float(fe["nu"])
    out = []
    h = beta[beta.norm == "H"]
    for (element, k, case), rc in h.groupby(["element", "k", "case"], sort=False):
        spec, k, gamma = SPACES.get(case), int(k), interfaces[element]
        if spec is None or spec.dimension is None:
            continue
        where = f"elastic3d, {case}, k={k}, {element}"
        out.append(row(claim_id("kernel", case, k, element), REF,
                       f"face, {where}: dim ker = the membranes' on every pair and ν (on matching meshes "
                       "max(dim M − dim W, 0))",
                       kernel_check(rc, spec, k, gamma, _membrane_kernels(membranes, element, k, case)), predicted=PASS))
        base = rc[np.isclose(rc.nu, base_nu)]
        if spec.stable and len(base):
            out.append(row(claim_id("bounded", case, k, element), REF,
                           f"face, {where}, ν = {base_nu:g}: β_H > floor with no kernel on every mesh pair",
                           bounded_check(base, cfg["beta_floor"]), predicted=PASS))
        for n in sweep["N"]:
            if matching_kernel(spec, k, int(n), gamma) > 0:
                continue  # β_H = 0 at every ν: no slope to claim
            rn = rc[(rc.N1 == n) & (rc.N2 == n)]
            if len(rn):
                out.append(row(claim_id("nu", case, k, element, n), REF,
                               f"face, {where}, N={int(n)}: β_H scales like (1 − 2ν)^(1/2) as ν → 1/2 (slope 1/2 of log β_H "
                               "vs log(1 − 2ν))", nu_check(rn, sweep["fit_nu_min"], sweep["slope_tolerance"]),
                               predicted=nu_prediction(spec, k, int(n), gamma)))
    if patch is not None:
        for (element, k, case), rc in patch.groupby(["element", "k", "case"], sort=False):
            spec, k = SPACES.get(case), int(k)
            if spec is None:
                continue
            pairs = sorted({(int(a), int(b)) for a, b in zip(rc.N1, rc.N2)})
            out.append(row(claim_id("patch", case, k, element), REF,
                           f"elastic face patch test, {case}, k={k}, {element}: a uniaxial compression across "
                           "non-matching faces is reproduced to round-off (λ_h = λ, u_h = u)", patch_verdict(rc),
                           predicted=patch_prediction(spec, k, interfaces[element], pairs)))
    return pd.DataFrame(out, columns=COLUMNS)
