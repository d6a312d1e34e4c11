"""The bottom of a spectrum without a dense eigensolver, for multiplier spaces too large for one.

β_h needs two things from the bottom of a spectrum (:mod:`.infsup`, :mod:`.kernel`): the kernel of
Bᵀ, from the smallest singular values of the scaled coupling W, and the smallest eigenvalues of
the pencil (S, G) above that kernel. A dense SVD of W and a dense pencil cost O(m³) each with a
large, partly BLAS-2 constant; on a 3D face (dim M ≈ 4,000 at k = 2, N = 32) they were 80 % of a
β_h run. Above :data:`DENSE_MAX_M` both come from here instead, at the cost of a few Cholesky
factorizations (BLAS-3, m³/3 each):

:func:`bottom_singular`
    block inverse subspace iteration on WᵀW with an *unsquared* Rayleigh–Ritz step: the Ritz
    values are the singular values of W Q (Q orthonormal), so a zero mode is measured as ‖W v‖,
    never as the square root of an eigenvalue of WᵀW (which would lose half the digits). A block
    method, because the kernels are large (dimension 4(Nk) on a face) and single-vector Lanczos
    finds one vector per multiple eigenvalue: ``scipy.sparse.linalg.eigsh`` counted 0 of R5.2's
    96 proven zero modes at k = 2, N = 12.
:func:`at_most_below`
    one Cholesky factorization of WᵀW − τI + ω Z Zᵀ (Z the d counted modes): it succeeds only
    if at most d eigenvalues lie below τ (Weyl), which certifies that the iteration missed no
    singular value below the first one above the kernel.
:func:`bottom_pencil`
    the smallest eigenvalues of (S, G) above a known kernel Z: Z is moved to the top of the
    spectrum (S + γ G Z (ZᵀGZ)⁻¹ ZᵀG, γ = 2 λ_max), then Lanczos on the explicit inverse of
    the standard form (shift-invert at 0: a Cholesky factorization, a column-blocked triangular
    solve and a triangular product, all BLAS-3; :func:`inverse_standard_form`).

Every start vector comes from a seeded generator (the same on every machine); what differs
between BLAS kernels is round-off only.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy.linalg import blas
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from . import mkl, openblas

DENSE_MAX_M = 1500
"""Largest dim M decided and solved densely (SVD of W, dense pencil); above it, this module.
Every table of the default DAG stays below it (the segment, and the face up to N = 12 at k = 2)."""
SHIFT = 1e-10
"""δ of the subspace iteration on WᵀW + δ I, relative to σ_max²: zero modes converge at the
rate δ/σ_{p+1}², i.e. in two or three steps."""
MIN_ITER = 3
"""Fewest steps of the subspace iteration of :func:`bottom_singular` (the count must also repeat)."""
MAX_ITER = 30
"""Most steps of that iteration."""
LAM_MAX_RTOL = 1e-2
"""Relative accuracy of λ_max in :func:`bottom_pencil` (``gap_over_roundoff`` to 2 digits)."""
LAM_MAX_NCV = 6
"""Lanczos vectors of :func:`lam_max`: ARPACK tests convergence (to :data:`LAM_MAX_RTOL`) after
that many steps, and restarts if it failed. The top of the face pencils is well separated at
this accuracy: 6 steps reach ~5e-4 where the default 20 reached ~2e-4 (k = 2, N = 24)."""
SOLVE_BLOCK = 512
"""Columns per block of the triangular solve K = R⁻¹ L in :func:`inverse_standard_form`."""
SOLVE_BLOCK_MKL = 1024
"""The same on the in-place MKL route (at m = 4,225 on two threads 512 does as well: measured by ``bench --what face``)."""
VALUE_RTOL = 1e-3
"""Relative change at which the first value above the counted ones has settled in
:func:`bottom_singular` (a margin in decades to ~1e-3, where a decision needs 1 decade; the
Cholesky certificate at σ_{d+1}²/2 needs less; 1e-6 took twice the steps)."""
GUARD = 4
"""Ritz values at the top of the block that may not be counted as zero (else the block grows)."""
SEED = 20010601
"""Seed of the start vectors (numpy's PCG64: the same stream on every machine)."""


@dataclass(frozen=True)
class BottomSingular:
    """The kernel of W (its singular values <= η) and the first singular value above it.

    Attributes
    ----------
    values : ndarray
        Ritz values σ_1 <= … <= σ_p of the block (singular values of W Q, Q orthonormal): each
        an upper bound of the corresponding singular value of W (Courant–Fischer).
    vectors : ndarray, shape (m, p)
        The orthonormal Ritz vectors, in the order of ``values``.
    count : int
        How many values are <= η.
    above : float
        σ_{count+1}(W): the first Ritz value above the counted ones (an upper bound, settled to
        :data:`VALUE_RTOL`; :func:`~.kernel.bottom_kernel` certifies a lower bound).
    smax : float
        σ_max(W) (Lanczos on WᵀW, relative accuracy ~1e-10).
    iterations : int
    """

    values: np.ndarray
    vectors: np.ndarray
    count: int
    above: float
    smax: float
    iterations: int


def largest_singular(W: sp.spmatrix, gram: sp.spmatrix | None = None) -> float:
    """σ_max(W) by Lanczos on WᵀW (``gram``, if already formed; a deterministic start vector)."""
    C = sp.csr_matrix(W.T @ W if gram is None else gram)
    v0 = np.ones(C.shape[0])
    return float(np.sqrt(spla.eigsh(C, k=1, which="LA", tol=1e-10, v0=v0, return_eigenvectors=False)[0]))


def bottom_singular(W, p: int, eta: float, smax: float | None = None,
                    gram: sp.spmatrix | None = None) -> BottomSingular | None:
    """The singular values of W (sparse, rows × m) below η, and the first above them.

    1. Block inverse subspace iteration with (WᵀW + δI)⁻¹, δ = :data:`SHIFT` σ_max², block p,
       and an unsquared Rayleigh–Ritz step (the SVD of W Q), until the count of Ritz values
       <= η is the same in two consecutive steps and the first value above them settled to
       :data:`VALUE_RTOL` (at least :data:`MIN_ITER` steps): modes below η converge at the
       rate δ/σ_{p+1}², i.e. at once, the next one at σ_{d+1}²/σ_{p+1}² (the block's products
       are BLAS-3: cheaper than single-vector Lanczos at this size).
    2. The counted modes are refined by one corrected step (round-off of the solve).
    Where the count reaches p − :data:`GUARD` (the block is too small) or the iteration does
    not settle in :data:`MAX_ITER` steps, the block doubles, on the same factorization; None
    when it cannot grow any more. ``gram``: WᵀW (sparse), if already formed.
    """
    W = sp.csr_matrix(W)
    m = W.shape[1]
    gram = sp.csr_matrix(W.T @ W) if gram is None else gram
    smax = largest_singular(W, gram) if smax is None else smax
    C = gram.toarray()
    C[np.diag_indices(m)] += SHIFT * smax ** 2
    F = openblas.cholesky_lower(C, overwrite=True, clean=False)  # cho_factor's, without the GIL
    while (res := _subspace_iteration(W, F, p, eta, smax)) is None and p < m - 1:
        p = min(2 * p, m - 1)
    return res


def _subspace_iteration(W, F, p: int, eta: float, smax: float) -> BottomSingular | None:
    """Step 1 and 2 of :func:`bottom_singular` with block p and F = the lower Cholesky factor of WᵀW + δI."""
    m = W.shape[1]
    # QR and SVD through la.openblas (scipy's routines, bit for bit, without the GIL): the blocks
    # of one space and the spaces beside it iterate side by side
    Q = openblas.qr_q(np.random.default_rng(SEED).standard_normal((m, p)), overwrite=True)
    counts, previous, it = [], None, 0
    for it in range(1, MAX_ITER + 1):
        Q = openblas.qr_q(openblas.potrs(F, Q), overwrite=True)
        R = openblas.qr_r(np.asarray(W @ Q), overwrite=True)
        s, vt = openblas.gesdd(R, True, overwrite=True, full=True)  # the singular values of W Q, no left vectors
        s, Q = s[::-1].copy(), Q @ vt[::-1].T  # ascending
        counts.append(int(np.sum(s <= eta)))
        if counts[-1] > p - GUARD:
            return None
        if it >= MIN_ITER and counts[-1] == counts[-2]:
            d = counts[-1]  # and the first value above them settled
            if abs(s[d] - previous[d]) <= VALUE_RTOL * s[d]:
                break
        previous = s
    else:
        return None
    d = counts[-1]
    if d:  # refinement: (WᵀW + δI)⁻¹ amplifies the round-off of the solve by σ_max²/σ_{p+1}²
        # along the range of Wᵀ; one corrected step Z − (WᵀW + δI)⁻¹ Wᵀ W Z removes it
        Z = Q[:, :d]
        Z = openblas.qr_q(Z - openblas.potrs(F, np.asarray(W.T @ (W @ Z))), overwrite=True)
        sz, vt = openblas.gesdd(openblas.qr_r(np.asarray(W @ Z), overwrite=True), True, overwrite=True, full=True)
        s = np.concatenate([sz[::-1], s[d:]])
        Q = np.hstack([Z @ vt[::-1].T, Q[:, d:]])
    above = float(s[d])
    return BottomSingular(s, Q, d, above, smax, it)


def at_most_below(C: np.ndarray, tau: float, Z: np.ndarray, omega: float) -> bool:
    """Whether the symmetric C has at most d = Z.shape[1] eigenvalues below τ, certified by one
    Cholesky factorization (LAPACK potrf): C − τI + ω Z Zᵀ positive definite (ω > 0, Z
    orthonormal) gives λ_{d+1}(C) ≥ λ_1(C + ω Z Zᵀ) > τ, because a positive semidefinite term of
    rank d lifts the i-th eigenvalue at most to the (i + d)-th (Weyl). Z is where the d small
    eigenvalues are believed to be; a wrong Z can only make the answer False, never a wrong True.
    In floating point a successful potrf certifies λ_min >= −c m ε ‖C − τI + ω Z Zᵀ‖, which
    :func:`~.kernel.bottom_kernel` keeps far below τ (its ``CERTIFY_FLOOR``). The flops of an
    inertia count (Bunch–Kaufman LDLᵀ), at BLAS-3 speed. ``C`` dense or sparse (made dense once)."""
    M = C.toarray(order="F") if sp.issparse(C) else np.array(C, float, order="F")
    M[np.diag_indices_from(M)] -= tau
    if Z.shape[1]:
        M = blas.dsyrk(omega, np.asfortranarray(Z), beta=1.0, c=M, trans=0, lower=1, overwrite_c=1)
    _, info = openblas.potrf(M, clean=False, overwrite=True)
    return info == 0


@dataclass(frozen=True)
class BottomPencil:
    """The smallest eigenvalues of (S, G) above a deflated kernel.

    Attributes
    ----------
    values : ndarray
        λ_{d+1} <= … (ascending; as many as Lanczos converged, up to the number asked).
    lam_max : float
        λ_max of the pencil (Lanczos, relative accuracy :data:`LAM_MAX_RTOL`).
    vectors : ndarray or None
        The eigenvectors x of ``values`` (columns, same order) where asked for, else None.
    """

    values: np.ndarray
    lam_max: float
    vectors: np.ndarray | None = None


def _standard_form(S: np.ndarray, L: np.ndarray) -> spla.LinearOperator:
    """x ↦ L⁻¹ S L⁻ᵀ x, the standard form of (S, G = L Lᵀ) (S symmetric: its lower triangle)."""
    m = S.shape[0]
    # symv takes Fortran order: a C-ordered S is passed as Sᵀ (no copy), whose upper triangle it is
    A, lower = (S.T, 0) if S.flags.c_contiguous and not S.flags.f_contiguous else (np.asfortranarray(S), 1)

    def mv(x):  # scipy's routines without the GIL (la/openblas.py): pencils side by side overlap
        y = openblas.solve_triangular(L, np.ravel(x), True, 1)
        return openblas.solve_triangular(L, openblas.symv(A, y, bool(lower)), True)

    return spla.LinearOperator((m, m), matvec=mv, dtype=float)


def lam_max(S: np.ndarray, L: np.ndarray) -> float:
    """λ_max of (S, L Lᵀ) by Lanczos (a deterministic start vector; relative accuracy
    :data:`LAM_MAX_RTOL`: the top of an H^{-1/2} pencil is clustered, and a round-off level and
    the deflation's γ need no more; :data:`LAM_MAX_NCV` vectors)."""
    m = S.shape[0]
    v0 = np.ones(m)
    return float(spla.eigsh(_standard_form(S, L), k=1, which="LA", tol=LAM_MAX_RTOL, v0=v0,
                            ncv=min(m, LAM_MAX_NCV), return_eigenvectors=False)[0])


def definite_factor(S: np.ndarray) -> np.ndarray | None:
    """Lower Cholesky factor of S (LAPACK potrf, the upper triangle zeroed), or None where S is
    not numerically positive definite (potrf meets a non-positive pivot)."""
    R, info = openblas.potrf(S)  # without the GIL: the blocks' factors side by side
    return None if info else R


def inverse_standard_form(R: np.ndarray, L: np.ndarray) -> np.ndarray:
    """Kᵀ K = Lᵀ (R Rᵀ)⁻¹ L with K = R⁻¹ L, R and L lower triangular (its lower triangle, Fortran
    order; the upper triangle holds zeros).

    K is lower triangular (a product of two): its columns j:j+b vanish above row j, and
    K[j:, j:j+b] = R[j:, j:]⁻¹ L[j:, j:j+b] needs only the trailing part of R, so the blocked
    solve costs m³/3 flops instead of the m³ of one solve with m right-hand sides; Kᵀ K of a
    triangular K is LAPACK lauum (m³/3, where syrk costs m³). Both agree with the plain route to
    round-off (tests/la/test_bottom.py). With MKL the blocks are solved in place on a copy of L
    (:func:`~infsup_contact.la.mkl.trailing_solve`; L's zeros above its diagonal make the rows
    above j of block j vanish): half the time of the copying route at m = 4,225 on two threads,
    the same K to 5e-16."""
    m = R.shape[0]
    if mkl.available():  # in place on the sub-blocks: no copy of R[j:, j:] per block
        K, R = np.array(L, dtype=float, order="F"), np.asfortranarray(R, dtype=float)
        for j in range(0, m, SOLVE_BLOCK_MKL):
            mkl.trailing_solve(R, K, j, min(j + SOLVE_BLOCK_MKL, m))
    else:
        K = np.zeros((m, m), order="F")
        for j in range(0, m, SOLVE_BLOCK):
            e = min(j + SOLVE_BLOCK, m)
            K[j:, j:e] = sla.solve_triangular(R[j:, j:], L[j:, j:e], lower=True, check_finite=False)
    C, info = openblas.lauum(K, overwrite=True)
    if info:
        raise np.linalg.LinAlgError(f"lauum failed (info {info})")
    return C


def bottom_pencil(S: np.ndarray, L: np.ndarray, n_values: int, Z: np.ndarray | None = None,
                  s_factor: np.ndarray | None = None, vectors: bool = False) -> BottomPencil:
    """The n_values smallest eigenvalues of S x = λ G x, G = L Lᵀ (L lower triangular, zeros
    above its diagonal: :func:`~infsup_contact.solvers.spectra.gram_factor`'s), above the kernel span Z.

    ``Z`` (m × d, S Z ≈ 0) is moved to λ = γ = 2 λ_max: the G-orthogonal complement of Z is
    invariant, so S' = S + γ G Z (ZᵀGZ)⁻¹ ZᵀG keeps the pencil's other eigenvalues, and it is
    positive definite. With S' = R Rᵀ (Cholesky) and K = R⁻¹ L, the largest eigenvalues θ of
    the explicit SPD matrix Kᵀ K = Lᵀ S'⁻¹ L (:func:`inverse_standard_form`) are 1/λ
    (shift-invert at 0); Lanczos on it costs one symmetric matrix-vector product per step.

    Without Z, S' = S itself where it is numerically positive definite (its factor
    ``s_factor`` = :func:`definite_factor` of S, if known: the pencils of one S with several
    Gram matrices share it); where potrf fails (a singular S), a floor 1e-14 λ_max diag(G) is
    added and λ ≈ 0 (its round-off), as the dense route gives.

    ``vectors``: also the eigenvectors x = L⁻ᵀ y of the Lanczos vectors y of Kᵀ K (Kᵀ K y = θ y
    ⇔ S' x = (1/θ) G x; in the G-orthogonal complement of Z, S' x = S x). Only a caller that
    draws a mode asks: Lanczos costs the same, the vectors one triangular solve.
    """
    m = S.shape[0]
    top = lam_max(S, L)
    deflate = Z is not None and Z.shape[1] > 0
    R = None if deflate else (definite_factor(S) if s_factor is None else s_factor)
    if R is None:
        Sp = np.array(S, float)
        if deflate:
            LtZ = L.T @ Z
            GZ = L @ LtZ
            Sp += 2.0 * top * GZ @ sla.solve(LtZ.T @ LtZ, GZ.T, assume_a="pos", check_finite=False)
        # a floor keeps the factorization defined where S is singular (no Z given): λ ≈ 0 there anyway
        Sp[np.diag_indices(m)] += 1e-14 * top * np.einsum("ij,ij->i", L, L)
        R = openblas.cholesky_lower(Sp, overwrite=True)
        del Sp
    inverse = inverse_standard_form(R, L)
    del R

    def mv(x):
        return openblas.symv(inverse, np.ravel(x), True)

    k = min(n_values, m - 1)
    op = spla.LinearOperator((m, m), matvec=mv, dtype=float)
    v0 = np.random.default_rng(SEED).standard_normal(m)
    out = spla.eigsh(op, k=k, which="LA", tol=1e-12, v0=v0, ncv=min(m, max(2 * k + 1, 40)),
                     return_eigenvectors=vectors)
    if not vectors:
        return BottomPencil(np.sort(1.0 / out), top)
    theta, y = out
    order = np.argsort(1.0 / theta)
    x = sla.solve_triangular(L, y[:, order], lower=True, trans="T", check_finite=False)
    return BottomPencil(1.0 / theta[order], top, x)
