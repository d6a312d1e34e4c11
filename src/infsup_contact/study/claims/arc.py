"""Ledger claims of the curved segment (:mod:`infsup_contact.study.beta.arc`), predicted from how
the arc is built (:mod:`infsup_contact.discretization.segment.arc`, ``.projection``):

* **R = ∞ is the paper** (``<name>-flat-is-the-paper``): the flat arc builds the paper's meshes and
  its exact coupling is the segment's, so every row equals the paper's code's bit for bit; with the
  projection (``<name>-flat-projection-is-the-paper``) P = id on a flat Γ and only the rule's
  round-off differs: the same kernels, β_h within 1e-10 (relative).
* **The exact coupling keeps the flat kernels** (``<name>-exact-kernels-are-flat``): it maps both
  traces to the arc by arc length, so B_i is the flat B_i at every R and the kernel of Bᵀ with it.
* **Projection on matching meshes keeps the count** (``<name>-projection-matching-kernel-is-count``):
  the curves are interpolated edge by edge, both sides share Γ_h, P = id, and the count is a proof.
* **Curvature does not change a verdict** (``<name>-verdicts-as-flat-exact``): the curved bodies'
  energies are equivalent to the flat ones with constants bounded in R ≥ R_min; every decisive flat
  verdict (STABLE, UNSTABLE) stays at every radius. With the projection
  (``<name>-verdicts-never-flip-projection``) B is also perturbed by the geometric error, which
  vanishes with h, and its entries carry the projection's round-off (the master point is found to
  ~1 ulp, its basis values to ~ε k/h): no verdict turns into the opposite one, but a numerical kernel
  (one the count does not prove) may become undecided.
* **Findings** (no prediction): what the projection does to the kernels of non-matching meshes.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ...criteria.claims import FAIL, FINDING, PASS, kernel_claim, row
from ...criteria.stability import INCONCLUSIVE as UNDECIDED
from ..beta.arc import PAPER, arc_verdicts, radius_of
from .tolerance import within

REF = "beyond the paper (the curved segment)"
ROW_KEY = ["series", "case", "k", "N1", "N2", "multiplier_mesh", "c1", "c2", "norm"]
FLAT_PROJECTION_TOLERANCE = 1e-10
"""Relative bound on |β_∞,projection − β_paper|: the projection's rule sums the same products in
another order and with |p'| = 1 computed (a few hundred terms, each with relative error ~1e-16)."""


def _against_paper(beta: pd.DataFrame, kappa: float, coupling: str) -> pd.DataFrame:
    paper = beta[beta.coupling == PAPER].set_index(ROW_KEY)
    mine = beta[(beta.curvature == kappa) & (beta.coupling == coupling)].set_index(ROW_KEY)
    return mine.merge(paper, left_index=True, right_index=True, suffixes=("", "_paper"))


def _bitwise(joined: pd.DataFrame):
    same = (joined.beta == joined.beta_paper) & (joined.kernel_dim == joined.kernel_dim_paper)
    text = f"{int(same.sum())}/{len(joined)} rows equal to the paper's code bit for bit"
    return (PASS if len(joined) and same.all() else FAIL), text


def _round_off(joined: pd.DataFrame):
    gap = np.abs(joined.beta - joined.beta_paper).max() / joined.beta_paper.max()
    kernels = (joined.kernel_dim == joined.kernel_dim_paper).all()
    text = f"{len(joined)} rows: kernels {'equal' if kernels else 'DIFFER'}, {within('max |Δβ|/max β', gap, FLAT_PROJECTION_TOLERANCE)}"
    return (PASS if len(joined) and kernels and gap <= FLAT_PROJECTION_TOLERANCE else FAIL), text


def _kernels_as_flat(beta: pd.DataFrame, coupling: str):
    parts = [_against_paper(beta, c, coupling) for c in sorted(set(beta.curvature[beta.coupling == coupling]))]
    joined = pd.concat(parts)
    differ = joined[joined.kernel_dim != joined.kernel_dim_paper]
    text = f"{len(joined) - len(differ)}/{len(joined)} rows with the flat kernel"
    if len(differ):
        first = differ[differ.index.get_level_values("norm") == "H"]
        text += "; differ (H rows): " + ", ".join(
            f"{c} {n1}:{n2} R={radius_of(r):g} ({int(a)} vs {int(b)})" for (_, c, _, n1, n2, *_), r, a, b
            in zip(first.index, first.curvature, first.kernel_dim, first.kernel_dim_paper))[:400]
    return differ, ((PASS if len(differ) == 0 else FAIL), text)


def _verdicts_as_flat(verdicts: pd.DataFrame, coupling: str, undecided_ok: bool = False):
    flat = verdicts[verdicts.coupling == PAPER].set_index(["series", "case", "norm"]).verdict
    flat = flat[flat != UNDECIDED]
    mine = verdicts[(verdicts.coupling == coupling) & verdicts.set_index(["series", "case", "norm"]).index.isin(flat.index)]
    expected = flat.reindex(pd.MultiIndex.from_frame(mine[["series", "case", "norm"]])).to_numpy()
    differ = mine.verdict.to_numpy() != expected
    undecided = differ & (mine.verdict == UNDECIDED).to_numpy()
    bad = mine[differ & ~(undecided & undecided_ok)]
    text = (f"{int((~differ).sum())}/{len(mine)} (radius, series, case, norm) verdicts as on the flat Γ, "
            f"{int(undecided.sum())} undecided, {int((differ & ~undecided).sum())} opposite "
            f"({len(flat)} decisive flat verdicts)")
    if len(bad):
        text += "; differ: " + ", ".join(f"{c} {s} {n} R={radius_of(r):g}: {v}" for r, s, c, n, v
                                         in zip(bad.curvature, bad.series, bad.case, bad.norm, bad.verdict))[:400]
    return (PASS if len(mine) and len(bad) == 0 else FAIL), text


def arc_claims(beta: pd.DataFrame, cfg: dict, name: str) -> pd.DataFrame:
    """The claims of the arc study ``name`` from its β table (schema ``arc_beta``; module docstring);
    ``cfg`` is the config's ``claims`` (the verdicts' slope tolerance, floor and confidence)."""
    verdicts = arc_verdicts(beta, cfg["slope_tolerance"], cfg["beta_floor"], cfg["confidence"])
    out = [row(f"{name}-flat-is-the-paper", REF, f"{name}: R = ∞ with the exact coupling is the paper's segment, "
               "bit for bit", _bitwise(_against_paper(beta, 0.0, "exact")))]
    if (beta.coupling == "projection").any():
        out.append(row(f"{name}-flat-projection-is-the-paper", REF,
                       f"{name}: R = ∞ with the projection: the paper's kernels, β_h to round-off",
                       _round_off(_against_paper(beta, 0.0, "projection"))))
        matching = beta[(beta.coupling == "projection") & (beta.N1 == beta.N2)]
        out.append(row(f"{name}-projection-matching-kernel-is-count", REF,
                       f"{name}: with the projection, the kernel on matching meshes is the dimension count",
                       kernel_claim(matching, matching.structural_kernel_dim.to_numpy(int))))
        differ, evidence = _kernels_as_flat(beta[beta.N1 != beta.N2], "projection")
        out.append(row(f"{name}-projection-nonmatching-kernels", REF, f"{name}: with the projection, are the "
                       "kernels on non-matching meshes the flat ones? (a finding)", evidence, predicted=FINDING))
    out.append(row(f"{name}-exact-kernels-are-flat", REF, f"{name}: with the exact coupling every kernel is the "
                   "flat one (B_i is the flat B_i)", _kernels_as_flat(beta, "exact")[1]))
    out.append(row(f"{name}-verdicts-as-flat-exact", REF, f"{name}: every decisive flat stability verdict is the "
                   "same at every radius (exact coupling)", _verdicts_as_flat(verdicts, "exact")))
    if (beta.coupling == "projection").any():
        out.append(row(f"{name}-verdicts-never-flip-projection", REF, f"{name}: no decisive flat stability verdict "
                       "turns into the opposite one at any radius (projection; a numerical kernel may become "
                       "undecided: the projected entries carry the projection's round-off)",
                       _verdicts_as_flat(verdicts, "projection", undecided_ok=True)))
        out.append(row(f"{name}-verdicts-as-flat-projection", REF, f"{name}: is every decisive flat verdict the same "
                       "at every radius with the projection? (a finding)", _verdicts_as_flat(verdicts, "projection"),
                       predicted=FINDING))
    return pd.DataFrame(out)


PATCH_PASS_RTOL = 1e-8
"""λ_h = λ to this relative accuracy counts as reproduced (the flat membranes' patch test's bound)."""
CONVERGES_SLOPE = 1.0
"""Smallest slope of log max|λ_h − λ| against log h that counts as converging (the body's map
is O(h^{k+1}) and ln r is smooth: first order is the least a consistent space shows)."""


PATCH_FIT_PAIRS = 3
"""The patch claim fits the λ error over the finest pairs only (at most the ledger's ``fit_window``):
the coarsest pair of the config's four, N2 = 4, is pre-asymptotic (the dual k = 2 error rises from
N2 = 4 to 8 before falling like h²)."""


def arc_patch_claims(patch: pd.DataFrame, name: str, window: int) -> pd.DataFrame:
    """The patch test's claims (:mod:`infsup_contact.study.patch.arc`, predictions in its docstring):
    at R = ∞ λ_h = λ iff 1 ∈ M_h; at finite R every space holding the constants converges (slope of
    the λ error ≥ :data:`CONVERGES_SLOPE` over the ``window`` finest pairs: the claim is about h → 0,
    as the ledger's fits are) and T3-like spaces do not."""
    flat = patch[patch.curvature == 0]
    hit = (flat.lambda_max_rel_error < PATCH_PASS_RTOL) == flat.holds_constants.astype(bool)
    out = [row(f"{name}-patch-flat-iff-constants", REF, f"{name}: on the flat segment the patch test's λ is "
               "reproduced to round-off iff 1 ∈ M_h", ((PASS if len(flat) and hit.all() else FAIL),
                                                      f"{int(hit.sum())}/{len(flat)} rows as 1 ∈ M_h says"))]
    curved = patch[patch.curvature > 0]
    slopes, bad = [], []
    for key, rows in curved[curved.holds_constants.astype(bool)].groupby(["curvature", "coupling", "case", "k"]):
        rows = rows[rows.N2.isin(sorted(set(rows.N2))[-min(window, PATCH_FIT_PAIRS):])]
        h, err = 1.0 / rows.N2.to_numpy(float), rows.lambda_max_rel_error.to_numpy(float)
        slope = float(np.polyfit(np.log(h), np.log(err), 1)[0]) if len(rows) > 1 else np.nan
        slopes.append(slope)
        if not slope >= CONVERGES_SLOPE:
            bad.append(f"{key[2]} k={key[3]} R={radius_of(key[0]):g} {key[1]}: {slope:.2f}")
    text = (f"{len(slopes)} series, slopes of the λ error in [{np.nanmin(slopes):.2f}, {np.nanmax(slopes):.2f}]"
            if slopes else "no series") + (f"; below {CONVERGES_SLOPE}: {', '.join(bad)}" if bad else "")
    out.append(row(f"{name}-patch-curved-converges", REF, f"{name}: on the arc every space holding the constants "
                   f"converges to the uniform pressure (slope of max|λ_h − λ| ≥ {CONVERGES_SLOPE:g})",
                   ((PASS if slopes and not bad else FAIL), text)))
    no_constants = curved[~curved.holds_constants.astype(bool)]
    finest = no_constants[no_constants.N2 == no_constants.N2.max()] if len(no_constants) else no_constants
    out.append(row(f"{name}-patch-curved-no-constants-fail", REF, f"{name}: on the arc a space without the "
                   "constants keeps an O(1) λ error at Γ's ends on the finest pair",
                   ((PASS if len(finest) and (finest.lambda_max_rel_error > 0.5).all() else FAIL),
                    f"{len(finest)} rows, λ errors in [{finest.lambda_max_rel_error.min():.2g}, "
                    f"{finest.lambda_max_rel_error.max():.2g}]" if len(finest) else "no row")))
    return pd.DataFrame(out)
