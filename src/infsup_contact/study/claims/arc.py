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
    text = f"{len(joined)} rows: kernels {'equal' if kernels else 'DIFFER'}, max |Δβ|/max β = {gap:.2e}"
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
    text = (f"{int((~differ).sum())}/{len(mine)} (radius, series, case, norm) verdicts as on the flat segment, "
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
