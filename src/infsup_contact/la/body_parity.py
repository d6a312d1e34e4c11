"""A body's Γ-last factorization split by its symmetries: the parity parts, factorized one by one.

Let commuting involutions π_1, ..., π_g (g = 1 or 2) of a body's free dofs (Γ last) commute with
its stiffness, P_b K P_bᵀ = K for every element P_b of the group they generate, and map Γ dofs to
Γ dofs (the reflections x → 1 − x, y → 1 − y of the structured hexahedra; found and checked in
:mod:`infsup_contact.models.body_symmetry`). In the orthonormal isotypic basis Q = [Q_0, ..., Q_{2^g − 1}]
(:func:`~infsup_contact.discretization.gamma.symmetry.isotypic_bases`, the characters of Z2^g,
as :class:`~.reflection.ReflectionSplit` uses it for the pencils) K is block diagonal,
K_c = Q_cᵀ K Q_c. An orbit of the group lies wholly in Γ or wholly in the interior, so every column
of Q_c is a Γ column or an interior one: ordered interior first, K_c is again a Γ-last matrix, and

    S = Σ_c Q_{c,Γ} S_c Q_{c,Γ}ᵀ,    K⁻¹ = Σ_c Q_c K_c⁻¹ Q_cᵀ,

with S_c the Γ Schur complement of K_c (exact algebra: Q is orthogonal and S commutes with the
group; the same S as the whole body's to the factorization's round-off, in another elimination
order). Each part is about 1/2^g of the body: a 3D nested-dissection factorization costs about
(1/2^g)² of the whole one per part and the dense Schur block (1/2^g)³, so the four parts of the
hexahedra need about a sixth of the flops (PARDISO's count, k = 2, N = 32: 875 → 133 GFLOP).

The parts are independent calls (:meth:`ParityParts.factorize` takes a ``map``: the built-in one
factorizes them one by one, a thread pool's runs them side by side — PARDISO releases the GIL).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .threaded import concurrent_map


@dataclass(frozen=True)
class ParityPart:
    """One isotypic component c of a body: K_c = Q_cᵀ K Q_c (Γ columns last) and its basis.

    Attributes
    ----------
    stiffness : scipy.sparse.csc_matrix
        K_c, interior columns first, then ``n_gamma`` Γ columns.
    n_gamma : int
        Γ columns of Q_c.
    basis : scipy.sparse.csr_matrix
        Q_c (n × n_c, orthonormal columns), in the column order of ``stiffness``.
    """

    stiffness: sp.csc_matrix
    n_gamma: int
    basis: sp.csr_matrix


@dataclass(frozen=True)
class ParityParts:
    """The parts of a body (:func:`parity_parts`) and how their factorizations make the body's."""

    parts: tuple
    n: int
    n_gamma: int

    def factorize(self, factorize_one, map=map) -> tuple:
        """(S, solve, X, X's blocks) of the body from ``factorize_one(K_c, n_gamma_c)`` of every
        part, which returns an object with ``schur``, ``solve`` and ``steklov`` (a
        :class:`~.schur.GammaFactorization`); ``map`` runs the independent calls (module text).
        X = S⁻¹ = Σ_c Q_{c,Γ} S_c⁻¹ Q_{c,Γ}ᵀ from the parts' own inverses (a part's ``steklov``, else
        potri of S_c): (1/2^g)³ of the work each, where the side would otherwise invert the whole
        S for its products (:class:`~.schur.SteklovProduct`). X's blocks: ((Q_{c,Γ}, S_c⁻¹), ...),
        each S_c⁻¹ exactly symmetric, for the sandwiches in parity blocks (:mod:`.parity_sandwich`)."""
        facs = list(map(lambda part: factorize_one(part.stiffness, part.n_gamma), self.parts))
        gammas = [part.basis[self.n - self.n_gamma:] for part in self.parts]
        tails = [Q[:, Q.shape[1] - part.n_gamma:].tocsr() for Q, part in zip(gammas, self.parts)]
        inverses = concurrent_map(lambda f: f.steklov if f.steklov is not None else spd_inverse(f.schur), facs)
        # S and X side by side (numpy's gathers and products, GIL-free: the same bits)
        S, X = concurrent_map(lambda Ms: self._sum(tails, Ms), [[f.schur for f in facs], inverses])
        blocks = tuple((P, _exactly_symmetric(Xc)) for P, Xc in zip(tails, inverses))
        return S, _PartsSolve(self.parts, [f.solve for f in facs]), X, blocks

    def _sum(self, tails, blocks) -> np.ndarray:
        """Σ_c Q_{c,Γ} M_c Q_{c,Γ}ᵀ (dense n_Γ × n_Γ), symmetrized: :func:`orbit_sandwich_sum`
        where every row of every Q_{c,Γ} holds one entry at most (a dof lies in one orbit), else
        :func:`sandwich_sum` (the same bits)."""
        if all(np.diff(Q.indptr).max(initial=0) <= 1 for Q in tails) and all(
                np.isfinite(M).all() for Q, M in zip(tails, blocks) if Q.shape[1]):
            return orbit_sandwich_sum(tails, blocks, self.n_gamma)
        return sandwich_sum(tails, blocks, self.n_gamma)


def sandwich_sum(tails, blocks, n_gamma: int) -> np.ndarray:
    """½ (A + Aᵀ), A = Σ_c Q_c (Q_c M_c)ᵀ (M_c symmetric: Q_c M_c Q_cᵀ) by scipy's sparse × dense
    products: the reference route of :func:`orbit_sandwich_sum`."""
    out = np.zeros((n_gamma, n_gamma))
    for Q, M in zip(tails, blocks):
        if Q.shape[1]:
            out += Q @ (Q @ np.asarray(M)).T
    return 0.5 * (out + out.T)


ROWS = 128
"""Rows of the result per block of :func:`orbit_sandwich_sum` (a block of n_Γ ≤ 10⁴ columns stays
within a few MB)."""


def orbit_sandwich_sum(tails, blocks, n_gamma: int) -> np.ndarray:
    """:func:`sandwich_sum` bit for bit where each row r of each Q_c holds one entry q_r at
    column j_r at most (else q_r = 0, j_r = 0) and every M_c is finite: the sparse products add
    each product to a zero, so (Q_c (Q_c M_c)ᵀ)_{rs} = 0 + q_r (0 + q_s M_c[j_s, j_r]), formed
    here row block by row block from M_cᵀ's entries, and symmetrized in place tile by tile — no
    n_Γ × n_c or n_Γ × n_Γ temporary and no strided pass over a whole transposed matrix."""
    out = np.zeros((n_gamma, n_gamma))
    for Q, M in zip(tails, blocks):
        if not Q.shape[1]:
            continue
        Mt = np.ascontiguousarray(np.asarray(M, dtype=float).T)
        has = np.diff(Q.indptr) > 0
        q = np.zeros(n_gamma)
        j = np.zeros(n_gamma, dtype=np.intp)
        q[has], j[has] = Q.data[Q.indptr[:-1][has]], Q.indices[Q.indptr[:-1][has]]
        for a in range(0, n_gamma, ROWS):
            r = slice(a, min(a + ROWS, n_gamma))
            term = np.take(Mt[j[r]], j, axis=1)  # (r, s) ↦ M_c[j_s, j_r]
            term *= q
            term += 0.0
            term *= q[r, None]
            term += 0.0
            out[r] += term
    for a in range(0, n_gamma, ROWS):  # ½ (out + outᵀ) in place, a tile and its mirror at a time
        r = slice(a, min(a + ROWS, n_gamma))
        for b in range(a, n_gamma, ROWS):
            c = slice(b, min(b + ROWS, n_gamma))
            upper = out[r, c].copy()
            np.multiply(0.5, upper + out[c, r].T, out=out[r, c])
            if b != a:
                np.multiply(0.5, out[c, r] + upper.T, out=out[c, r])
    return out


def _exactly_symmetric(X) -> np.ndarray:
    """½ (X + Xᵀ) of a square dense X (a no-op on the bits of an exactly symmetric one)."""
    X = np.asarray(X, dtype=float)
    return 0.5 * (X + X.T)


def spd_inverse(S: np.ndarray) -> np.ndarray:
    """S⁻¹ of an SPD matrix by LAPACK potrf and potri (both triangles filled)."""
    if S.shape[0] == 0:
        return np.zeros((0, 0))
    c, info = sla.lapack.dpotrf(S, lower=False)
    if info == 0:
        c, info = sla.lapack.dpotri(c, lower=False)
    if info != 0:
        raise np.linalg.LinAlgError(f"potrf/potri failed (info = {info}) on a part's Schur complement")
    X = np.triu(c)
    return X + np.triu(X, 1).T


class _PartsSolve:
    """b ↦ K⁻¹ b = Σ_c Q_c K_c⁻¹ Q_cᵀ b from the parts' solves (vectors or columns)."""

    def __init__(self, parts, solves):
        self.parts, self.solves = parts, solves

    def __call__(self, b):
        b = np.asarray(b, dtype=float)
        out = np.zeros_like(b)
        for part, solve in zip(self.parts, self.solves):
            if part.basis.shape[1]:
                out += part.basis @ solve(np.asarray(part.basis.T @ b))
        return out


CONGRUENCE_ROWS = 4096
"""Rows of Q_cᵀ K Q_c per block of :func:`congruence` (at most four orbits' worth of K's rows each:
the block's K Q_c, a few tens of MB, instead of one the size of K for every part)."""


def congruence(K: sp.csr_matrix, Q: sp.csr_matrix) -> sp.csr_matrix:
    """Qᵀ (K Q), CSR, as scipy's ``Q.T.tocsr() @ (K @ Q)`` gives it, to the order of its stored
    entries (the reference route; tested), row block by row block: the rows A of Qᵀ need the rows
    I of K Q where they hold entries (I sorted), and the product adds row by row, each row of
    K[I] Q is that row of K Q and the entries of a row of Qᵀ keep their order, so every block is
    those rows of the whole product."""
    Qt = Q.T.tocsr()
    blocks = []
    for a in range(0, Qt.shape[0], CONGRUENCE_ROWS):
        rows = Qt[a:a + CONGRUENCE_ROWS]
        support = np.unique(rows.indices)
        local = sp.csr_matrix((rows.data, np.searchsorted(support, rows.indices).astype(rows.indices.dtype),
                               rows.indptr), shape=(rows.shape[0], support.size))
        blocks.append((local @ (K[support] @ Q)).tocsr())
    if not blocks:
        return sp.csr_matrix((0, Q.shape[1]))
    return sp.vstack(blocks, format="csr")


def parity_parts(K, n_gamma: int, bases) -> ParityParts:
    """The isotypic parts of the Γ-last SPD ``K`` in the ``bases`` (Q_0, ...) of its group
    (:func:`~infsup_contact.discretization.gamma.symmetry.isotypic_bases` of involutions of its
    dofs that map Γ, the last ``n_gamma``, onto Γ and commute with K: checked by the caller).
    Each part's columns are ordered interior first (an orbit never mixes the two), K_c symmetrized."""
    K = sp.csr_matrix(K)
    n = K.shape[0]

    def part(Q):
        Q = Q.tocsc()
        first_row = Q.indices[Q.indptr[:-1]] if Q.shape[1] else np.zeros(0, int)
        on_gamma = first_row >= n - n_gamma
        Q = Q[:, np.concatenate([np.flatnonzero(~on_gamma), np.flatnonzero(on_gamma)])].tocsr()
        if Q.shape[1] == 0:
            return None
        Kc = congruence(K, Q)
        Kc = (0.5 * (Kc + Kc.T.tocsr())).tocsc()  # symmetric to the last bit: the solves' LU sees it whole
        Kc.sort_indices()
        return ParityPart(Kc, int(on_gamma.sum()), Q)

    # the parts side by side (sparse products, GIL-free: each part the same operations, the same bits)
    parts = [p for p in concurrent_map(part, list(bases)) if p is not None]
    return ParityParts(tuple(parts), n, int(n_gamma))
