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

from ...io import TableError
from ...table_schemas import SERIES_COLUMNS
from .registry import energy_rate

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
    """The rate the exact solution of the scene kind ``scene`` allows (the registry's
    :attr:`~.scene_registry.SceneSpec.energy_rate`: min(k, min(p, q) − 1/2) for the
    manufactured solution); NaN where none is derived."""
    return energy_rate(scene, k, p, q)


def series_columns(frame: pd.DataFrame) -> list:
    """The columns of ``frame`` that define a series (:data:`~infsup_contact.table_schemas.SERIES_COLUMNS`,
    those present): two series concatenated in one table are fitted apart, never together."""
    return [c for c in SERIES_COLUMNS if c in frame.columns]


def _where(frame: pd.DataFrame, label) -> str:
    """``line 7`` for the row with index ``label`` of a table read by ``io.read_table``."""
    lines = frame.attrs.get("lines")
    return f"line {lines[label]}" if lines is not None and label < len(lines) else f"data row {label + 1}"


def _describe(keys: list, values) -> str:
    values = values if isinstance(values, tuple) else (values,)
    return ", ".join(f"{k}={v}" for k, v in zip(keys, values) if v == v)  # NaN (not applicable): left out


def check_rate_input(frame: pd.DataFrame, name: str = "table") -> None:
    """Refuse what a fit would turn into a wrong slope, one line naming ``name``, the line and
    the series: N1/N2 <= 0 (non-integer N is refused by the table's schema), a negative or
    non-finite error, and a mesh listed twice in one series (a row repeated, two runs joined)."""
    for col in ("N1", "N2"):
        bad = frame.index[frame[col] <= 0]
        if len(bad):
            raise TableError(name, f"{_where(frame, bad[0])}: {col} = {frame.at[bad[0], col]}, not a mesh",
                             allowed="N >= 1")
    for col in MEASURES:
        values = frame[col].to_numpy(float)
        bad = frame.index[~np.isfinite(values) | (values < 0)]
        if len(bad):
            raise TableError(name, f"{_where(frame, bad[0])}: {col} = {frame.at[bad[0], col]}, not an error norm",
                             allowed="finite numbers >= 0")
    keys = series_columns(frame)
    matching = frame[frame.N1 == frame.N2]
    twice = matching[matching.duplicated(subset=[*keys, "N2"], keep=False)]
    if len(twice):
        first = twice.iloc[0]
        other = next(i for i in twice.index[1:] if twice.loc[i, [*keys, "N2"]].equals(first[[*keys, "N2"]]))
        raise TableError(name, f"{_where(frame, twice.index[0])} and {_where(frame, other)} list the mesh "
                         f"N = {first.N2} twice in the series {_describe(keys, tuple(first[keys]))}",
                         allowed="each mesh once per series")


def series_sizes(frame: pd.DataFrame) -> pd.Series:
    """Meshes (matching N1 = N2) per series, indexed by the series' columns."""
    matching = frame[frame.N1 == frame.N2]
    return matching.groupby(series_columns(frame), sort=True, dropna=False).N2.nunique()


def rate_table(frame: pd.DataFrame, window: int = 3, name: str = "table") -> pd.DataFrame:
    """One row per series (:func:`series_columns`: scene, case, k, family and, where present,
    c1, c2, the scene's p and q, seed, multiplier mesh) and measure: slope, stderr, expected (energy).

    The input is checked first (:func:`check_rate_input`, errors naming ``name``). The
    expectation uses the scene kind (column ``scene_kind`` if present, else ``scene``) and the
    exponents p, q of the rows (columns ``p``, ``q``; defaults 3).
    """
    check_rate_input(frame, name)
    rows = []
    keys = series_columns(frame)
    for key, grp in frame[frame.N1 == frame.N2].groupby(keys, sort=True, dropna=False):
        series = dict(zip(keys, key))
        h = 1.0 / grp.N2.to_numpy(float)
        kind = grp["scene_kind"].iloc[0] if "scene_kind" in grp else series["scene"]
        p = float(grp["p"].iloc[0]) if "p" in grp else 3.0
        q = float(grp["q"].iloc[0]) if "q" in grp else 3.0
        for measure in MEASURES:
            slope, se, used = fit_slope(h, grp[measure].to_numpy(float), window)
            exp = expected_energy_rate(kind, int(series["k"]), p, q) if measure == "energy_error" else np.nan
            rows.append(dict(series, measure=measure, slope=slope, stderr=se, points=used,
                             h_min=h.min(), expected=exp))
    return pd.DataFrame(rows)
