"""Richardson extrapolation of a series of Gram matrices in its truncation n_max, and the
spectral norm that stops it (the segment's sine series, :mod:`.norms`; the face's double
series, :mod:`.face_norms`, whole or in the parity blocks of :mod:`.face_parity`)."""
from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from ..errors import InputError
from ..la.threaded import elementwise


def extrapolate(partial, p: float, n0: int, n_cap: int, rtol: float, ops=None) -> tuple[np.ndarray, dict]:
    """Richardson extrapolation of a series of Gram matrices with a tail ~ C n^{−p}: the partial
    sums S(n) = ``partial(n)`` at n = n0, 2n0, 4n0, ... (asked in increasing n), extrapolated
    R(n) = S(2n) + (S(2n) − S(n)) / (2^p − 1), until ‖R(2n) − R(n)‖₂ / ‖R(2n)‖₂ ≤ rtol or 2n
    would pass ``n_cap`` (:func:`~.norms.gram_h`; the face's double series, :mod:`.face_norms`).

    ``ops``: the step, difference and spectral norm for another representation of the partial
    sums (an object with ``step(hi, lo, divisor)``, ``diff(a, b)``, ``norm2(a)``; the face's
    parity blocks, :class:`~.face_parity.BlockOps`), default :class:`DenseOps`.

    Returns
    -------
    R : ndarray (or what ``partial`` returns)
    info : dict
        ``n_max``, ``nmax_rel_error`` (before two extrapolations exist, the size of the
        extrapolation step), ``capped`` (the estimate still above rtol at the cap), ``n_start``.

    Raises
    ------
    InputError
        For n0 or n_cap < 1.
    """
    if n0 < 1 or n_cap < 1:
        raise InputError("n_start/n_cap", "positive integers", got=(n0, n_cap))
    n0 = min(n0, n_cap)
    divisor = 2.0 ** p - 1.0
    s_lo, n_hi = partial(n0), min(2 * n0, n_cap)
    s_hi = partial(n_hi)
    ops = DenseOps if ops is None else ops
    r_prev = ops.step(s_hi, s_lo, divisor)  # R(n) = S(2n) + (S(2n) − S(n)) / (2^p − 1)
    err = ops.norm2(ops.diff(r_prev, s_hi)) / ops.norm2(r_prev)
    capped = False
    while True:
        if 2 * n_hi > n_cap:
            capped = err > rtol
            break
        s_lo, s_hi, n_hi = s_hi, partial(2 * n_hi), 2 * n_hi
        r = ops.step(s_hi, s_lo, divisor)
        err = ops.norm2(ops.diff(r, r_prev)) / ops.norm2(r)
        r_prev = r
        if err <= rtol:
            break
    return r_prev, {"n_max": int(n_hi), "nmax_rel_error": float(err), "capped": bool(capped),
                    "n_start": int(n0)}


class DenseOps:
    """:func:`extrapolate`'s operations on dense matrices: threaded element-wise passes (bit for
    bit numpy's, :func:`~infsup_contact.la.threaded.elementwise`) and :func:`_norm2`."""

    @staticmethod
    def step(hi, lo, divisor):
        return elementwise(lambda a, b: a + (a - b) / divisor, hi, lo)

    @staticmethod
    def diff(a, b):
        return elementwise(np.subtract, a, b)

    @staticmethod
    def norm2(a):
        return _norm2(a)


class BlockOps:
    """:func:`extrapolate`'s operations on lists of diagonal blocks (:mod:`.face_parity`): the
    step and the difference block by block, the spectral norm the largest block's."""

    @staticmethod
    def step(hi, lo, divisor):
        return [DenseOps.step(h, l, divisor) for h, l in zip(hi, lo)]

    @staticmethod
    def diff(a, b):
        return [DenseOps.diff(x, y) for x, y in zip(a, b)]

    @staticmethod
    def norm2(blocks):
        return max(_norm2(B) for B in blocks)


NORM2_DENSE_MAX = 400
"""Largest order for which :func:`_norm2` takes all eigenvalues (LAPACK); above it Lanczos."""


def _norm2(A: np.ndarray) -> float:
    """Spectral norm of a symmetric matrix (largest |eigenvalue|).

    It only measures the Richardson step against ``rtol``, so six correct digits suffice: up
    to :data:`NORM2_DENSE_MAX` all eigenvalues (the segment's Grams, bit-for-bit as before),
    above it the largest-magnitude one by Lanczos (ARPACK, relative accuracy 1e-8), which
    costs O(n²) per step instead of a dense eigensolve (a face's Gram at N = 32 has n ≈ 4,000).
    """
    if len(A) <= NORM2_DENSE_MAX:
        return float(np.max(np.abs(np.linalg.eigvalsh(A))))
    start = np.ones(len(A)) / np.sqrt(len(A))  # a fixed start: the estimate is reproducible
    ncv = NORM2_SHORT_KRYLOV if len(A) > NORM2_SHORT_KRYLOV_MIN else None
    return float(abs(spla.eigsh(A, k=1, which="LM", tol=1e-8, v0=start, ncv=ncv,
                                return_eigenvectors=False)[0]))


NORM2_SHORT_KRYLOV_MIN = 1500
"""Order above which :func:`_norm2` restarts Lanczos with :data:`NORM2_SHORT_KRYLOV` vectors
instead of ARPACK's default 20: the top of a Gram matrix (or of a Richardson step) is well
separated, 11 products reach the same 1e-8 where the default takes 21 (a dense product is 12 ms
at order 4,225); the default DAG's Grams, all below, keep their digits."""
NORM2_SHORT_KRYLOV = 10
