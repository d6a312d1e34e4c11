"""The interface operator's terms B X Bᵀ computed in parity blocks, never as a whole m × m matrix.

Where a body is factorized in its parity parts (:mod:`.body_parity`), its Steklov inverse is
known block by block, X = Σ_c P_c X_c P_cᵀ (P_c the Γ columns of part c: an orthonormal basis
P = [P_0, ...] of the Γ dofs, X_c of order about n_Γ / 2^g). Where the multiplier space has the
same reflections (:class:`~.reflection.ReflectionSplit`, Q = [Q_0, ...] orthonormal), the
coupling is equivariant and C = Qᵀ B P is block diagonal up to round-off: C = D + O, D the
blocks C_{a σ(a)} of the matching components, O the rest. Then

    Qᵀ (B X Bᵀ) Q = C X_P Cᵀ,    block a of D X_P Dᵀ = C_{aσ(a)} X_{σ(a)} C_{aσ(a)}ᵀ,

and only these blocks are computed: (1/2^g) of the sparse-times-dense products of the whole
sandwich and (1/2^g) of its memory, no split of a whole S afterwards (:meth:`~.reflection.ReflectionSplit.blocks`).
What they drop is bounded, not assumed: C X_P Cᵀ − D X_P Dᵀ = D X_P Oᵀ + O X_P Dᵀ + O X_P Oᵀ, and
with t = tr(O X_P Oᵀ) (X_P is positive definite) ‖D X_P Oᵀ‖_F <= ‖D X_P^{1/2}‖₂ ‖X_P^{1/2} Oᵀ‖_F
= ‖D X_P Dᵀ‖₂^{1/2} t^{1/2} and ‖O X_P Oᵀ‖_F <= t, so the dropped part is at most
2 (max_a ‖S_a‖_F t)^{1/2} + t, S_a the computed blocks; t costs one pass over the sparse O's
normal matrices, nothing dense (:func:`_off_energy`). The pencils take
the blocks where that bound, relative to the blocks' own norm, is at most :data:`RELATIVE_DROP`
(a quarter of :data:`~.reflection.INVARIANCE_RTOL`, so that any sum of two terms stays within it); else the
caller computes the whole sandwich (:func:`parity_sandwich` returns None).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .threaded import symmetric_part, symmetric_sandwich

INVARIANCE_RTOL = 1e-11
"""Largest (Σ_{a<b} ‖Q_aᵀ M Q_b‖_F²)^{1/2} / ‖M‖_F (the blocks the split drops) for which S
and G count as reflection invariant (:mod:`.reflection`, which takes it from here)."""
RELATIVE_DROP = INVARIANCE_RTOL / 4
"""Largest bound on the dropped part of one term, relative to the Frobenius norm of its blocks
(a combination Σ T_i / c_i of two terms is then within :data:`INVARIANCE_RTOL`)."""


@dataclass(frozen=True)
class ParityOperator:
    """A symmetric m × m operator kept in the components Q_a of a reflection split.

    Attributes
    ----------
    blocks : tuple of ndarray
        Q_aᵀ M Q_a, one per component (0 × 0 where the component is empty).
    dropped : float
        An upper bound on ‖Qᵀ M Q − diag(blocks)‖_F (what the blocks leave out).
    bases : tuple of scipy.sparse matrices
        The Q_a (m × m_a).
    """

    blocks: tuple
    dropped: float
    bases: tuple

    @property
    def shape(self) -> tuple:
        m = self.bases[0].shape[0]
        return (m, m)

    @property
    def norm(self) -> float:
        """‖diag(blocks)‖_F."""
        return float(np.sqrt(sum(np.linalg.norm(b) ** 2 for b in self.blocks)))

    @property
    def distance(self) -> float:
        """The dropped part relative to the operator (a lower bound of ‖M‖_F in the denominator:
        ‖diag(blocks)‖_F − dropped), as :meth:`~.reflection.ReflectionSplit.blocks` reports it
        of a whole matrix; inf where nothing is left."""
        scale = self.norm - self.dropped
        if self.dropped == 0.0:
            return 0.0
        return self.dropped / scale if scale > 0 else np.inf

    def __array__(self, dtype=None, copy=None):
        """The whole m × m matrix Σ_a Q_a M_a Q_aᵀ (a caller that needs it dense: none on the
        split routes, where the blocks serve)."""
        out = np.zeros(self.shape)
        for Q, M in zip(self.bases, self.blocks):
            if Q.shape[1]:
                Q = sp.csr_matrix(Q)
                out += Q @ (Q @ M).T
        return out if dtype is None else out.astype(dtype)


def combine(terms, scales) -> ParityOperator:
    """Σ_i T_i / c_i of :class:`ParityOperator` terms on one split, each block symmetrized (as
    :func:`~infsup_contact.solvers.interface_operator.combine_terms` does the whole matrix)."""
    blocks = []
    for a in range(len(terms[0].blocks)):
        total = 0.0
        for T, c in zip(terms, scales):
            total = total + T.blocks[a] / c
        blocks.append(symmetric_part(total) if np.ndim(total) == 2 and len(total) else np.zeros((0, 0)))
    dropped = float(sum(T.dropped / c for T, c in zip(terms, scales)))
    return ParityOperator(tuple(blocks), dropped, terms[0].bases)


def parity_sandwich(B, steklov_parts, bases) -> ParityOperator | None:
    """B X Bᵀ in the components ``bases`` (Q_a) of the multiplier space, from the Steklov inverse
    in the body's parity blocks ``steklov_parts`` ((P_c, X_c), ...): the blocks
    C_{aσ(a)} X_{σ(a)} C_{aσ(a)}ᵀ of the matching components (σ(a) the part carrying most of
    Q_aᵀ B; a bijection between the non-empty components, else None) and the bound on what they
    drop (module text); None where that bound exceeds :data:`RELATIVE_DROP`."""
    B = sp.csr_matrix(B)
    QT = [sp.csr_matrix(Q.T) for Q in bases]
    C = [[(QTa @ B @ P).tocsr() for P, _ in steklov_parts] for QTa in QT]
    sigma = _matching(C)
    if sigma is None:
        return None
    blocks = []
    for a, row in enumerate(C):
        D = row[sigma[a]] if sigma[a] is not None else None
        if D is None or not D.shape[0]:
            blocks.append(np.zeros((QT[a].shape[0],) * 2))
            continue
        blocks.append(symmetric_sandwich(D, steklov_parts[sigma[a]][1]))
    top = max((np.linalg.norm(b) for b in blocks if b.size), default=0.0)  # >= ‖D X_P Dᵀ‖₂
    t = _off_energy(C, sigma, [X for _, X in steklov_parts])                 # >= tr(O X_P Oᵀ)
    dropped = 2.0 * np.sqrt(top * t) + t
    out = ParityOperator(tuple(blocks), float(dropped), tuple(bases))
    return out if out.distance <= RELATIVE_DROP else None


def _off_energy(C, sigma, inverses) -> float:
    """An upper bound on tr(O X_P Oᵀ) = Σ_c ⟨X_c, Σ_{a: σ(a) ≠ c} C_acᵀ C_ac⟩ (O the blocks
    C_ac, c ≠ σ(a)): Σ |X_c|ᵢⱼ |M_c|ᵢⱼ over the nonzeros of the sparse M_c (no cancellation
    trusted)."""
    total = 0.0
    for c, X in enumerate(inverses):
        M = None
        for a, row in enumerate(C):
            if sigma[a] != c and row[c].nnz:
                part = (row[c].T @ row[c]).tocoo()
                M = part if M is None else (M + part).tocoo()
        if M is not None and M.nnz:
            total += float(np.sum(np.abs(X[M.row, M.col] * M.data)))
    return total


def strongest_components(norms) -> list | None:
    """σ(a) = argmax_c ``norms[a][c]`` for each row a (None for a row of zeros or an empty one),
    or None unless σ is one-to-one on the rows that carry anything: which component of an
    equivariant map's target holds each component of its source (the rest is round-off)."""
    sigma = [int(np.argmax(row)) if len(row) and max(row) > 0.0 else None for row in norms]
    taken = [c for c in sigma if c is not None]
    return sigma if len(taken) == len(set(taken)) else None


def _matching(C) -> list | None:
    """:func:`strongest_components` of the blocks C_ac by their Frobenius norms."""
    return strongest_components([[sp.linalg.norm(Cac) if Cac.nnz else 0.0 for Cac in row] for row in C])
