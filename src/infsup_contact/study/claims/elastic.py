"""Ledger claims of the elastic scene: does the paper's verdict carry over to plane strain?

Same criteria as the membranes (:mod:`infsup_contact.criteria.claims`: slope interval of log β_h
vs log h inside ±τ and min β_h > floor for "bounded"; exact kernel counts). Each claim's
``predicted`` column was written before the tables existed; the reasoning:

* **Same kernels** (``elastic-kernel-as-membranes``, exact): μ is in the kernel of
  B A⁻¹ Bᵀ iff b(v, μ) = 0 for every v, and b sees only the normal traces v_{i,y}, which range
  over the same scalar trace spaces as the membranes' w_i (clamped: zero at Γ's ends). So the
  kernel dimension is the membranes' one on every row, matching or not, for every ν.
* **Discrete bound** (``elastic-bound``, exact): β_h^el >= β_h^mem / sqrt(2μ̂ + λ̂) on every
  row with no kernel (:mod:`infsup_contact.study.beta.elastic`); the elastic and membrane
  energies are equivalent with ν-dependent constants (this bound and Korn's inequality), so
  β_h^el is bounded away from 0 iff β_h^mem is, at every fixed ν < 1/2.
* Hence **the paper's verdicts carry over**: T3, T4, T5, DUAL (and the user space) bounded
  (``elastic-<tag>-k<k>-<family>``), R5.2 / DUAL-ALL 2 and R5.4 1 zero modes on matching
  meshes (``elastic-<tag>-<family>``), and on non-matching meshes the elastic series gets the
  membranes' verdict (``elastic-nonmatching-<case>-k<k>-<family>``).
* **ν → 1/2** (``elastic-nu<ν>-…``, ``elastic-nu-scaling-…``): a clamped body cannot change
  volume for free and ∫_Γ v·n = ∫_Ω div v, so a multiplier with nonzero mean (every space has
  one) costs λ̂ ~ 1/(1 − 2ν): its Rayleigh quotient is ~ (1 − 2ν), which makes it the smallest
  one near 1/2, and it does not depend on h. Prediction: β_h ∝ (1 − 2ν)^{1/2} (slope 1/2 ± τ
  of log β_h vs log(1 − 2ν) over ν >= 0.49 on the finest mesh), kernels unchanged, and every
  stable space stays bounded in h at every ν of the sweep, for k = 1 as for k = 2: the locking
  of P_1 raises the cost of the zero-mean modes, but the volume mode is already the cheapest,
  so locking changes the value of β_h (through that mode) and not the verdict.
"""
from __future__ import annotations

import pandas as pd

from ...discretization.spaces.registry import SPACES
from ...criteria.claims import (FAIL, INCONCLUSIVE, PASS, bounded_claim, close_decisions, close_text, finest, kernel_claim,
                     predicted_kernel, row, slope_verdict)
from .tolerance import within

REF = "beyond the paper (its Section 2: elastic bodies)"
PASS_RTOL = 1e-10
"""The patch test's bound: the table's ``passes`` is both errors below it (``PASS_RTOL`` of
:mod:`infsup_contact.study.patch.segment`, not imported: that module loads NGSolve)."""


def _bound_check(frame: pd.DataFrame, rtol: float = 1e-8):
    rows = frame[frame.kernel_dim_membranes == 0]
    margin = rows.beta - rows.beta_membranes * rows.bound_factor * (1 - rtol)
    ratio = rows.beta / rows.beta_membranes
    return (PASS if len(rows) and (margin >= 0).all() else FAIL), (
        f"{len(rows)} rows without kernel; min β_el − β_mem/sqrt(2μ+λ) = {margin.min():.3g}; "
        f"β_el/β_mem in [{ratio.min():.3g}, {ratio.max():.3g}]")


def _kernel_check(frame: pd.DataFrame):
    same = frame.kernel_dim == frame.kernel_dim_membranes
    text = (f"{int(same.sum())}/{len(frame)} rows with equal kernel dimension; elastic kernel dims "
            f"{sorted(set(frame.kernel_dim.astype(int).tolist()))}")
    # either model's kernel decision is close: the comparison rests on both
    close = frame.loc[close_decisions(frame).index.union(close_decisions(frame, "kernel_decision_membranes").index)]
    if len(close):
        return INCONCLUSIVE, f"{text}; {close_text(close)}"
    return (PASS if same.all() else FAIL), text


def elastic_claims(beta: pd.DataFrame, sweep: pd.DataFrame, cfg: dict) -> pd.DataFrame:
    """The elastic claims from the ν = ν0 table ``beta`` and the ν sweep ``sweep``."""
    tol, floor, conf, win = cfg["slope_tolerance"], cfg["beta_floor"], cfg["confidence"], cfg["fit_window"]
    both = pd.concat([beta, sweep], ignore_index=True)
    out = [row("elastic-kernel-as-membranes", REF, "plane strain: the kernel of B A⁻¹ Bᵀ has the membranes' "
               "dimension on every mesh pair, case, k and ν (b sees the normal traces only)", _kernel_check(both)),
           row("elastic-bound", REF, "β_h(elastic) >= β_h(membranes, c = E) / sqrt(2μ + λ) (Lame parameters at E = 1) on every "
               "row without kernel (v = (0, w))", _bound_check(both))]
    h = beta[beta.norm == "H"]
    matching, nonmatching = h[h.N1 == h.N2], h[h.N1 != h.N2]
    for fam, fb in matching.groupby("family", sort=False):
        for case, rc in fb.groupby("case", sort=False):
            spec = SPACES.get(case)
            if spec is None:
                continue
            if spec.stable:
                for k, rk in rc.groupby("k"):
                    out.append(row(f"elastic-{spec.tag}-k{k}-{fam}", REF,
                                   f"elastic, ν={rk.nu.iloc[0]:g}, {case}, k={k}, {fam}: β_h bounded away from 0",
                                   bounded_claim(finest(rk, win), tol, floor, conf)))
            elif spec.expected == "unstable" and spec.dimension is not None:
                dim = predicted_kernel(spec, rc)
                out.append(row(f"elastic-{spec.tag}-{fam}", REF,
                               f"elastic, {case}, {fam}, matching: β_h = 0 with a {dim}-dimensional kernel",
                               kernel_claim(rc, dim)))
    for (fam, case, k), rk in nonmatching.groupby(["family", "case", "k"], sort=False):
        rk = finest(rk, win)
        if len(rk) < 3:
            continue
        el = bounded_claim(rk, tol, floor, conf)
        mem = bounded_claim(rk.assign(beta=rk.beta_membranes), tol, floor, conf)
        ratio = f"{rk.N1.iloc[0]}:{rk.N2.iloc[0]}"
        out.append(row(f"elastic-nonmatching-{case}-k{k}-{fam}", REF,
                       f"elastic, {case}, k={k}, {fam}, non-matching {ratio}, G_h = trace of Ω2: the "
                       "membranes' verdict on 'β_h bounded away from 0'",
                       (PASS if el[0] == mem[0] else FAIL, f"elastic {el[0]} ({el[1]}); membranes {mem[0]}")))
    for nu, sn in sweep.groupby("nu"):
        for case, rc in sn.groupby("case", sort=False):
            spec = SPACES.get(case)
            for k, rk in rc.groupby("k"):
                if spec is not None and spec.stable:
                    out.append(row(f"elastic-nu{nu:g}-{spec.tag}-k{k}", REF,
                                   f"elastic, ν={nu:g}, {case}, k={k}, structured: β_h bounded away from 0",
                                   bounded_claim(finest(rk, win), tol, floor, conf)))
    near = sweep[sweep.nu >= 0.49]
    for (case, k), rc in near.groupby(["case", "k"], sort=False):
        spec = SPACES.get(case)
        if spec is None or not spec.stable or rc.nu.nunique() < 3:
            continue
        rn = rc[rc.N2 == rc.N2.max()].sort_values("nu")
        x = 1.0 - 2.0 * rn.nu.to_numpy(float)
        out.append(row(f"elastic-nu-scaling-{spec.tag}-k{k}", REF,
                       f"elastic, {case}, k={k}, N={int(rn.N2.iloc[0])}: β_h ∝ (1 − 2ν)^(1/2) as ν → 1/2 "
                       "(the volume mode)", _scaling(x, rn.beta.to_numpy(float), tol, conf)))
    return pd.DataFrame(out)


def _scaling(x, beta, tol, conf):
    verdict, text = slope_verdict(x, beta, 0.5, tol, conf)
    vals = ", ".join(f"{b:.4g}" for b in beta)
    return verdict, f"β_h = {vals} at 1 − 2ν = " + ", ".join(f"{v:g}" for v in x) + f"; {text}"



def patch_claims(patch: pd.DataFrame) -> pd.DataFrame:
    """Patch-test claims (:mod:`infsup_contact.study.patch.segment`): per case and k, λ_h = p and u_h = u
    to 1e-10 on every pair (predicted iff 1 ∈ M_h: every case but T3); T3's error confined to
    a boundary layer (the middle-half error falls ≥ 10x when the pair is refined at a fixed
    ratio, the end-interval error stays 1)."""
    out = []
    for (case, k), rc in patch.groupby(["case", "k"], sort=False):
        spec = SPACES.get(case)
        tag = spec.tag if spec is not None else case
        ok = bool(rc.passes.astype(bool).all())
        pairs = " ".join(f"{a}:{b}" for a, b in zip(rc.N1, rc.N2))
        out.append(row(f"elastic-patch-{tag}-k{k}", REF,
                       f"patch test, {case}, k={k}: λ_h = p and u_h = u to 1e-10 relative on {pairs}",
                       (PASS if ok else FAIL, _patch_text(rc, ok)),
                       predicted=_patch_prediction(spec, k)))
    lacking = [c for c, k in zip(patch.case, patch.k) if _patch_prediction(SPACES.get(c), k) == FAIL]
    t3 = patch[patch.case.isin(lacking)].assign(ratio=lambda f: (f.N1 / f.N2).round(9))
    for (case, k, ratio), rc in t3.groupby(["case", "k", "ratio"]):
        if len(rc) < 2:
            continue
        rc = rc.sort_values("N2")
        first, last = rc.iloc[0], rc.iloc[-1]
        ok = last.lambda_middle_rel_error <= first.lambda_middle_rel_error / 10 and \
            (rc.lambda_end_rel_error > 0.5).all()
        out.append(row(f"elastic-patch-{case}-layer-k{k}-{int(first.N1)}to{int(first.N2)}", REF,
                       f"patch test, {case}, k={k}, ratio {int(first.N1)}:{int(first.N2)}: the error is a boundary "
                       "layer at Γ's ends (middle-half error falls >= 10x under refinement, end error stays O(1))",
                       (PASS if ok else FAIL,
                        "middle half " + ", ".join(f"{v:.3g}" for v in rc.lambda_middle_rel_error)
                        + "; end intervals " + ", ".join(f"{v:.3g}" for v in rc.lambda_end_rel_error)
                        + " at N2 = " + ", ".join(str(int(n)) for n in rc.N2)),
                       predicted="finding"))  # found after the run (the prediction said: end intervals only)
    return pd.DataFrame(out)


def _patch_text(rc: pd.DataFrame, ok: bool) -> str:
    """The patch claim's evidence: where every pair passes, its errors are round-off, stated against
    :data:`PASS_RTOL` (:func:`.tolerance.within`); where not, the errors themselves (end intervals
    and middle half say where the error sits)."""
    dims = f"kernel dims {sorted(set(rc.kernel_dim.astype(int).tolist()))}"
    if ok:
        return (f"{within('max |λ_h − p|/p (end intervals and middle half alike)', rc.lambda_max_rel_error.max(), PASS_RTOL)}"
                f"; {within('max |u_h − u|/δ', rc.u_max_rel_error.max(), PASS_RTOL)}; {dims}")
    return (f"max |λ_h − p|/p = {rc.lambda_max_rel_error.max():.3g}, end intervals "
            f"{rc.lambda_end_rel_error.max():.3g}, middle half {rc.lambda_middle_rel_error.max():.3g}; "
            f"max |u_h − u|/δ = {rc.u_max_rel_error.max():.3g}; {dims}")


def _patch_prediction(spec, k: int) -> str:
    """PASS where 1 ∈ M_h (a uniform pressure is in the space: the discrete solution is exact,
    study/patch/segment.py), FAIL where it is not; a space outside the registry is predicted to pass."""
    return FAIL if spec is not None and not spec.contains_constants(k) else PASS


def hertz_claims(hertz: pd.DataFrame) -> pd.DataFrame:
    """Hertz-scene claims (:mod:`infsup_contact.study.contact.hertz`): the modeling error against
    plane-strain Hertz (max pressure) falls as the contact zone shrinks relative to the domain
    (predicted); per case and k the fitted energy-error rate and the oscillation of λ_h
    (findings: no prediction of their values was stated)."""
    import numpy as np

    out = []
    mod = hertz[hertz.study == "modeling"].sort_values("d")
    if len(mod) >= 2:
        err = mod.p_max_rel_error.to_numpy(float)
        a = (mod.hertz_a if "hertz_a" in mod else mod.half_width).to_numpy(float)
        ok = bool(np.all(np.diff(err) > 0))
        out.append(row("elastic-hertz-modeling-trend", REF,
                       "Hertz scene: the max-pressure error against plane-strain Hertz (for the measured P) "
                       "decreases as a/W decreases (finest mesh, T3, k=2)",
                       (PASS if ok else FAIL, "p_max error " + ", ".join(f"{e:.3g}" for e in err)
                        + " at a/W = " + ", ".join(f"{v:.3g}" for v in a))))
    disc = hertz[hertz.study == "discretization"]
    for (case, k), rc in disc.groupby(["case", "k"], sort=False):
        rc = rc.sort_values("N")
        if len(rc) < 2:
            continue
        slope = np.polyfit(np.log(1.0 / rc.N.to_numpy(float)), np.log(rc.energy_error.to_numpy(float)), 1)[0]
        spec = SPACES.get(case)
        tag = spec.tag if spec is not None else case
        out.append(row(f"elastic-hertz-{tag}-k{k}", REF,
                       f"Hertz scene, {case}, k={k}: energy error vs the fine-mesh solution converges "
                       "(fitted slope > 0)",
                       (PASS if slope > 0 else FAIL,
                        f"energy slope {slope:.2f} over N = {', '.join(str(int(n)) for n in rc.N)}; "
                        "oscillation " + ", ".join(f"{v:.3g}" for v in rc.oscillation)
                        + "; p_max error " + ", ".join(f"{v:.3g}" for v in rc.p_max_rel_error)),
                       predicted="finding"))
    return pd.DataFrame(out)
