"""The claims ledger: each claim of the paper (and each finding beyond it) gets a verdict
from data, by one documented criterion per kind of claim.

Criteria
--------
slope claims
    Fit log y = s log h + c by least squares (``scipy.stats.linregress``) and form the
    two-sided ``confidence`` interval of s with Student's t. For a predicted slope s0
    (0 for "β_h bounded away from zero", 1/2 for Remark 3.1, the expected rate for
    convergence) the verdict is PASS if the interval lies inside [s0 − τ, s0 + τ], FAIL if it
    does not meet that band, INCONCLUSIVE otherwise. τ is one number for all claims
    (config ``claims.slope_tolerance``; ``rate_tolerance`` for convergence rates).
    A bounded claim also needs min β_h > ``beta_floor``.
kernel claims
    Exact integers: the kernel dimension (its proven part plus the zero modes decided from
    Bᵀ, :data:`infsup_contact.solvers.kernel.KERNEL_CRITERION`) equals the paper's dimension
    count on every matching mesh pair. A row whose decision sits within
    :data:`~infsup_contact.solvers.kernel.MARGIN_DECADES` of the error level
    (``kernel_decision == "close"``) makes the claim INCONCLUSIVE: the rounding of one BLAS
    kernel must not decide it.
comparison claims
    An inequality checked on every pair of rows it applies to, up to 1e-8 relative.
rate claims
    The fitted energy-error slope is at least the rate the solution's regularity allows,
    minus ``rate_tolerance`` (the regularity gives an upper bound on the error).
"""
from __future__ import annotations

import re

import numpy as np
import pandas as pd
from scipy import stats

from ..discretization.spaces.registry import PAPER_CASES, SIGN_CHECK_SPACE, SPACES
from ..solvers.kernel import CLOSE

PASS, FAIL, INCONCLUSIVE = "PASS", "FAIL", "INCONCLUSIVE"
BEYOND = "beyond the paper"
"""paper_ref of every row the paper does not state: findings (no prediction) and predicted
claims about spaces it does not treat ("beyond the paper (Wohlmuth 2000)")."""
COLUMNS = ["claim_id", "paper_ref", "statement", "evidence", "verdict", "predicted"]


def slope_interval(h, y, confidence: float = 0.95):
    """(slope, lower, upper) of log y vs log h; the interval is ±t·stderr (n − 2 dof)."""
    h, y = np.asarray(h, float), np.asarray(y, float)
    if np.ptp(np.log(y)) <= 1e-12 * np.abs(np.log(y)).max():  # constant: exact zero slope
        return 0.0, 0.0, 0.0
    res = stats.linregress(np.log(h), np.log(y))
    if len(h) < 3:
        return res.slope, -np.inf, np.inf
    half = stats.t.ppf(0.5 + confidence / 2, len(h) - 2) * res.stderr
    return float(res.slope), float(res.slope - half), float(res.slope + half)


def slope_verdict(h, y, s0: float, tol: float, confidence: float = 0.95):
    """PASS / FAIL / INCONCLUSIVE for "log y has slope s0 in log h" and a text of the fit."""
    if len(h) < 2 or np.any(np.asarray(y) <= 0):
        return INCONCLUSIVE, f"not enough positive data ({len(h)} points)"
    s, lo, hi = slope_interval(h, y, confidence)
    if s0 - tol <= lo and hi <= s0 + tol:
        verdict = PASS
    elif hi < s0 - tol or lo > s0 + tol:
        verdict = FAIL
    else:
        verdict = INCONCLUSIVE
    return verdict, f"slope {s:.3f}, {int(confidence * 100)}% CI [{lo:.3f}, {hi:.3f}] vs {s0:g}±{tol:g}"


def finest(rows: pd.DataFrame, window: int) -> pd.DataFrame:
    """The ``window`` finest meshes of a series (the asymptotic claim is about h → 0): the
    rows of the ``window`` largest distinct N2, every seed of each (perturbed meshes)."""
    ns = sorted(set(rows.N2.tolist()))[-window:]
    return rows[rows.N2.isin(ns)].sort_values("N2", kind="stable")


def bounded_claim(rows: pd.DataFrame, tol: float, floor: float, confidence: float):
    """β_h bounded away from zero over a mesh series (rows of one case/k/family/norm)."""
    rows = rows.sort_values("N2")
    h, beta = 1.0 / rows.N2.to_numpy(float), rows.beta.to_numpy(float)
    if beta.min() <= floor:
        return FAIL, f"min β_h = {beta.min():.3g} <= floor {floor:g}"
    verdict, text = slope_verdict(h, beta, 0.0, tol, confidence)
    return verdict, f"β_h in [{beta.min():.4f}, {beta.max():.4f}] over N = {_ns(rows)}{_seeds(rows)}; {text}"


def predicted_kernel(spec, rows: pd.DataFrame):
    """The registry's structural kernel count for a series of matching rows: one integer when
    it is the same on every row (the paper's R5.2: 2, R5.4: 1), else an array per row."""
    dims = np.array([spec.structural_kernel(int(k), int(n)) for k, n in zip(rows.k, rows.N2)])
    return int(dims[0]) if len(set(dims.tolist())) == 1 else dims


def close_decisions(rows: pd.DataFrame, column: str = "kernel_decision") -> pd.DataFrame:
    """The rows whose kernel decision (``column``) is ``close`` (within MARGIN_DECADES of the
    error level); none for tables without the column (rows computed before it existed)."""
    if column not in rows.columns:
        return rows.iloc[:0]
    return rows[rows[column] == CLOSE]


def close_text(close: pd.DataFrame) -> str:
    margins = close.kernel_margin_decades.to_numpy(float) if "kernel_margin_decades" in close else []
    return (f"{len(close)} row(s) with a kernel decision closer than the stated margin to the error level "
            f"(N = {_ns(close)}; margins {', '.join(f'{m:.2f}' for m in margins[:4])} decades)")


def kernel_claim(rows: pd.DataFrame, expected):
    """The kernel dimension equals ``expected`` on every row (INCONCLUSIVE where a row's
    decision is close)."""
    dims = rows.kernel_dim.to_numpy(int)
    ok = len(dims) > 0 and np.all(dims == expected) and np.all(rows.structural_kernel_dim == expected)
    above = rows.smallest_nonzero.to_numpy(float)
    text = (f"kernel dims {sorted(set(dims.tolist()))} (predicted {expected}) on {len(dims)} mesh pairs; "
            f"eigenvalue above the kernel: sqrt in [{above.min():.3g}, {above.max():.3g}]")
    close = close_decisions(rows)
    if len(close):
        return INCONCLUSIVE, f"{text}; {close_text(close)}"
    return (PASS if ok else FAIL), text


def sufficiency_claim(beta: pd.DataFrame, atol: float = 1e-6):
    """(5.10) is sufficient: β_h >= β_h restricted to v = (0, v2), on every row (up to the
    round-off floor of a β that is 0: sqrt of 1e-16 relative eigenvalue noise)."""
    gap = beta.beta - beta.beta_v1_zero
    return (PASS if (gap >= -atol).all() else FAIL), (
        f"{len(beta)} rows; min β_h − β_h(v1 = 0) = {gap.min():.3g}")


def nonmatching_claim(beta: pd.DataFrame, finer: bool, families=None, rtol: float = 1e-8, series=None):
    """With Ω2 and G_h = trace of Ω2 fixed, β_h(N1, N2) >= β_h(N2, N2), for N1 > N2 (finer Ω1)
    or N1 < N2 (coarser Ω1), on the given families (all by default) and non-matching
    ``series`` (all by default; matching partners come from every series)."""
    keys = ["family", "k", "case", "norm", "multiplier_mesh", "c1", "c2", "seed"]
    b = beta[beta.multiplier_mesh == "omega2"]
    b = b.assign(seed=b.seed.fillna(-1) if "seed" in b.columns else -1)
    if "series" in b.columns:  # a pair of two series once
        b = b.drop_duplicates(subset=[c for c in b.columns if c != "series"])
    if families is not None:
        b = b[b.family.isin(families)]
    match = b[b.N1 == b.N2][keys + ["N2", "beta"]].rename(columns={"beta": "beta_matching"})
    side = b[(b.N1 > b.N2) if finer else (b.N1 < b.N2)]
    if series is not None:
        side = side[side.series == series] if "series" in side.columns else side.iloc[:0]
    pairs = side[keys + ["N2", "beta"]].merge(match, on=keys + ["N2"], how="inner")
    count = len(pairs)
    worst = float(np.nanmin(pairs.beta - pairs.beta_matching * (1 - rtol), initial=np.inf))
    if count == 0:
        return INCONCLUSIVE, "no non-matching pair with a matching partner in the table"
    return (PASS if worst >= 0 else FAIL), f"{count} comparisons; min β(N1≠N2) − β(N2=N1) = {worst:.3g}"


def _ns(rows) -> str:
    return ",".join(str(n) for n in sorted(set(rows.N2.astype(int))))


def _seeds(rows) -> str:
    """`` (3 seeds pooled, 15 points)`` for rows of several perturbed seeds, else empty."""
    if "seed" not in rows.columns or rows.seed.nunique() < 2:
        return ""
    return f" ({rows.seed.nunique()} seeds pooled, {len(rows)} points)"


def row(claim_id, paper_ref, statement, verdict_evidence, predicted=PASS) -> dict:
    verdict, evidence = verdict_evidence
    return dict(claim_id=claim_id, paper_ref=paper_ref, statement=statement, evidence=evidence,
                verdict=verdict, predicted=predicted)


def sign_check(k: int = 2, n: int = 32, c=(1.0, 3.0), case: str = SIGN_CHECK_SPACE) -> dict:
    """Eq. (3.13) erratum: compare λ_h with ∓c_i ∂u_{i,h}/∂x2 on Γ (membranes scene, whose
    multiplier is O(1); in the manufactured scene λ is small against ∇u and the comparison
    would measure the boundary-gradient error instead of the sign).

    With b(v, μ) = ∫_Γ (v2 − v1) μ and a(u, v) − b(v, λ) = (f, v), integrating by parts gives
    λ = −c1 ∂u1/∂x2 = −c2 ∂u2/∂x2; (3.13) prints +c_i ∂u_i/∂x2. Returns the relative
    L²(Γ) mismatch of both signs for both sides (the y-derivative is ``grad(gf)[1]``).
    """
    import ngsolve

    from ..solvers.contact import lambda_values, solve_contact
    from .scenes import membranes

    sol = solve_contact(membranes(c1=c[0], c2=c[1]), case, k, "structured", n, n, time_floor=False)
    x = (np.arange(400) + 0.5) / 400
    lam = lambda_values(sol, x)
    out = {}
    for i, (gf, side, ci) in enumerate(zip(sol.u, sol.sides, c), start=1):
        mesh = side.trace.fes.mesh
        dy = np.array([ngsolve.grad(gf)[1](mesh(xi, 1.0)) for xi in x])
        scale = np.linalg.norm(lam)
        out[f"minus_c{i}"] = float(np.linalg.norm(lam + ci * dy) / scale)
        out[f"plus_c{i}"] = float(np.linalg.norm(lam - ci * dy) / scale)
    return out


REM55_INSTANCES = (
    # (id, statement, displacement k, space spec (label, s, continuous, vanish), stable?)
    ("Rem5.5-shrink-M", "shrinking M_h keeps stability: M^1_{0,k-1} ⊂ M^1_{0,k} (T3) with V_h^k, k=2",
     2, ("M1_0,1", 1, True, True), True),
    ("Rem5.5-enlarge-W", "enlarging W_h keeps stability: T5's M^1_{1} with V_h^3 instead of V_h^2",
     3, ("M1_1", 1, True, False), True),
    ("Rem5.5-enlarge-M-unstable", "enlarging M_h of an unstable pair keeps it unstable: "
     "M^0_2 ⊃ M^0_1 (R5.4) with V_h^2", 2, ("M0_2", 2, False, False), False),
)


def ledger(beta: pd.DataFrame, rates: pd.DataFrame, extra: pd.DataFrame, cfg: dict,
           rate_scene: str) -> pd.DataFrame:
    """All claims as one table (see the module docstring for the criteria); the energy rates
    of the contact scene ``rate_scene`` (config ``contact.primary_scene``) are claimed."""
    tol, floor, conf, win = cfg["slope_tolerance"], cfg["beta_floor"], cfg["confidence"], cfg["fit_window"]
    rows = []
    b = beta[(beta.multiplier_mesh == "omega2") & (beta.N1 == beta.N2)]
    first_c = b[["c1", "c2"]].iloc[0].tolist() if len(b) else [1.0, 1.0]
    b = b[(b.c1 == first_c[0]) & (b.c2 == first_c[1])]
    stable = [s for s in SPACES.values() if s.stable]

    def ref_of(spec, ref):  # a claim about a space the paper does not treat is beyond the paper
        return ref if spec.id in PAPER_CASES else f"{BEYOND} ({ref})"

    unstable = [s for s in SPACES.values() if s.expected == "unstable" and s.dimension is not None]
    for fam, fb in b.groupby("family", sort=False):
        for spec in stable:
            case, ref = spec.id, ref_of(spec, spec.paper_ref)
            for k, rk in fb[(fb.case == case) & (fb.norm == "H")].groupby("k"):
                series = {"even N": rk[rk.N2 % 2 == 0], "odd N": rk[rk.N2 % 2 == 1]}
                for label, rs in series.items():
                    rs = finest(rs, win)
                    if len(rs) >= 3:
                        rows.append(row(f"{spec.tag}-k{k}-{fam}-{label.replace(' ', '')}", ref,
                                        f"{case}, k={k}, {fam}, {label}: β_h bounded away from 0 (H^-1/2_00 norm)",
                                        bounded_claim(rs, tol, floor, conf)))
        for spec in unstable:
            case, ref = spec.id, ref_of(spec, spec.paper_ref)
            rc = fb[fb.case == case]
            if len(rc):
                dim = predicted_kernel(spec, rc)
                rows.append(row(f"{spec.tag}-{fam}", ref,
                                f"{case}, {fam}, matching meshes: β_h = 0 with a {dim}-dimensional kernel "
                                f"(dim M − dim W = {dim})", kernel_claim(rc, dim)))
        for spec in stable:
            case = spec.id
            for k, rk in fb[(fb.case == case) & (fb.norm == "L2")].groupby("k"):
                rk = finest(rk[rk.N2 % 2 == 0], win)
                if len(rk) >= 3:
                    v, text = slope_verdict(1 / rk.N2.to_numpy(float), rk.beta.to_numpy(float), 0.5, tol, conf)
                    rows.append(row(f"Rem3.1-{case}-k{k}-{fam}", ref_of(spec, "Rem 3.1"),
                                    f"{case}, k={k}, {fam}: in the L²(Γ) norm β_h decays like h^(1/2)",
                                    (v, f"over N = {_ns(rk)}{_seeds(rk)}; {text}")))
    rows += findings(beta, cfg)
    rows.append(row("eq5.10-sufficient", "(5.10)",
                    "the Ω2-only condition (5.10) is sufficient: β_h >= the inf-sup constant with v1 = 0",
                    sufficiency_claim(beta)))
    rows += worst_case_claims(beta)
    for _, e in extra.iterrows():
        rows.append(row(e.claim_id, e.paper_ref, e.statement, (e.verdict, e.evidence), e.predicted))
    if rates is not None and len(rates):
        r = rates[(rates.scene == rate_scene) & (rates.measure == "energy_error") & (rates.family == "structured")]
        for _, rr in r[r.case.isin([s.id for s in stable])].iterrows():
            # the regularity bound is an upper bound on the error: a faster observed rate
            # (pre-asymptotic, e.g. the small kink term at x = a for k = 3) is consistent with it
            ok = rr.slope >= rr.expected - cfg["rate_tolerance"]
            note = "; faster than the bound (pre-asymptotic)" if rr.slope > rr.expected + cfg["rate_tolerance"] else ""
            rows.append(row(f"rate-{rr.case}-k{int(rr.k)}", "(4.8)",
                            f"{rr.case}, k={int(rr.k)}: energy error converges at least at the rate "
                            f"min(k, r−1) = {rr.expected:g} the regularity allows ({rate_scene}, structured)",
                            (PASS if ok else FAIL,
                             f"slope {rr.slope:.3f} ± {rr.stderr:.3f} over {int(rr.points)} finest meshes, "
                             f"h_min = {rr.h_min:.4g}; tolerance {cfg['rate_tolerance']}{note}")))
    return pd.DataFrame(rows, columns=COLUMNS)


def worst_case_claims(beta: pd.DataFrame) -> list:
    """The paper's "matching meshes are the worst case" (§5 before (5.10)): for a fixed Ω2
    mesh and G_h = trace of Ω2, β_h(N1, N2) >= β_h(N2, N2); one claim per non-matching series
    and mesh family. The paper's own claim is the structured fixed-ratio series (where Ω1's
    trace pattern repeats); the families N1 = N2 + 1 and N1 = round(√2 N2), the perturbed and
    unstructured meshes and a coarser Ω1 are findings."""
    from ..discretization.gamma.mesh_series import describe

    rows = []
    nm = beta[beta.N1 != beta.N2]
    for series in nonmatching_series(beta):
        s = nm[nm.series == series] if "series" in nm.columns else nm
        finer = bool((s.N1 > s.N2).all())
        what = "finer" if finer else "coarser"
        for fam in sorted(set(s.family), key=lambda f: (f != "structured", f)):
            paper = finer and fam == "structured" and series.startswith("ratio")
            cid = (f"eq5.10-matching-worst-{what}-omega1-{series}" if paper
                   else f"finding-matching-worst-{what}-omega1-{series}-{fam}")
            rows.append(row(cid, "§5 before (5.10)" if paper else "beyond the paper",
                            f"{fam} meshes, non-matching {describe(series)} (Ω1 {what}): for a fixed Ω2 mesh "
                            "and G_h = trace of Ω2, β_h is >= the matching value (matching is the worst case)",
                            nonmatching_claim(beta, finer=finer, families=[fam], series=series),
                            predicted=PASS if paper else "finding"))
    return rows


NONMATCHING_ID = re.compile(r"^finding-(?P<series>ratio\d+-\d+|plus1|sqrt2)-(?P<case>.+)-(?P<mm>omega2|omega1|union)"
                            r"-k(?P<k>[1-4])-(?P<family>structured|perturbed|unstructured)$")
"""The id of a bounded claim of :func:`findings` on a non-matching series."""


def nonmatching_claims(claims: pd.DataFrame) -> pd.DataFrame:
    """The non-matching bounded claims of a ledger with their series, case, multiplier mesh
    (``mm``), k and family parsed from the id (:data:`NONMATCHING_ID`)."""
    parts = claims.claim_id.astype(str).str.extract(NONMATCHING_ID)
    sel = parts.series.notna()
    out = pd.concat([claims[sel], parts[sel]], axis=1)
    return out.assign(k=out.k.astype(int)) if len(out) else out.assign(k=pd.Series(dtype=int))


MM_TEXT = {"omega2": "G_h = trace of Ω2", "omega1": "G_h = trace of Ω1",
           "union": "G_h = common refinement of both traces"}


def nonmatching_series(beta: pd.DataFrame) -> list:
    """The non-matching series of a β table (column ``series``; without it, pairs grouped by
    their reduced ratio as ``ratio3-2``), in order of appearance."""
    from ..discretization.gamma.mesh_series import ratio_series

    nm = beta[beta.N1 != beta.N2]
    if "series" not in nm.columns:
        return [] if nm.empty else list(dict.fromkeys(ratio_series(a, b) for a, b in zip(nm.N1, nm.N2)))
    return [s for s in dict.fromkeys(nm.series) if s != "matching"]


def findings(beta: pd.DataFrame, cfg: dict) -> list:
    """What the paper does not say but the tables show: on every non-matching series
    (a fixed ratio such as 3:2, or a family N1 = N2 + 1, N1 = round(√2 N2):
    :mod:`infsup_contact.discretization.gamma.mesh_series`), for every mesh family, multiplier mesh,
    case and k, "β_h bounded away from 0" by :func:`bounded_claim` over the series' finest
    meshes (every seed). One claim per series: a statement that holds on one series and not
    on another shows as two rows with different verdicts."""
    from ..discretization.gamma.mesh_series import describe, ratio_series

    tol, floor, conf, win = cfg["slope_tolerance"], cfg["beta_floor"], cfg["confidence"], cfg["fit_window"]
    rows = []
    c1, c2 = beta[["c1", "c2"]].iloc[0].tolist()
    nm = beta[(beta.N1 != beta.N2) & (beta.norm == "H") & (beta.c1 == c1) & (beta.c2 == c2)]
    if "series" not in nm.columns:
        nm = nm.assign(series=[ratio_series(a, b) for a, b in zip(nm.N1, nm.N2)])
    for series in nonmatching_series(beta):
        ns = nm[nm.series == series]
        for (fam, mm, case, k), r in ns.groupby(["family", "multiplier_mesh", "case", "k"], sort=False):
            if r.N2.nunique() < 3 or case not in SPACES:
                continue
            rows.append(row(f"finding-{series}-{case}-{mm}-k{k}-{fam}", "beyond the paper",
                            f"{case}, k={k}, {fam}, non-matching {describe(series)}, {MM_TEXT[mm]}: "
                            "β_h bounded away from 0", bounded_claim(finest(r, win), tol, floor, conf),
                            predicted="finding"))
    return rows


def extra_claims(cfg: dict) -> pd.DataFrame:
    """Claims that need their own small computation: the (3.13) sign and Rem 5.5 instances."""
    from ..solvers.infsup import beta_rows

    tol, floor, conf = cfg["slope_tolerance"], cfg["beta_floor"], cfg["confidence"]
    s = sign_check()
    ok = max(s["minus_c1"], s["minus_c2"]) < 0.1 and min(s["plus_c1"], s["plus_c2"]) > 1.5
    rows = [row("eq3.13-sign", "(3.13) erratum",
                "with b(v,μ) = ∫(v2 − v1)μ, λ = −c1 ∂u1/∂x2 = −c2 ∂u2/∂x2 on Γ (the paper prints +)",
                (PASS if ok else FAIL,
                 "relative L²(Γ) mismatch of λ_h vs −c_i∂u_ih/∂x2: "
                 f"{s['minus_c1']:.3g} (i=1), {s['minus_c2']:.3g} (i=2); vs +c_i∂u_ih/∂x2: "
                 f"{s['plus_c1']:.3g}, {s['plus_c2']:.3g} (membranes, T5, k=2, N=32, c=(1,3))"))]
    for cid, statement, k, spec, stable in REM55_INSTANCES:
        frame = pd.DataFrame([r for n in cfg["rem55_N"]
                              for r in beta_rows("structured", k, n, n, [spec], norms=["H"])])
        verdict = bounded_claim(frame, tol, floor, conf) if stable else kernel_at_least(frame, 1)
        rows.append(row(cid, "Rem 5.5", statement, verdict))
    return pd.DataFrame(rows, columns=COLUMNS)


def kernel_at_least(rows: pd.DataFrame, n: int):
    """β_h = 0: a kernel of dimension >= n on every mesh (INCONCLUSIVE where a decision is close)."""
    dims = rows.kernel_dim.to_numpy(int)
    text = f"kernel dims {dims.tolist()} over N = {_ns(rows)}"
    close = close_decisions(rows)
    if len(close):
        return INCONCLUSIVE, f"{text}; {close_text(close)}"
    return (PASS if np.all(dims >= n) else FAIL), text
