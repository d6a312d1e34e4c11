"""The round-off of a producer's entries of B, and what it does to the kernel threshold η.

A production code assembles b_ij = Σ_q w_q φ_j(x_q) μ_i(x_q); an entry that is zero in exact
arithmetic (a cancelling sum, a biorthogonal pair, a scale factor divided out) comes out as
~1e-15 · max |b|, and every other entry carries an error of the same order. Let r bound
these errors relative to max |b_ij|: |δb_ij| <= r · max |b| on every *stored* entry (an entry
not stored, or stored as an exact 0, is exact). W = D_A^{-1/2} Bᵀ D_G^{-1/2} then has

    ‖δW‖₂ <= ‖δW‖_F <= r · max |b| · ‖D_A^{-1/2} Pᵀ D_G^{-1/2}‖_F =: E(r)            (1)

with P the 0/1 pattern of B's stored entries, and Weyl's inequality moves every singular
value by at most E(r). The kernel threshold of :func:`~infsup_contact.solvers.kernel.error_level`
becomes η = max(rows, m) ε σ_max + 2 E(r): the SVD's backward error plus twice the bound (1)
(the factor 2: r below is an estimate from a sample, and the same convention holds for the
suite's own couplings). A true zero singular value then lies below E(r) <= η/2.

r comes from, in this order (:func:`entry_roundoff`; ``entry_rtol_source`` in the row):

``declared``
    ``entry_rtol`` in the manifest, unless the data show more (then ``estimated``, with a note);
``estimated``
    from the data (:func:`estimate_entry_rtol`): the largest of
    (a) the *tiny entries*: a stored |b_ij| <= :data:`TINY_RTOL` × max |b| is a producer zero
        (no quadrature of polynomials on a mesh gives a genuine ratio of 1e-12 between two
        entries of one coupling: rows scale like the local h and the multiplier's size), and
        its size is its round-off: r_a = max |b_ij| / max |b|. Measured against the largest
        entry of B, not of the entry's row: a row left over a fixed dof (Kratos zeroes the
        columns of B over Dirichlet dofs, leaving the end multipliers' rows at ~1e-13) is tiny
        in every entry, and only the global scale shows it;
    (b) the *zero row sums*: a row whose exact sum |Σ_j b_ij| is <= :data:`TINY_RTOL` × Σ_j |b_ij|
        sums to 0 in exact arithmetic (a mortar coupling [−B1 | B2] of partitions of unity,
        a divergence against a constant field); its sum is the sum of its nnz_i entry errors,
        of size ~√nnz_i · r for independent errors: r_b = max |Σ_j b_ij| / (√nnz_i · max |b|)
        (the sum is taken exactly, ``math.fsum``, so our own round-off is not counted);
    both are at most TINY_RTOL by construction, so an estimate never raises η by more than
    that. An estimate at or below ε (the representation of the entries themselves, which the
    SVD term already covers) counts as none;
``exact``
    no sign of round-off: r = 0 and η is the exact-entry threshold.

A round-off the data do not show (a producer that drops its tiny entries and whose rows do
not sum to zero, or a text export with 8 significant digits) is caught by the pencil
cross-check of :mod:`.engine`: a "first non-zero" eigenvalue of (B A⁻¹ Bᵀ, G) at the pencil's
round-off level makes the decision ``close``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

TINY_RTOL = 1e-12
"""A stored entry this small relative to B's largest, or a row sum this small relative to
the row's Σ |b_ij|, is a producer zero (module docstring)."""
SOURCES = ("declared", "estimated", "exact")


@dataclass(frozen=True)
class EntryRoundoff:
    """r of the module docstring, where it came from, and the evidence in words."""

    rtol: float
    source: str
    evidence: str


def estimate_entry_rtol(B) -> tuple:
    """(r, evidence) from the data of B (module docstring, (a) and (b)); r = 0 without evidence."""
    B = sp.csr_matrix(B, dtype=float)
    B.eliminate_zeros()
    if B.nnz == 0:
        return 0.0, "B has no entries"
    absB = abs(B)
    top = float(absB.max())
    tiny = np.abs(B.data) <= TINY_RTOL * top
    r_a = float(np.abs(B.data[tiny]).max()) / top if tiny.any() else 0.0
    nnz = np.diff(B.indptr)
    abs_sum = np.asarray(absB.sum(axis=1)).ravel()
    r_b, n_zero_sum = 0.0, 0
    for i in np.flatnonzero(nnz >= 2):
        s = abs(math.fsum(B.data[B.indptr[i]:B.indptr[i + 1]]))
        if s <= TINY_RTOL * abs_sum[i]:
            n_zero_sum += 1
            r_b = max(r_b, s / (math.sqrt(nnz[i]) * top))
    eps = float(np.finfo(float).eps)
    r = max(r_a, r_b)
    text = (f"{int(tiny.sum())} tiny entries (<= {TINY_RTOL:g} x max|b|; largest {r_a:.2g} x max|b|), "
            f"{n_zero_sum} rows summing to 0 (deviation {r_b:.2g} x sqrt(nnz) x max|b|)")
    return (r if r > eps else 0.0), text


def entry_roundoff(B, declared=None) -> EntryRoundoff:
    """r of the module docstring: the declared value, raised to the estimate where the data show more."""
    r_est, text = estimate_entry_rtol(B)
    if declared is not None and declared >= r_est:
        return EntryRoundoff(float(declared), "declared", f"entry_rtol: {declared:g} declared; data: {text}")
    if r_est > 0.0:
        more = f"; the declared entry_rtol {declared:g} is below it" if declared is not None else ""
        return EntryRoundoff(r_est, "estimated", f"entry round-off {r_est:.2g} x max|b| from {text}{more}")
    return EntryRoundoff(0.0, "exact", f"entries taken as exact: {text}")


def entry_error_bound(B_touched_t, da, dg, rtol: float) -> float:
    """E(r) of (1): r · max |b| · ‖D_A^{-1/2} Pᵀ D_G^{-1/2}‖_F, from Bᵀ on the touched dofs
    (sparse, rows = touched dofs) and the square roots of the diagonals ``da`` (of A on them)
    and ``dg`` (of G)."""
    Bt = sp.coo_matrix(B_touched_t)
    if rtol == 0.0 or Bt.nnz == 0:
        return 0.0
    stored = Bt.data != 0.0
    rows, cols = Bt.row[stored], Bt.col[stored]
    frob = math.sqrt(float(np.sum((1.0 / (np.asarray(da)[rows] * np.asarray(dg)[cols])) ** 2)))
    return rtol * float(np.abs(Bt.data).max()) * frob
