"""Hints where a foreign system's numbers suggest a mistake in the export or in the levels, not a
property of the multiplier space. A hint changes no verdict; it goes to the verdict row's
``hints`` column and to stderr as ``infsup-contact: hint: …``.

=====================================  =========================================================
finding                                hint
=====================================  =========================================================
β_h grows under refinement (the        B or G scaled by a mesh-dependent factor (a mortar
slope's whole interval below −τ in     code's E/h, say): a factor c(h) on B scales β_h by c(h),
log β_h vs log h)                      on G by c(h)^(−1/2); slope −1 ≈ B·(1/h)
B of shape n × m (fits transposed)     part of the shape refusal: "B appears transposed"
a kernel of Bᵀ on the coarse levels    the coarse levels are too coarse (a non-matching pair's
that is gone on the fine ones          coarse levels often have one): add finer levels
INCONCLUSIVE on a slope interval the   how many levels finer than h_min, halving h, would bring
band ±τ cannot decide                  the interval to a decision with the scatter seen, and
                                       from which h the local slopes agree (coarser levels are
                                       pre-asymptotic: drop them)
=====================================  =========================================================
"""
from __future__ import annotations

from contextlib import contextmanager

import numpy as np
from scipy import stats

from .readers import SystemFileError

MAX_EXTRA_LEVELS = 8
"""Most levels (each halving h) a coarse-levels hint proposes; beyond, it says "more than"."""
MIN_PER_DIRECTION = 8
"""Multipliers per direction of Γ below which a level is coarse for a rate. Measured on the
stable T3, k = 1, N1 = N2 + 1 (m = N2 − 1): the local slopes of log β_h are 0.33, 0.31, 0.25,
0.20, 0.15, 0.13 between N2 = 2, 3, 4, 6, 8, 12, 16; they reach τ = 0.15 between 7 and 11
multipliers."""
MIN_LEVELS_FINE = 3
"""Levels a slope's interval needs (n − 2 >= 1 degree of freedom)."""


def system_hints(rows, out: dict, tol: float, confidence: float, notes=None) -> list:
    """The hints for one verdict, each also written to ``notes`` (stderr) as
    ``infsup-contact: hint: …``: ``rows`` of :func:`~.levels.system_rows` (coarse to fine),
    ``out`` the verdict of :func:`~infsup_contact.criteria.stability.stability_verdict` on them."""
    h = np.array([r["h"] for r in rows], float)
    dims = [int(r["kernel_detected"]) for r in rows]
    hints = [scale_hint(out, tol), vanishing_kernel_hint(h, dims)]
    from_fit = out["kernel_dim"] == 0 and not any(r["kernel_decision"] == "close" for r in rows)
    if from_fit and out["verdict"] != "STABLE" and not hints[0]:
        m = np.array([r["m"] for r in rows], float)
        hints.append(coarse_levels_hint(h, m, np.array([r["beta"] for r in rows], float), out, tol, confidence))
    hints = [text for text in hints if text]
    for text in hints if notes is not None else ():
        print(f"infsup-contact: hint: {text}", file=notes)
    return hints


def scale_hint(out: dict, tol: float) -> str | None:
    """β_h (or the eigenvalue above the kernel) that grows under refinement: the slope's whole
    interval below −τ. β_h is at most the continuity constant of b in the exported norms, which
    does not depend on h for H^{-1/2}_00 and L², so a β_h growing like a power of 1/h says the
    entries carry a power of h."""
    slope, hi = out.get("slope", np.nan), out.get("slope_hi", np.nan)
    if not (np.isfinite(slope) and np.isfinite(hi) and hi < -tol):
        return None
    near = round(2 * slope) / 2  # the nearest multiple of 1/2: B·h^-1 gives −1, G·h gives −1/2
    power = f" ≈ {near:g}, β_h ~ h^{near:g}" if near and abs(slope - near) <= tol else ""
    return (f"β_h grows under refinement (slope {slope:.2f} of log β_h vs log h{power}): is B or G scaled by a "
            "mesh-dependent factor (E/h, say)? A factor c(h) on B scales β_h by c(h), on G by c(h)^(-1/2); "
            "export B and G without it")


def vanishing_kernel_hint(h, dims) -> str | None:
    """A kernel of Bᵀ on the coarsest levels that is gone on the finer ones: the verdict
    (UNSTABLE: a kernel on any level) then rests on levels too coarse for the pair."""
    if not dims or dims[0] == 0 or dims[-1] != 0:
        return None
    first = next(i for i in range(len(dims)) if all(d == 0 for d in dims[i:]))
    need = MIN_LEVELS_FINE - (len(dims) - first)
    return (f"the kernel of B^T shrinks under refinement (dims {dims} over 1/h = "
            f"{', '.join(f'{1 / v:g}' for v in h)}) and is gone from h = {h[first]:g} on: the levels coarser "
            f"than that are too coarse for this pair (non-matching meshes?); to judge the rate, drop them"
            + (f" and add at least {need} level(s) finer than h = {h.min():g}" if need > 0 else ""))


def coarse_levels_hint(h, m, y, out: dict, tol: float, confidence: float) -> str | None:
    """A slope that did not decide STABLE on levels that may be too coarse for it: the levels
    with fewer than :data:`MIN_PER_DIRECTION` multipliers per direction of Γ, and from which h
    on there would be that many (by the growth of m); from which level on the local slopes
    between consecutive levels agree within τ; for an INCONCLUSIVE verdict, how many levels
    finer than h_min (halving h each) would bring the interval to a decision if the scatter
    about the fit stays as it is. None when the levels are fine enough and the verdict decided."""
    ok = np.isfinite(y) & (y > 0)
    h, m, y = h[ok], m[ok], y[ok]
    if len(h) < 3 or not np.isfinite(out.get("slope", np.nan)):
        return None
    per_dir = _per_direction(h, m)
    coarse = per_dir < MIN_PER_DIRECTION
    inconclusive = out["verdict"] == "INCONCLUSIVE"
    if not (coarse.any() or inconclusive):
        return None
    parts = [f"{len(h)} levels may be too few or too coarse for this verdict: the slope {out['slope']:.3f} has the "
             f"{int(confidence * 100)}% interval [{out['slope_lo']:.3f}, {out['slope_hi']:.3f}] against 0±{tol:g}"]
    if coarse.any():
        finest = np.argmin(h)  # per direction m^(1/d) grows like 1/h: MIN_PER_DIRECTION at h_fine
        h_fine = h[finest] * per_dir[finest] / MIN_PER_DIRECTION
        parts.append(f"the levels h = {_fmt(h[coarse], 'g')} have about {_fmt(per_dir[coarse], '.0f')} multipliers "
                     f"per direction of Γ, fewer than {MIN_PER_DIRECTION}: a slope there is pre-asymptotic (more so "
                     f"on non-matching meshes); it means something from about h = {h_fine:.3g} on")
    local = np.diff(np.log(y)) / np.diff(np.log(h))
    first = next(i for i in range(len(local)) if np.all(np.abs(local[i:] - local[-1]) <= tol))
    parts.append(f"local slopes {_fmt(local, '.2f')}" + (f", agreeing within ±{tol:g} only from h = {h[first]:g} on"
                                                       if first else ""))
    if coarse.any():  # the scatter of pre-asymptotic levels says nothing of the fine ones'
        parts.append(f"give at least {MIN_LEVELS_FINE} levels at or below h = {h_fine:.3g} before trusting the slope")
    else:
        use = slice(first, None) if len(h) - first >= 3 else slice(None)
        extra = _levels_to_decide(np.log(h[use]), np.log(y[use]), tol, confidence)
        more = f"about {extra} level(s)" if extra is not None else f"more than {MAX_EXTRA_LEVELS} levels"
        parts.append(f"add {more} finer than h = {h.min():g} (halving h each), by the scatter seen")
    return "; ".join(parts)


def _per_direction(h, m):
    """Multipliers per direction of Γ on each level, m^(1/d), with d ∈ {1, 2} the dimension of Γ
    by the growth of m + 1 under refinement (m + 1: the interior nodes of N cells are N − 1)."""
    growth = np.polyfit(np.log(1.0 / h), np.log(m + 1.0), 1)[0]
    return m ** (1.0 if growth < 1.5 else 0.5)


def _levels_to_decide(x, z, tol: float, confidence: float) -> int | None:
    """Fewest levels at log h = x_min − j log 2 (j = 1, 2, …) whose addition, with the fit's
    slope and residual scatter unchanged, makes the interval decide (inside ±τ, or clear of
    it); None above :data:`MAX_EXTRA_LEVELS` or when the slope sits on a band edge."""
    fit = stats.linregress(x, z)
    scatter = np.sqrt(np.sum((z - fit.intercept - fit.slope * x) ** 2) / (len(x) - 2))
    room = abs(tol - abs(fit.slope))
    if room < 1e-3:
        return None
    for extra in range(1, MAX_EXTRA_LEVELS + 1):
        xs = np.concatenate([x, x.min() - np.log(2.0) * np.arange(1, extra + 1)])
        half = stats.t.ppf(0.5 + confidence / 2, len(xs) - 2) * scatter / np.sqrt(np.sum((xs - xs.mean()) ** 2))
        if half < room:
            return extra
    return None


def _fmt(values, spec: str) -> str:
    return "[" + ", ".join(f"{v:{spec}}" for v in values) + "]"


@contextmanager
def transposed_b_hint(A, B, G):
    """Around a shape check: a refusal of a B that is n × m where m × n was expected (it fits
    transposed) gets "B appears transposed" in its one line."""
    try:
        yield
    except SystemFileError as err:
        n, m = A.shape[0], G.shape[0]
        if n != m and B.shape == (n, m) and A.shape[0] == A.shape[1] and G.shape[0] == G.shape[1]:
            raise SystemFileError(err.where, f"{err.allowed}; hint: B appears transposed: give B as m x n "
                                  f"({m} x {n}: a row per multiplier, a column per dof)", key=err.key) from None
        raise
