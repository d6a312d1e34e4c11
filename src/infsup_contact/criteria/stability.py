"""The stability verdict of one space over a mesh sequence: STABLE, UNSTABLE or INCONCLUSIVE.

A kernel (β_h = 0 on a mesh, the dimension count or decided from Bᵀ) is UNSTABLE; a decision
closer than its margin to the error level is INCONCLUSIVE; otherwise the ledger's claim "β_h
bounded away from 0" (:func:`.claims.bounded_claim`: min β_h above the floor and the slope's
interval inside [−τ, τ]) decides: PASS → STABLE, FAIL → UNSTABLE, INCONCLUSIVE → INCONCLUSIVE.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from . import claims as criteria

STABLE, UNSTABLE, INCONCLUSIVE = "STABLE", "UNSTABLE", "INCONCLUSIVE"
FROM_LEDGER = {criteria.PASS: STABLE, criteria.FAIL: UNSTABLE, criteria.INCONCLUSIVE: INCONCLUSIVE}
"""The ledger's verdict on "β_h bounded away from 0" as a stability verdict."""
MIN_MESHES = 3
"""Fewest meshes of a series: a slope's confidence interval needs n − 2 >= 1 dof."""
_ONE_VALUE = ("case", "k", "family", "norm", "multiplier_mesh", "c1", "c2")


def stability_verdict(rows, tol: float, floor: float, confidence: float) -> dict:
    """STABLE, UNSTABLE or INCONCLUSIVE for one space and one norm over a mesh sequence.

    Parameters
    ----------
    rows : list of dict or pandas.DataFrame
        Rows of :func:`~infsup_contact.solvers.infsup.beta_rows` (columns ``N2``, ``beta``,
        ``kernel_dim``, ``smallest_nonzero``), one per mesh, all of one case, degree, family,
        norm and multiplier mesh; h = 1/N2.
    tol : float
        Slope tolerance τ (config ``claims.slope_tolerance``).
    floor : float
        β floor (config ``claims.beta_floor``): min β_h <= floor is UNSTABLE.
    confidence : float
        Confidence level of the slope interval (config ``claims.confidence``).

    Returns
    -------
    dict
        ``verdict``; ``kernel_dim`` (the largest numerical kernel dimension over the meshes);
        ``beta_min``, ``beta_max`` (β_h of eq. (4.5) over the meshes); ``slope``,
        ``slope_lo``, ``slope_hi`` (least-squares slope and its interval,
        :func:`~infsup_contact.criteria.claims.slope_interval`) of log β_h vs log h, or, where
        there is a kernel, of log(smallest_nonzero) (β above the kernel) vs log h; NaN when
        fewer than two positive values; ``evidence`` (one line of text).

    Raises
    ------
    ValueError
        If the rows mix cases, degrees, families, norms or multiplier meshes, or repeat a mesh.
    """
    frame = _series(rows)
    h = 1.0 / frame.N2.to_numpy(float)
    beta = frame.beta.to_numpy(float)
    kernel_dim = int(frame.kernel_dim.max())
    close = criteria.close_decisions(frame)
    if len(close):
        verdict, fitted = INCONCLUSIVE, frame.smallest_nonzero.to_numpy(float) if kernel_dim > 0 else beta
        evidence = criteria.close_text(close)
    elif kernel_dim > 0:
        verdict, fitted = UNSTABLE, frame.smallest_nonzero.to_numpy(float)
        evidence = (f"β_h = 0: kernel dims {frame.kernel_dim.astype(int).tolist()} over N = "
                    f"{criteria.ns_text(frame)}; fit of the eigenvalue above the kernel")
    else:
        ledger_verdict, evidence = criteria.bounded_claim(frame, tol, floor, confidence)
        verdict, fitted = FROM_LEDGER[ledger_verdict], beta
    slope, lo, hi = _fit(h, fitted, confidence)
    return dict(verdict=verdict, kernel_dim=kernel_dim, beta_min=float(beta.min()),
                beta_max=float(beta.max()), slope=slope, slope_lo=lo, slope_hi=hi,
                evidence=evidence)



def _series(rows) -> pd.DataFrame:
    frame = pd.DataFrame(rows)
    missing = {"N2", "beta", "kernel_dim", "smallest_nonzero"} - set(frame.columns)
    if len(frame) == 0 or missing:
        raise ValueError(f"need beta_rows rows with columns N2, beta, kernel_dim, smallest_nonzero "
                         f"(missing {sorted(missing)}, {len(frame)} rows)")
    for col in _ONE_VALUE:
        if col in frame.columns and frame[col].nunique() > 1:
            raise ValueError(f"rows of one series expected; column {col!r} has {sorted(set(frame[col]))}")
    if frame.N2.duplicated().any():
        raise ValueError(f"one row per mesh expected; N2 = {frame.N2.tolist()}")
    return frame.sort_values("N2")


def _fit(h, y, confidence):
    ok = np.isfinite(y) & (y > 0)
    if ok.sum() < 2:
        return np.nan, np.nan, np.nan
    return tuple(float(v) for v in criteria.slope_interval(h[ok], y[ok], confidence))
