"""The claims engine's criteria: each claim of the paper (and each finding beyond it), for
every model, gets a verdict from data by one documented criterion per kind of claim.

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
not run
    A claim whose computation needs an optional code that is not installed where the ledger
    was built (a producer, study/producers.py) keeps its prediction and gets the verdict
    NOT RUN, its evidence naming the install command: neither PASS nor FAIL, and not
    INCONCLUSIVE either (nothing was computed). The gate lists such claims without judging them.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from ..solvers.kernel import CLOSE

PASS, FAIL, INCONCLUSIVE = "PASS", "FAIL", "INCONCLUSIVE"
NOT_RUN = "NOT RUN"
"""The verdict of a claim that was not computed: an optional code it needs is not installed."""
FINDING = "finding"
"""``predicted`` of a row no prediction was stated for (what the tables show)."""
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
    return verdict, f"β_h in [{beta.min():.4f}, {beta.max():.4f}] over N = {ns_text(rows)}{seeds_text(rows)}; {text}"


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
            f"(N = {ns_text(close)}; margins {', '.join(f'{m:.2f}' for m in margins[:4])} decades)")


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


def ns_text(rows) -> str:
    return ",".join(str(n) for n in sorted(set(rows.N2.astype(int))))


def seeds_text(rows) -> str:
    """`` (3 seeds pooled, 15 points)`` for rows of several perturbed seeds, else empty."""
    if "seed" not in rows.columns or rows.seed.nunique() < 2:
        return ""
    return f" ({rows.seed.nunique()} seeds pooled, {len(rows)} points)"


def row(claim_id, paper_ref, statement, verdict_evidence, predicted=PASS) -> dict:
    verdict, evidence = verdict_evidence
    return dict(claim_id=claim_id, paper_ref=paper_ref, statement=statement, evidence=evidence,
                verdict=verdict, predicted=predicted)


def kernel_at_least(rows: pd.DataFrame, n: int):
    """β_h = 0: a kernel of dimension >= n on every mesh (INCONCLUSIVE where a decision is close)."""
    dims = rows.kernel_dim.to_numpy(int)
    text = f"kernel dims {dims.tolist()} over N = {ns_text(rows)}"
    close = close_decisions(rows)
    if len(close):
        return INCONCLUSIVE, f"{text}; {close_text(close)}"
    return (PASS if np.all(dims >= n) else FAIL), text
