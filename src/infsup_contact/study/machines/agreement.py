"""Where the machine paths must agree: the sweep's exact columns and verdicts identical, β within
a tolerance set by how far its gap stands above round-off (:func:`beta_tolerance`), between the
tables :mod:`.paths` writes under each path.
"""
from __future__ import annotations

import numpy as np

KEYS = ["model", "case", "k", "N1", "N2", "multiplier_mesh", "norm"]
EXACT = ["kernel_dim", "structural_kernel_dim", "kernel_detected", "kernel_decision", "kernel_check", "dim_M"]
"""The sweep's columns that no code path may change (the kernel decisions and dimensions)."""


def compare(sweeps: dict, verdicts: dict) -> list:
    """Differences between the tables of several machine paths (empty: they agree).

    Parameters
    ----------
    sweeps, verdicts : dict
        path name → :func:`~.paths.sweep_rows` / :func:`~.paths.verdict_rows` of a process run on it; the first
        is the reference.

    Returns
    -------
    list of str
        One line per disagreement: an exact column or a verdict that differs, or a resolved
        β that differs by more than :func:`beta_tolerance`.
    """
    (ref_name, ref), *others = sweeps.items()
    problems = []
    for name, frame in others:
        both = ref.merge(frame, on=KEYS, suffixes=("", "_other"))
        if len(both) != len(ref) or len(frame) != len(ref):
            problems.append(f"{name}: {len(frame)} rows vs {len(ref)} under {ref_name}")
        for col in EXACT:
            bad = both[both[col] != both[f"{col}_other"]]
            problems += [f"{name} vs {ref_name}: {col} {r[col]} != {r[col + '_other']} at "
                         f"{dict((c, r[c]) for c in KEYS)}" for _, r in bad.iterrows()]
        for col in ("beta", "smallest_nonzero"):
            a, b = both[col].to_numpy(float), both[f"{col}_other"].to_numpy(float)
            rel = np.abs(a - b) / np.maximum(np.abs(a), np.finfo(float).tiny)
            tol = beta_tolerance(both.gap_over_roundoff.to_numpy(float), both.gap_over_roundoff_other.to_numpy(float))
            bad = both[rel > tol]
            problems += [f"{name} vs {ref_name}: {col} {r[col]:.12g} vs {r[col + '_other']:.12g} at "
                         f"{dict((c, r[c]) for c in KEYS)}" for _, r in bad.iterrows()]
    (ref_name, ref), *others = verdicts.items()
    for name, frame in others:
        both = ref.merge(frame, on=["case", "k", "norm"], suffixes=("", "_other"))
        if len(both) != len(ref) or len(frame) != len(ref):
            problems.append(f"{name}: {len(frame)} verdicts vs {len(ref)} under {ref_name}")
        bad = both[(both.verdict != both.verdict_other) | (both.kernel_dim != both.kernel_dim_other)]
        problems += [f"{name} vs {ref_name}: verdict {r.verdict_other} (kernel {r.kernel_dim_other}) != "
                     f"{r.verdict} (kernel {r.kernel_dim}) for {r.case} k={r.k} {r.norm}" for r in bad.itertuples()]
    return problems


def beta_tolerance(gap_a, gap_b) -> np.ndarray:
    """Relative tolerance of β between two runs: 10**GAP_DECADES/gap_over_roundoff (module
    docstring) where both resolve it, inf (digits of round-off) where either does not."""
    from ...solvers.kernel import GAP_DECADES

    gap = np.minimum(np.asarray(gap_a, float), np.asarray(gap_b, float))
    with np.errstate(divide="ignore"):
        return np.where(gap >= 10.0 ** GAP_DECADES, 10.0 ** GAP_DECADES / gap, np.inf)


def max_beta_difference(sweeps: dict) -> tuple[float, float]:
    """Largest relative difference of β between the paths over the resolved rows, and the
    largest of those differences over its tolerance (<= 1: inside it)."""
    (_, ref), *others = sweeps.items()
    worst, worst_scaled = 0.0, 0.0
    for _, frame in others:
        both = ref.merge(frame, on=KEYS, suffixes=("", "_other"))
        tol = beta_tolerance(both.gap_over_roundoff, both.gap_over_roundoff_other)
        ok = np.isfinite(tol)
        a, b = both.beta.to_numpy(float)[ok], both.beta_other.to_numpy(float)[ok]
        if len(a):
            rel = np.abs(a - b) / np.maximum(np.abs(a), np.finfo(float).tiny)
            worst, worst_scaled = max(worst, float(rel.max())), max(worst_scaled, float((rel / tol[ok]).max()))
    return worst, worst_scaled

