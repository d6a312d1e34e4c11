"""How far an exported B is from the exact mortar coupling, where the bodies' traces are described.

With ``norm: H`` a level may describe, besides its multipliers, the trace basis of each body on
Γ (``traces``: a list of one or two descriptions in the forms of :mod:`.multiplier_basis`, each
with ``columns`` — the column of B (the dof of A) of each trace function in the description's
numbering, −1 for none — and ``sign``, the sign of that body's block in B; default −1 for the
first and +1 for the second, b(v, μ) = ∫_Γ (v2 − v1) μ). The exact coupling is then

    B_exact[row of ψ_j, column of φ_l] = sign · ∫_Γ ψ_j φ_l,

integrated on the common refinement of the two partitions by the interface's Gauss rule, exact
for the product's degree (the suite's own coupling, :mod:`~infsup_contact.discretization.gamma.coupling`),
times |Γ| for the pull-back. The row reports ‖B − B_exact‖_F / ‖B_exact‖_F (``coupling_distance``):
round-off for an exact producer; a code that integrates on one side's quadrature only is exact on
matching meshes and off by the integration error on non-matching ones.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import norm as sparse_norm

from .multiplier_basis import _array, describe_space
from .readers import SystemFileError

TRACE_KEYS = ("columns", "sign")


def _traces(manifest, level, n: int) -> list:
    """[(space, columns per space function, sign)] of the level's ``traces``; one line per fault."""
    where, key = manifest.path, f"levels[{level.index}].traces"
    raw = level.traces
    if not isinstance(raw, list) or not 1 <= len(raw) <= 2 or not all(isinstance(t, dict) for t in raw):
        raise SystemFileError(where, f"{key}: expected a list of one or two trace descriptions (mappings with "
                              f"columns; found {raw!r:.60})")
    out = []
    for b, entry in enumerate(raw):
        here = f"{key}[{b}]"
        if "rows" in entry:
            raise SystemFileError(where, f"{here}.rows: a trace gives its columns of B (columns:), not rows")
        if "columns" not in entry:
            raise SystemFileError(where, f"{here}: missing key 'columns' (the column of B of each trace function, "
                                  "-1 for none)")
        sign = entry.get("sign", -1 if b == 0 and len(raw) == 2 else 1)
        if isinstance(sign, bool) or sign not in (-1, 1):
            raise SystemFileError(where, f"{here}.sign: expected -1 or 1 (found {sign!r:.20})")
        form = {k: v for k, v in entry.items() if k not in TRACE_KEYS}
        space, order = describe_space(where, here, form, manifest.path.parent, manifest.gamma)
        cols = _array(where, f"{here}.columns", entry["columns"], manifest.path.parent, integer=True).ravel()
        if len(cols) != space.dim or np.any(cols < -1) or np.any(cols >= n):
            raise SystemFileError(where, f"{here}.columns: expected {space.dim} integers in -1..{n - 1} (one per "
                                  f"trace function; B has {n} columns; found {len(cols)})")
        live = cols[cols >= 0]
        if len(np.unique(live)) != len(live):
            raise SystemFileError(where, f"{here}.columns: a column of B named twice")
        out.append((space, cols[order], sign))
    return out


def exact_coupling(described, traces, n: int) -> sp.csr_matrix:
    """B_exact (m × n, rows in B's order) of the described multipliers against ``traces``."""
    from ..discretization.gamma.coupling import weighted_values

    gamma = described.gamma.interface  # the manifest's Γ, pulled back
    scale = float(np.prod(described.gamma.size))
    rows = described.rows  # row of B of each multiplier function
    out = sp.csr_matrix((described.m, n))
    for space, cols, sign in traces:
        pieces = gamma.common_refinement(described.space.breakpoints, space.breakpoints)
        x, w = gamma.quadrature(pieces, described.space.degree + space.degree)
        local = weighted_values(described.space, x, w).T @ weighted_values(space, x, np.ones_like(w))
        local = sp.coo_matrix(local)
        keep = cols[local.col] >= 0
        out = out + sp.csr_matrix((sign * scale * local.data[keep], (rows[local.row[keep]], cols[local.col[keep]])),
                                  shape=(described.m, n))
    return out


CHECKED_RTOL = 1e-8
"""A body's block of B within this relative Frobenius distance of its exact coupling checks the
description (the round-off of an exactly integrated block is ~1e-15; :data:`.multiplier_gram.MASS_RTOL`
is the same 1e-8). Farther on every body, the distance cannot tell a wrong description from
quadrature: a B integrated on the multiplier mesh only is 0.005–0.22 from the exact coupling
(non-matching, per row up to 0.29: P_0 multipliers with the midpoint rule), where DOLFINx's P_3
described with equispaced nodes is 0.16 (0.18 per row) and one swapped pair of rows ~2/√m."""


ROW_RTOL = 0.5
"""Largest row distance (‖b_i − α e_i‖ / max_j ‖α e_j‖ on a body's block) that quadrature explains: a B
integrated on the multiplier mesh only is up to 0.29 off per row (above), a row of B holding
another multiplier's entries √2 (disjoint supports) or ≥ 1.03 (neighbours, P_1)."""


def block_distances(manifest, level, described, B, rows=None, per_row: bool = False) -> list:
    """‖B_b − E_b‖_F / ‖E_b‖_F per described trace b (its columns of B only; B as read, on its
    ``rows``): the body whose trace mesh is the multiplier mesh is integrated exactly by any rule on
    the multiplier cells exact for the product's degree, so one block at round-off checks the
    description even where the other is inexact. ``per_row``: max_i ‖b_i − α e_i‖ / max_j ‖α e_j‖ instead,
    α = ⟨B_b, E_b⟩ / ⟨E_b, E_b⟩ (a factor on all of B, a code's E/h, is not a wrong description)."""
    traces = _traces(manifest, level, B.shape[1])
    out = []
    for trace in traces:
        cols = trace[1][trace[1] >= 0]
        exact = exact_coupling(described, [trace], B.shape[1])[:, cols]
        mine = sp.csr_matrix(B)[:, cols]
        if rows is not None:
            exact, mine = exact[rows], mine[rows]
        if per_row:  # against the best multiple α E_b: a factor on B (a code's E/h) is no description error
            alpha = float(exact.multiply(mine).sum() / max(exact.multiply(exact).sum(), 1e-300))
            size = abs(alpha) * np.sqrt(np.asarray(exact.multiply(exact).sum(axis=1)).ravel())
            diff = sp.csr_matrix(mine - alpha * exact)
            off = np.sqrt(np.asarray(diff.multiply(diff).sum(axis=1)).ravel())
            out.append(float(off.max() / size.max()) if size.max() > 0 else float("inf"))
            continue
        norm = sparse_norm(exact)
        out.append(float(sparse_norm(mine - exact) / norm) if norm > 0 else float("inf"))
    return out


def coupling_distance(manifest, level, described, B, rows=None) -> float:
    """‖B − B_exact‖_F / ‖B_exact‖_F for the level's described traces (B as read, before any
    dof is removed; on its ``rows`` only, default all), or NaN without ``traces``."""
    if level.traces is None:
        return float("nan")
    exact = exact_coupling(described, _traces(manifest, level, B.shape[1]), B.shape[1])
    if rows is not None:
        B, exact = sp.csr_matrix(B)[rows], exact[rows]
    norm = sparse_norm(exact)
    if not norm > 0:
        raise SystemFileError(manifest.path, f"levels[{level.index}].traces: the described traces do not meet the "
                              "multipliers (the exact coupling is zero)")
    return float(sparse_norm(sp.csr_matrix(B) - exact) / norm)
