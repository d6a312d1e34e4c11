"""Convergence rates: least-squares slopes of log(error) against log(h) with standard errors.

Expected energy rates for the manufactured scene (documented derivation): the data
λ = x(a − x)₊^p and g = (x − a)₊^q (1 − x) are, near x = a, in H^{p+1/2−ε} and
H^{q+1/2−ε} on Γ, and u_i = t_i(x)φ(y) − λ(x)ψ(y)/c_i inherits that x-regularity
(polynomial in y). Hence u ∈ H^{r}(Ω_i) with r = min(p, q) + 1/2 − ε and the best
approximation in P_k gives ‖u − u_h‖_a = O(h^{min(k, r − 1)}): min(k, 2.5) for p = q = 3 and
min(k, 1.25) for p = q = 1.75. For ``membranes`` no rate is derived (mixed boundary
conditions at Γ's endpoints and an unknown free boundary): the expectation is left NaN.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

MEASURES = ("energy_error", "l2_error", "lambda_l2_error", "lambda_hm12_error")


def fit_slope(h: np.ndarray, err: np.ndarray, window: int = 3) -> tuple[float, float, int]:
    """Slope of log err vs log h over the ``window`` finest points, its standard error, points used."""
    order = np.argsort(h)[:window]
    h, err = np.asarray(h)[order], np.asarray(err)[order]
    keep = err > 0
    if keep.sum() < 2:
        return np.nan, np.nan, int(keep.sum())
    res = stats.linregress(np.log(h[keep]), np.log(err[keep]))
    return float(res.slope), float(res.stderr) if keep.sum() > 2 else np.nan, int(keep.sum())


def expected_energy_rate(scene: str, k: int, p: float = 3.0, q: float = 3.0) -> float:
    """min(k, min(p, q) − 1/2) for the manufactured scene; NaN where none is derived."""
    return float(min(k, min(p, q) - 0.5)) if scene == "manufactured" else float("nan")


def rate_table(frame: pd.DataFrame, window: int = 3) -> pd.DataFrame:
    """One row per (scene, case, k, family, measure): slope, stderr, expected (energy).

    The expectation uses the scene kind (column ``scene_kind`` if present, else ``scene``)
    and the exponents p, q of the rows (columns ``p``, ``q``; defaults 3).
    """
    rows = []
    keys = ["scene", "case", "k", "family"]
    for key, grp in frame[frame.N1 == frame.N2].groupby(keys, sort=True):
        h = 1.0 / grp.N2.to_numpy(float)
        kind = grp["scene_kind"].iloc[0] if "scene_kind" in grp else key[0]
        p = float(grp["p"].iloc[0]) if "p" in grp else 3.0
        q = float(grp["q"].iloc[0]) if "q" in grp else 3.0
        for measure in MEASURES:
            slope, se, used = fit_slope(h, grp[measure].to_numpy(float), window)
            exp = expected_energy_rate(kind, key[2], p, q) if measure == "energy_error" else np.nan
            rows.append(dict(zip(keys, key), measure=measure, slope=slope, stderr=se, points=used,
                             h_min=h.min(), expected=exp))
    return pd.DataFrame(rows)
