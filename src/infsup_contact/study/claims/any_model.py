"""Ledger claims of any model's β table, predicted from the registry and a dimension count alone.

What holds for every model whose energy a(·,·) is symmetric positive definite and equivalent to
the membranes' on each body (so nothing here reads the model):

* **The dimension count is a proof** (``<name>-kernel-at-least-count``): μ_h with b(v, μ_h) = 0 for
  every v of the two trace spaces is a zero mode of B A⁻¹ Bᵀ whatever A is, and there are at
  least max(dim M − dim(W1 + W2), 0) of them; every row's kernel is at least its
  ``structural_kernel_dim``.
* **Stable spaces stay stable** (``<name>-<tag>-k<k>[-<element>]``, predicted PASS): a(·,·) equivalent
  to Σ|v_i|²₁ changes β_h by bounded factors only, so a space registered stable keeps β_h bounded
  away from 0 on matching meshes (slope of log β_h vs log h within ±τ, min β_h above the floor).
* **Zero modes stay** (same id scheme): the kernel depends on B alone; on a 2D model (Γ the paper's
  segment, scalar P_k traces) it is the registry's count on every matching mesh; where the row's
  proof (``structural_kernel_dim``, the interface's count of the modes b cannot see) is positive on
  every matching mesh the kernel is exactly that (a registered-stable space included: a face can
  give it modes the segment does not); otherwise an unstable space has at least one mode.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ...criteria.claims import (FAIL, FINDING, INCONCLUSIVE, PASS, bounded_claim, close_decisions, close_text,
                                finest, kernel_at_least, kernel_claim, predicted_kernel, row)
from ...discretization.spaces.registry import SPACES

REF = "beyond the paper (a model of the model table)"


def _count_check(beta: pd.DataFrame):
    short = beta[beta.kernel_dim < beta.structural_kernel_dim]
    text = (f"{len(beta) - len(short)}/{len(beta)} rows with kernel >= max(dim M − dim W, 0); "
            f"kernel dims {sorted(set(beta.kernel_dim.astype(int).tolist()))}")
    close = close_decisions(beta)
    if len(short) and len(close):
        return INCONCLUSIVE, f"{text}; {close_text(close)}"
    return (PASS if len(short) == 0 else FAIL), text


def model_claims(beta: pd.DataFrame, cfg: dict, name: str, dim: int) -> pd.DataFrame:
    """The claims of one model-table entry ``name`` from its β table (columns of ``model_beta``);
    ``dim`` is the model's body dimension (2: Γ the segment), ``cfg`` the config's ``claims``."""
    tol, floor, conf, win = cfg["slope_tolerance"], cfg["beta_floor"], cfg["confidence"], cfg["fit_window"]
    out = [row(f"{name}-kernel-at-least-count", REF, f"{name}: every row's kernel is at least max(dim M − dim W, 0) "
               "(a dimension count, a proof for any SPD energy)", _count_check(beta))]
    h = beta[(beta.norm == "H") & (beta.N1 == beta.N2)]
    for (element, case, k), rows in h.groupby(["element", "case", "k"], sort=False):
        spec = SPACES.get(case)
        if spec is None:
            continue
        cid = f"{name}-{spec.tag}-k{k}" + ("" if element == "-" else f"-{element}")
        where = f"{name}, {case}, k={k}" + ("" if element == "-" else f", {element}")
        proven = rows.structural_kernel_dim.to_numpy(int)
        if spec.stable and not proven.any():
            out.append(row(cid, REF, f"{where}: β_h bounded away from 0 on matching meshes (H^-1/2_00 norm)",
                           bounded_claim(finest(rows, win), tol, floor, conf)))
        elif spec.expected == "unstable" and dim == 2 and spec.dimension is not None:
            expected = predicted_kernel(spec, rows)
            text = expected if np.isscalar(expected) else "the registry's count"
            out.append(row(cid, REF, f"{where}: kernel of dimension {text} on matching meshes",
                           kernel_claim(rows, expected)))
        elif proven.all():  # the face's proof counts the modes (a stable space can lose them on a face)
            out.append(row(cid, REF, f"{where}: the kernel is the proven one on matching meshes "
                           f"({', '.join(map(str, proven))})", kernel_claim(rows, proven)))
        elif spec.expected == "unstable":
            out.append(row(cid, REF, f"{where}: β_h = 0 (a kernel) on matching meshes", kernel_at_least(rows, 1)))
        else:  # no expectation registered and no proven mode: what β_h does is a finding
            out.append(row(cid, REF, f"{where}: β_h bounded away from 0 on matching meshes? (a finding)",
                           bounded_claim(finest(rows, win), tol, floor, conf), predicted=FINDING))
    return pd.DataFrame(out)
