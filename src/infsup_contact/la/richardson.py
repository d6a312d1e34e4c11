"""Richardson extrapolation of a series of Gram matrices in its truncation n_max, and the
relative step in the Gram's own metric that stops it and bounds its error (the segment's sine series, :mod:`.norms`; the face's double
series, :mod:`infsup_contact.discretization.face.norms.tensor`, whole or in the parity blocks of :mod:`.face_parity`)."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla
from scipy.linalg import blas

from ..errors import InputError
from . import openblas
from .threaded import concurrent_map, elementwise


def extrapolate(partial, p: float, n0: int, n_cap: int, rtol: float, ops=None) -> tuple[np.ndarray, dict]:
    """Richardson extrapolation of a series of Gram matrices with a tail ~ C n^{−p}: the partial
    sums S(n) = ``partial(n)`` at n = n0, 2n0, 4n0, ... (asked in increasing n), extrapolated
    R(n) = S(2n) + (S(2n) − S(n)) / (2^p − 1) and once more for a term n^{−(p+1)}
    (:func:`romberg_row`, :data:`STAGES`), until the stated error :func:`lookahead_bound`
    of the newest R is ≤ rtol or 2n would pass ``n_cap`` (:func:`~.norms.gram_h`; the face's
    double series, :mod:`infsup_contact.discretization.face.norms.tensor`).

    The steps are measured in the Gram's own metric, δ = ‖R^{−1/2} (R(2n) − R(n)) R^{−1/2}‖₂
    (:func:`relative_step`), not against ‖R‖₂: (1 − ε) G ≤ R ≤ (1 + ε) G in the Loewner order
    moves every eigenvalue of every pencil S m = β² R m by a factor within [1/(1 + ε), 1/(1 − ε)],
    whatever S is (each norm's c pairs, kernel or not), so a bound on ε is a bound on the row's
    β² and on β (half of it, to first order). ‖R(2n) − R(n)‖₂/‖R‖₂ is not: it weighs the error
    by the Gram's largest eigenvalue, and the bottom of the spectrum, where β lives, has a
    relative error up to cond(G) times larger (T5, k = 2, hexahedra, N = 20: β 2.7e-5 off, 9.7e-7
    stated).

    ``ops``: the step, difference and relative steps for another representation of the partial
    sums (an object with ``step(hi, lo, divisor)``, ``diff(a, b)``, ``rel_norms(es, r)``; the face's
    parity blocks, :class:`BlockOps`), default :class:`DenseOps`.

    Returns
    -------
    R : ndarray (or what ``partial`` returns)
    info : dict
        ``n_max``; ``nmax_rel_error``, the stated bound on the relative error of every eigenvalue
        of a pencil with R (:func:`lookahead_bound` of the last two steps; before two steps exist,
        the last step itself; inf where the steps stopped shrinking); ``capped`` (the bound still
        above rtol at the cap, or not yet confirmed by two steps); ``n_start``.

    Raises
    ------
    InputError
        For n0 or n_cap < 1.
    """
    if n0 < 1 or n_cap < 1:
        raise InputError("n_start/n_cap", "positive integers", got=(n0, n_cap))
    ops = DenseOps if ops is None else ops
    n, row, last = min(n0, n_cap), None, {}
    while True:
        row_prev, row = row, romberg_row(partial(n), row, p, ops)
        best, err, confirmed = len(row) - 1, np.inf, False
        if len(row) > 1:
            stages = [i for i in range(1, len(row)) if row_prev is not None and i < len(row_prev)]
            # each stage's step since the level before, all in the metric of the deepest entry
            steps = ops.rel_norms([ops.diff(row[i], row_prev[i]) for i in stages], row[-1]) if stages else []
            bounds = {i: (lookahead_bound(d, last.get(i)), i in last) for i, d in zip(stages, steps)}
            last = dict(zip(stages, steps))
            done = {i: b for i, (b, c) in bounds.items() if c}
            if done:  # the stage with the smallest confirmed bound
                best = min(done, key=lambda i: (done[i], -i))
                err, confirmed = done[best], True
            elif stages:
                err = bounds[best][0] if best in bounds else max(b for b, _ in bounds.values())
            elif 2 * n > n_cap:  # the first level with an extrapolation, and the last: its size
                err = ops.rel_norms([ops.diff(row[-1], row[-2])], row[-1])[0]
            # else: nothing confirmed, the loop goes on, and this size enters no later bound
        if (confirmed and err <= rtol) or 2 * n > n_cap:
            break
        n *= 2
    return row[best], {"n_max": int(n), "nmax_rel_error": float(err),
                       "capped": bool(not (confirmed and err <= rtol)), "n_start": int(min(n0, n_cap))}


STAGES = 2
"""Richardson stages (the columns of the Romberg table): the tail C n^{−p} (p = 2 where a basis
function jumps or does not vanish on ∂Γ, 4 for the smooth ones), then a term n^{−(p+1)}. On the
face's p = 2 series (T5, R5.4, k = 2, N = 8) one stage converges by 1/8 a level and two by 1/9
to 1/15, so the bound reaches 1e-6 three levels earlier; a stage whose term is absent (T3's
next term is n^{−6}) neither gains nor loses. Each level states the smaller confirmed bound of
the two stages (and returns that stage's matrix): the first stage's is confirmed two levels
earlier, where a fast series (T3) already stops."""


def romberg_row(S: np.ndarray, previous: list | None, p: float, ops) -> list:
    """The Romberg table's row of the partial sum S = S(n): [S, T_1, ..., T_j] with
    T_i = T_{i−1} + (T_{i−1} − T'_{i−1}) / (2^{q_i} − 1), q_i = p + i − 1, T' the row of n/2
    (``previous``, None at the first level), up to :data:`STAGES` extrapolations."""
    row = [S]
    for i in range(min(STAGES, 0 if previous is None else len(previous))):
        row.append(ops.step(row[i], previous[i], 2.0 ** (p + i) - 1.0))
    return row


def lookahead_bound(step: float, previous: float | None) -> float:
    """The stated relative error of the newest extrapolation R_j, from its last step
    δ_j = ‖R_j − R_{j−1}‖ (in R_j's metric) and the one before, δ_{j−1}.

    Where the extrapolations converge geometrically with the ratio ρ = δ_j / δ_{j−1} the level
    before showed (one level of look-ahead), R_j's remaining error is
    Σ_{i≥1} ρ^i δ_j = δ_j ρ / (1 − ρ); the bound states max(δ_j, 2 δ_j ρ / (1 − ρ)), the factor 2
    for a ratio still drifting upward (a tail slower than the extrapolation assumes: Σ n^{−3/2}
    with p = 2 has ρ → 1/√2 from below, and δ ρ / (1 − ρ) alone came out 1 % short of the error
    at n = 65,536). It is the step itself while ρ ≤ 1/3 (the face's p = 2 series: ρ ≈ 1/13, the
    step over-states the error about 12-fold) and grows without limit as the steps stop
    shrinking (inf at ρ ≥ 1: no bound).
    Without an earlier step (``previous`` None) it is the step alone, not yet confirmed."""
    if previous is None:
        return step
    if step == 0.0:
        return 0.0
    rho = step / previous if previous > 0 else np.inf
    return float(np.inf) if rho >= 1.0 else step * max(1.0, 2.0 * rho / (1.0 - rho))


class DenseOps:
    """:func:`extrapolate`'s operations on dense matrices: threaded element-wise passes (bit for
    bit numpy's, :func:`~infsup_contact.la.threaded.elementwise`) and :func:`relative_steps`."""

    @staticmethod
    def step(hi, lo, divisor):
        return elementwise(lambda a, b: a + (a - b) / divisor, hi, lo)

    @staticmethod
    def diff(a, b):
        return elementwise(np.subtract, a, b)

    @staticmethod
    def rel_norms(es, r):
        return relative_steps(es, r)


class BlockOps:
    """:func:`extrapolate`'s operations on lists of diagonal blocks (:mod:`.face_parity`): the
    step and the difference block by block, the relative step the largest block's."""

    @staticmethod
    def step(hi, lo, divisor):
        return [DenseOps.step(h, l, divisor) for h, l in zip(hi, lo)]

    @staticmethod
    def diff(a, b):
        return [DenseOps.diff(x, y) for x, y in zip(a, b)]

    @staticmethod
    def rel_norms(es, grams):
        # G = Q diag(blocks) Qᵀ with Q orthogonal: the Loewner order holds block by block; the
        # blocks side by side (potrf and the Lanczos steps by la/openblas.py, GIL-free, one BLAS thread each: the same bits)
        per_block = concurrent_map(lambda b: relative_steps([e[b] for e in es], grams[b], BLOCK_DENSE_MAX),
                                   [b for b, R in enumerate(grams) if len(R)])
        return [max((v[j] for v in per_block), default=0.0) for j in range(len(es))]


BLOCK_DENSE_MAX = 128
"""Largest block order for which :class:`BlockOps` takes all eigenvalues of the standard form
(:func:`relative_step`); above it Lanczos on x ↦ L⁻¹ E L⁻ᵀ x with L made once for both
stages, as the whole matrices above :data:`RELATIVE_DENSE_MAX`. The step only has to be known to a
few digits against ``rtol`` (Lanczos: :data:`STEP_LANCZOS_TOL`); the dense route's two triangular solves
with a full right-hand side and a full eigensolve cost 2n³ + 4n³/3 flops per step, the Lanczos
route n³/3 (L, shared) plus a few dozen O(n²) steps: at k = 2, N = 16 (blocks of ~270) the
stopping test of the 12 spaces took 0.7 CPU-s instead of 3.1. Up to 128 (every face space of the
default DAG, N <= 10: blocks <= 121) the dense route stays, so their stated errors keep their
digits to round-off; the whole matrices (the segment's Grams) keep :data:`RELATIVE_DENSE_MAX`."""


def relative_step(E: np.ndarray, R: np.ndarray) -> float:
    """‖L⁻¹ E L⁻ᵀ‖₂ for R = L Lᵀ (symmetric E, positive definite R): the smallest ε with
    −ε R ≤ E ≤ ε R, i.e. the largest relative change E makes to an eigenvalue of any pencil
    with R (:func:`extrapolate`). inf where R is not numerically positive definite (an early
    partial sum that does not yet resolve every basis function).

    Up to :data:`RELATIVE_DENSE_MAX` the whole standard form L⁻¹ E L⁻ᵀ and its eigenvalues
    (LAPACK), above it the largest-magnitude eigenvalue by Lanczos on x ↦ L⁻¹ E L⁻ᵀ x (two
    triangular solves and a product a step, O(n²); ARPACK's default 20 vectors, residual
    tolerance :data:`STEP_LANCZOS_TOL`)."""
    return relative_steps([E], R)[0]


def relative_steps(Es: list, R: np.ndarray, dense_max: int | None = None) -> list:
    """:func:`relative_step` of each of ``Es`` against one R, its Cholesky factor made once (for
    every E: the standard forms up to ``dense_max``, default :data:`RELATIVE_DENSE_MAX`, Lanczos
    above)."""
    L, info = openblas.potrf(np.asarray(R, float))  # without the GIL: the blocks side by side
    if info:
        return [float(np.inf)] * len(Es)
    dense_max = RELATIVE_DENSE_MAX if dense_max is None else dense_max
    L = np.asfortranarray(L)
    if len(L) <= dense_max:
        return [_standard_form_norm(E, L) for E in Es]
    return [_lanczos_norm(E, L) for E in Es]


def _lanczos_norm(E: np.ndarray, L: np.ndarray) -> float:
    """max |λ| of L⁻¹ E L⁻ᵀ by Lanczos (a fixed start; a step: two triangular solves, ``dtrsv``,
    and one product, O(n²)). The solves need no L⁻¹: at order 2,352 (a block of k = 2, N = 48)
    a step took 2.6 ms against 4.1 ms with L⁻¹ formed (dtrtri, 0.19 s more per block and level),
    and less at every order from 300 (one thread, OpenBLAS)."""
    def apply(x):  # scipy's dtrsv without the GIL (la/openblas.py): the blocks' steps overlap
        return openblas.trsv(L, E @ openblas.trsv(L, x, True, 1), True, 0)

    n = len(L)
    op = spla.LinearOperator((n, n), matvec=apply, dtype=float)
    start = np.ones(n) / np.sqrt(n)  # a fixed start: the estimate is reproducible
    return float(abs(spla.eigsh(op, k=1, which="LM", tol=STEP_LANCZOS_TOL, v0=start, return_eigenvectors=False)[0]))


STEP_LANCZOS_TOL = 1e-4
"""ARPACK's tolerance (residual relative to the Ritz value) of :func:`_lanczos_norm`. A Ritz
value's error is of the order of the residual squared: on the face's series (k = 2, N = 48,
DUAL and DUAL-Q9, 52 steps) 1e-4 gave every step within 1.7e-7 of the value at 1e-8 in 40 % fewer
products (the steps' tops are clustered: about 60 products a step at 1e-8), and the step only
has to be known to a few digits against ``rtol``."""


def _standard_form_norm(E: np.ndarray, L: np.ndarray) -> float:
    """max |λ| of L⁻¹ E L⁻ᵀ from the whole standard form and all its eigenvalues (LAPACK)."""
    X = sla.solve_triangular(L, E, lower=True)
    X = sla.solve_triangular(L, X.T, lower=True)
    return float(np.max(np.abs(np.linalg.eigvalsh((X + X.T) / 2.0))))


RELATIVE_DENSE_MAX = 400
"""Largest order for which :func:`relative_step` forms the standard form and all its eigenvalues;
above it Lanczos (at order 1,500 the dense route took about 40 % of a k = 2, N = 20
face request; Lanczos needs a few dozen O(n²) products)."""


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
separated, 11 products reach the same 1e-8 where the default takes 21 (a dense product each,
at order 4,225); the default DAG's Grams, all below, keep their digits."""
NORM2_SHORT_KRYLOV = 10
