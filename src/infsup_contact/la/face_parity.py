"""The face's H Gram series in the four parity blocks of the axis reflections (large N).

Where both 1D factors of a tensor space M^x ⊗ M^y (:mod:`infsup_contact.discretization.face.spaces.tensor`; the piece space P of a
cellwise one, :mod:`infsup_contact.discretization.face.norms.cellwise`) are symmetric under x → 1 − x, i.e. the reflection
maps the basis onto itself (:func:`~infsup_contact.discretization.face_parity_bases.axis_parity`, found and checked as the face's reflections,
:func:`~infsup_contact.discretization.gamma.symmetry.induced_permutation`), their bases split into even and odd functions,
Q^x_e and Q^x_o (:func:`~infsup_contact.discretization.gamma.symmetry.isotypic_bases`). Because
sin(mπ(1 − x)) = (−1)^{m+1} sin(mπx), an even function has sine coefficients at odd m only, an
odd one at even m only. So the double series

    S(n) = Σ_{m, n' ≤ n} c_{m n'} c_{m n'}ᵀ / (π √(m² + n'²)),    c_{m n'} = c^x_m ⊗ c^y_{n'},

is block diagonal in the four bases T_c = Q^x_{p} ⊗ Q^y_{q} (c = p + 2q, bit set = odd), and
block c is the same separable sum over the odd or even m and n' alone, of the coefficients
(Q^x_p)ᵀ c^x and (Q^y_q)ᵀ c^y (:func:`parity_blocks`). Each block has about a quarter of
the dimension: the separable product (dim² r per block), its reordering, the Richardson steps and
the spectral norms that stop them (:class:`~.richardson.BlockOps`) cost about a quarter of the whole matrix's, and a cellwise
space's sandwich R S_P Rᵀ becomes R̃_c S_P,c R̃_cᵀ with R̃_c = Q_cᵀ R T_c (Q_c the multiplier
basis's own components under the same two reflections: R intertwines them, so the blocks
between different components vanish; checked, :func:`intertwined`). The Gram matrix is
assembled once at the end, G = Σ_c Q_c G_c Q_cᵀ (:func:`assemble`), or, inside
:func:`deferred_assembly` (a β_h request, whose pencils take the blocks), only where a consumer
reads it (:class:`ParityGram`: :func:`numpy.asarray` of it assembles it then, once). The coefficients the split
drops (an even function's at even m) are zero mathematically, round-off numerically: G agrees
with the unsplit series to round-off (tests/la/test_face_parity.py).
"""
from __future__ import annotations

import contextlib
import contextvars
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from .reflection import symmetric_permutation
from .threaded import concurrent_map, signed_gather_sum, symmetric_pairs, symmetric_part, symmetric_sandwich

INTERTWINE_RTOL = 1e-10
"""Largest ‖Q_aᵀ R T_b‖_F / ‖R‖_F (a ≠ b) for which R counts as intertwining the reflections."""


def tensor_bases(parities) -> list:
    """T_c = Q^x_p ⊗ Q^y_q, c = p + 2q (index a·dim M^y + b, as the tensor basis)."""
    (qx, qy) = parities
    return [sp.kron(qx[c & 1], qy[c >> 1], format="csr") for c in range(4)]


def parity_blocks(coeffs, index, weights_on) -> list:
    """[S_c(n_max)], c = 0..3: the four parity blocks of the double sine series (module text) from
    the factors' coefficients in the parity bases, ``coeffs[axis][p]`` = (Q_p)ᵀ c (dim_p × len(index[p])),
    and the sine indices ``index`` = (odd m, even m). The weights 1/(π√(m² + n²)) come as one
    separable sum for the four blocks, ``weights_on(x_lo, x_hi)`` on the range of all of them
    (``columns(M, squares)`` = M E, ``scaled(L)`` = L D, :class:`~infsup_contact.discretization.face.norms.tensor.SeparableWeights`):
    so each parity's products c ⊗ c and their columns are made once per direction, not once
    per block (the y direction's are the x direction's where the two factors are the same), and
    block c = p + 2q is scaled(columns_x[p]) · columns_y[q]ᵀ."""
    squares = [np.asarray(idx, dtype=float) ** 2 for idx in index]
    ends = [(s[0], s[-1]) for s in squares]
    weights = weights_on(min(a[0] + b[0] for a in ends for b in ends), max(a[1] + b[1] for a in ends for b in ends))

    def columns(cs):  # per parity: (c ⊗ c) E, the products dropped once their columns are made
        return concurrent_map(lambda cx: weights.columns((cx[0][:, None, :] * cx[0][None, :, :]).reshape(
            cx[0].shape[0] ** 2, -1), cx[1]), list(zip(cs, squares)))

    # the parities' columns, then the blocks, side by side (GIL-free products, one BLAS thread each)
    left = columns(coeffs[0])
    same = all(np.array_equal(a, b) for a, b in zip(coeffs[0], coeffs[1]))
    right = left if same else columns(coeffs[1])
    scaled = concurrent_map(weights.scaled, left)
    return concurrent_map(lambda c: symmetric_pairs(scaled[c & 1] @ right[c >> 1].T, coeffs[0][c & 1].shape[0],
                                                    coeffs[1][c >> 1].shape[0]), range(4))


def intertwined(R: sp.csr_matrix, Qs, Ts) -> list | None:
    """[R̃_c = Q_cᵀ R T_c] where every block Q_aᵀ R T_b (a ≠ b) is at most
    :data:`INTERTWINE_RTOL` of R (Frobenius), else None."""
    scale = sp.linalg.norm(R)
    out = []
    for a, Q in enumerate(Qs):
        left = (Q.T @ R).tocsr()
        for b, T in enumerate(Ts):
            block = (left @ T).tocsr()
            if a == b:
                out.append(block)
            elif sp.linalg.norm(block) > INTERTWINE_RTOL * scale:
                return None
    return out


def sandwiched(Rs, blocks) -> list:
    """[R̃_c S_c R̃_cᵀ], symmetrised (:func:`~infsup_contact.la.threaded.symmetric_sandwich`)."""
    return [symmetric_part(symmetric_sandwich(R, S)) for R, S in zip(Rs, blocks)]


def assemble(bases, blocks) -> np.ndarray:
    """G = Σ_c Q_c G_c Q_cᵀ for isotypic bases (at most one nonzero per row each, ±1/√|orbit|):
    one signed gather per block (:func:`~infsup_contact.la.threaded.signed_gather_sum`),
    exactly symmetric."""
    index, sign = [], []
    for Q in bases:
        Q = sp.csr_matrix(Q)
        live = np.diff(Q.indptr) > 0
        if np.any(np.diff(Q.indptr) > 1):
            raise ValueError("an isotypic basis has at most one nonzero per row")
        idx, w = np.zeros(Q.shape[0], dtype=np.intp), np.zeros(Q.shape[0])
        idx[live], w[live] = Q.indices, Q.data
        index.append(idx)
        sign.append(w)
    return signed_gather_sum([np.asarray(B, dtype=float) for B in blocks], index, sign)


SIGNED_PERMUTATION_RTOL = 1e-12
"""Largest | |entry| − 1 | of Q_cᵀ Q'_c for which two orthonormal bases of one component count
as the same columns up to order and sign (:meth:`ParityGram.in_bases`)."""


_DEFERRED = contextvars.ContextVar("face_parity_deferred", default=False)


@contextlib.contextmanager
def deferred_assembly():
    """Inside: a Gram summed in parity blocks (:func:`gram_of`) is returned as its
    :class:`ParityGram`, assembled only where a consumer reads the dense G (``np.asarray(G)``,
    :func:`dense`); a β_h request's pencils take the blocks and never do (5 of 89 CPU-s at k = 2,
    N = 32 went into assembling 12 full Grams nobody read)."""
    token = _DEFERRED.set(True)
    try:
        yield
    finally:
        _DEFERRED.reset(token)


def gram_of(bases, blocks) -> tuple:
    """(G, :class:`ParityGram`) of a Gram summed in the parity blocks ``blocks`` of ``bases``: G
    assembled (:func:`assemble`), or inside :func:`deferred_assembly` the ParityGram itself."""
    parity = ParityGram(bases, blocks)
    return (parity if _DEFERRED.get() else assemble(parity.bases, parity.blocks)), parity


def deferring() -> bool:
    """Whether a Gram summed in parity blocks is returned unassembled (:func:`deferred_assembly`)."""
    return _DEFERRED.get()


def dense(G) -> np.ndarray:
    """The dense matrix of a Gram: G itself, or a :class:`ParityGram`'s assembled matrix."""
    return G.dense if isinstance(G, ParityGram) else G


def diagonal(G) -> np.ndarray:
    """The diagonal of a Gram: ``np.diag`` of a dense one; a :class:`ParityGram`'s own
    (:meth:`ParityGram.diagonal`: without assembling it where it knows how)."""
    return G.diagonal() if isinstance(G, ParityGram) else np.diag(G)


class ParityGram:
    """A Gram matrix in the four parity blocks it was summed in: G = Σ_c Q_c G_c Q_cᵀ
    (``bases`` Q_c with orthonormal columns, at most one nonzero per row; ``blocks`` G_c).
    Carried in the Gram's ``info["parity"]`` so that the pencils (:func:`~.reflection.usable`)
    take the blocks as summed instead of splitting the assembled G again; inside
    :func:`deferred_assembly` also in place of G, which it assembles on first use (:attr:`dense`,
    ``np.asarray``: the same matrix as :func:`assemble`, read-only: it is shared)."""

    ndim = 2
    dtype = np.dtype(float)

    def __init__(self, bases, blocks):
        self.bases = tuple(sp.csr_matrix(Q) for Q in bases)
        self.blocks = tuple(np.asarray(B, dtype=float) for B in blocks)

    @property
    def shape(self) -> tuple:
        return (self.bases[0].shape[0],) * 2

    @property
    def nbytes(self) -> int:
        """The blocks' bytes (about a quarter of the dense G's; constant, for a cache's count)."""
        return sum(B.nbytes for B in self.blocks)

    @cached_property
    def dense(self) -> np.ndarray:
        """G = Σ_c Q_c G_c Q_cᵀ (:func:`assemble`), once."""
        G = assemble(self.bases, self.blocks)
        G.setflags(write=False)
        return G

    def diagonal(self) -> np.ndarray:
        """The diagonal of G (of the assembled matrix: its entries, bit for bit)."""
        return np.diag(self.dense)

    def __array__(self, dtype=None, copy=None):
        return self.dense if dtype is None else self.dense.astype(dtype, copy=False)

    def in_bases(self, bases) -> list | None:
        """[Q'_cᵀ G Q'_c] for the bases Q'_c of the same components (another order of the
        columns, other signs: the reflections' split, :class:`~.reflection.ReflectionSplit`),
        each a signed gather of the G_c whose component holds it; None where a Q'_c is not such
        a signed permutation of one Q_c (the caller splits G itself)."""
        out = []
        for Qs in bases:
            Qs = sp.csc_matrix(Qs)
            hits = [c for c, Q in enumerate(self.bases) if (Q.T @ Qs).count_nonzero()]
            if len(hits) != 1 or self.bases[hits[0]].shape[1] != Qs.shape[1]:
                return None
            c = hits[0]
            P = sp.csc_matrix(self.bases[c].T @ Qs)
            P.eliminate_zeros()
            if np.any(np.diff(P.indptr) != 1) or np.any(np.abs(np.abs(P.data) - 1.0) > SIGNED_PERMUTATION_RTOL):
                return None
            idx, sign = P.indices, np.sign(P.data)  # column j of Q' is sign[j] times column idx[j] of Q_c
            if len(np.unique(idx)) != len(idx):
                return None
            block = symmetric_permutation(self.blocks[c], idx)
            out.append(block if np.all(sign > 0) else block * np.multiply.outer(sign, sign))
        return out
