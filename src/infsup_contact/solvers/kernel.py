"""The kernel of the β_h eigenproblem (4.5): the proven part and the part decided numerically.

β_h² is the smallest eigenvalue of (B A⁻¹ Bᵀ) m = β² G m. A is SPD, so the kernel of
B A⁻¹ Bᵀ is the kernel of Bᵀ: the μ ∈ M_h with b(v, μ) = 0 for every trace v. Two facts
decide it, and neither involves A⁻¹ or G⁻¹:

proven part
    μ ⊥ (W1 + W2) in L²(Γ) is a linear condition of rank at most dim(W1 + W2), so
    dim ker ≥ max(dim M_h − dim(W1 + W2), 0) (the paper's counts of Remarks 5.2 and 5.4).
    This part is never lost to round-off: it is reported however the numbers come out.

numerical part (:data:`KERNEL_CRITERION`)
    the singular values of W = D_v⁻¹ Bᵀ D_μ⁻¹, the stacked couplings [B_1ᵀ; B_2ᵀ] scaled by
    the L²(Γ) norms of the trace basis functions (rows) and of the multiplier basis
    functions (columns). Diagonal scalings do not change the kernel; they make the entries
    O(1) whatever the element sizes. A backward-stable SVD returns singular values within
    p(m, n)·ε·‖W‖₂ of the exact ones of the computed W (LAPACK Users' Guide §4.9), and the
    computed W differs from the exact one by the round-off δW of its entries (Weyl:
    |σ_i(W + δW) − σ_i(W)| <= ‖δW‖₂). The error level is therefore
    η = max(rows, cols)·ε·σ_max + 2‖W − W'‖_F: the first term the SVD's (the rank tolerance of
    numpy.linalg.matrix_rank and Golub–Van Loan §5.4.1), the second the entries', measured:
    W' is the same matrix from a Gauss rule three points longer, exact for the polynomials
    too, so W − W' is round-off only (it reaches ~100 ε‖W‖ for k = 4 on the union partition
    of 17:16: the high-order basis values carry it). A singular value <= η counts as zero.
    ``tests/solvers/test_kernel.py`` checks both terms against η with independent estimates.

Working with Bᵀ and not with B A⁻¹ Bᵀ squares nothing: a mode with β ≈ 1e-6 sits at
β² ≈ 1e-12 in the pencil — within three decades of the pencil's own round-off level
n·ε·λ_max, which is too optimistic anyway after a Cholesky reduction by an ill-conditioned G —
but its singular value stays near 1e-6 here, eight decades above η.

The decision's **margin** is its distance from η, in decades: the smallest of
log10(σ_{d+1}/η) (the first singular value counted as non-zero) and, when modes beyond the
proof were counted, log10(η/σ_d) (the largest counted as zero). A decision with a margin
below :data:`MARGIN_DECADES` is ``close``: claims and verdicts resting on it are
INCONCLUSIVE, never PASS or FAIL by the luck of one BLAS kernel's rounding.

For a foreign system the entries of B carry the producer's round-off, ``entry_error`` =
E(r) of :mod:`infsup_contact.systems.roundoff`, and every ``clear`` decision is checked against
the pencil itself (:func:`pencil_cross_check`): a first mode counted non-zero must stand a
decade above the pencil's round-off level n ε λ_max, else the decision is ``close``.

The pencil's own gap rule (:func:`kernel_from_gap`) stays as the independent cross-check
(``tests/solvers/test_kernel.py``: both agree wherever the pencil's gap is clear). Pure numpy/scipy:
the command line states the rule without importing NGSolve.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..la import bottom, openblas

MARGIN_DECADES = 1.0
"""A kernel decision whose margin from η is smaller than this many decades is ``close``."""
GAP_DECADES = 3
"""The pencil cross-check (:func:`kernel_from_gap`): a kernel needs the first eigenvalue above
it at least 10**GAP_DECADES times the pencil's round-off level."""
KERNEL_CRITERION = (
    "kernel of B A^-1 B^T = kernel of B^T: kernel_dim = max(proven, numerical), proven = "
    "structural_kernel_dim = max(dim M - dim(W1 + W2), 0) (a proof: mu orthogonal to W1 + W2 "
    "is at most dim(W1 + W2) conditions), numerical = the number of singular values <= eta of the "
    "stacked couplings [B1^T; B2^T] scaled by the L2(Gamma) norms of the basis functions, "
    "eta = max(rows, cols)*eps*sigma_max + 2*||W - W'||_F (the SVD's backward error, and the entries' "
    "round-off measured against a longer exact Gauss rule W'); "
    "kernel_detected = kernel_dim - proven; kernel_margin_decades = distance of the decision from "
    "eta in decades; kernel_decision = close when below 1 decade (claims resting on it are "
    "INCONCLUSIVE), else clear; above dim M = 1500 the bottom singular values come from block inverse "
    "iteration on W^T W, measured as ||W v|| and certified by a Cholesky factorization of "
    "W^T W - tau I + smax^2 Z Z^T (Weyl; la/bottom.py)")
"""The rule of :func:`coupling_kernel`, as stated in ``infsup-contact beta --help`` and docs/method.md."""
CLEAR, CLOSE = "clear", "close"


@dataclass(frozen=True)
class KernelDecision:
    """The kernel of Bᵀ on a multiplier space (module docstring).

    Attributes
    ----------
    dim : int
        kernel dimension, max(proven, numerical count); ``kernel_dim`` of a β row.
    proven : int
        the part a dimension count proves (``structural_kernel_dim``).
    detected : int
        dim − proven: zero modes found numerically beyond the proof.
    margin_decades : float
        distance of the decision from η in decades (inf when nothing is decided: every
        mode proven and no singular value above them).
    decision : str
        ``clear`` (margin >= :data:`MARGIN_DECADES`) or ``close``.
    tol : float
        η, the error level the singular values are compared with.
    singular : ndarray
        the singular values of W, ascending, the structurally zero ones (cols > rows) included.
    numerical : int
        the number of singular values <= η; below ``proven`` only if the error level was
        exceeded (``kernel_check`` reports ``below_structural`` then).
    vectors : ndarray or None
        an orthonormal basis (m × dim) of the kernel in W's column coordinates, where the route
        computed one (:func:`bottom_kernel`; the deflation of :func:`~infsup_contact.la.bottom.bottom_pencil`).
    """

    dim: int
    proven: int
    detected: int
    margin_decades: float
    decision: str
    tol: float
    singular: np.ndarray
    numerical: int
    vectors: np.ndarray | None = field(default=None, repr=False, compare=False)


def coupling_kernel(W: np.ndarray, proven: int = 0, entry_error: float = 0.0,
                    vectors: bool = False) -> KernelDecision:
    """Decide the kernel of a scaled Bᵀ (rows: trace dofs, columns: multipliers).

    Parameters
    ----------
    W : ndarray, shape (rows, m)
        Bᵀ with the diagonal scalings of the module docstring (any other diagonal scaling
        that makes the columns O(1) works; the kernel does not depend on it).
    proven : int
        a proven lower bound on the kernel dimension (a dimension count); m − rows is
        added to it implicitly (the rank of W is at most ``rows``).
    entry_error : float
        an estimate of ‖δW‖_F, the round-off of W's entries (module docstring); η gets twice it.
    vectors : bool
        also return the kernel's right singular vectors (a full SVD: costlier).

    Returns
    -------
    KernelDecision
    """
    W = np.asarray(W, float)
    rows, m = W.shape
    if m == 0:
        raise ValueError("an empty multiplier space (dim M = 0) has no kernel to decide")
    proven = int(max(proven, m - rows, 0))
    if vectors and rows:
        s, vt = right_singular(W)
        V = vt[::-1].T  # right singular vectors, ascending singular values
    elif vectors:  # no trace dof touched (B = 0): every multiplier is in the kernel
        s, V = np.zeros(0), np.eye(m)
    else:
        s, V = (openblas.gesdd(np.asarray_chkfinite(W, dtype=float), False)[0] if rows else np.zeros(0)), None
    s = np.concatenate([np.zeros(m - len(s)), np.sort(s)])  # ascending, structural zeros first
    s_max = float(s[-1])
    tol = error_level(rows, m, s_max, entry_error)
    numerical = int(np.sum(s <= tol))
    return decide(s, proven, tol, numerical, s_max, None if V is None else V[:, :max(proven, numerical)])


def right_singular(W: np.ndarray, overwrite: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(s, Vᵀ) of ``sla.svd(W, full_matrices=m > rows)``, bit for bit, without the left vectors
    where W is tall.

    LAPACK's dgesdd decomposes a W with rows >= ⌊11 m / 6⌋ (its MNTHR) through W = Q R: dgeqrf,
    then R alone (dgebrd, dbdsdc, dormbr), then U = Q U_R. The kernel needs only s and Vᵀ, which
    the same calls on R give with the same bits (tests/solvers/test_kernel.py), without forming Q
    and U: 2 rows m² + O(m³) flops instead of 6 rows m² + O(m³) (a block of R5.4 at k = 2, N = 48:
    18,818 × 2,304), and two rows × m arrays fewer. Other shapes take dgesdd on W itself. ``overwrite``: W's
    memory may hold the QR factors (a caller's temporary, Fortran-ordered to be used in place)."""
    W = np.asarray(W, float)
    rows, m = W.shape
    if m == 0 or m > rows:
        return tuple(sla.svd(W, full_matrices=m > rows, check_finite=True)[1:])
    # scipy's own LAPACK routines through ctypes (la/openblas.py): the same bits, without the GIL,
    # so the reflections' blocks side by side (symmetry.split_dense_kernel) run on both cores
    if rows < (m * 11) // 6:
        return openblas.gesdd(np.asarray_chkfinite(W), True)
    return openblas.gesdd(openblas.qr_r(W, overwrite=overwrite), True, overwrite=True)


def decide(s, proven, tol, numerical, s_max, vectors=None) -> KernelDecision:
    """The decision and its margin (module docstring) from the ascending singular values s
    (all of them, or the bottom ones with σ_max last)."""
    m = len(s)
    dim = max(proven, numerical)
    ratios = [s[dim] / tol] if dim < m and tol > 0 else []
    if numerical > proven:  # modes counted as zero beyond the proof
        ratios.append(tol / max(s[dim - 1], np.finfo(float).tiny))
    elif numerical < proven:  # proven zero modes above η: the error level was exceeded
        ratios.append(tol / s[proven - 1])
    margin = float(np.log10(min(ratios))) if ratios else np.inf
    if s_max == 0.0:  # B = 0: everything is kernel, nothing to decide
        margin = np.inf
    return KernelDecision(dim, proven, dim - proven, margin, CLOSE if margin < MARGIN_DECADES else CLEAR,
                          float(tol), s, numerical, vectors)


BLOCK_EXTRA = 32
"""Block size of :func:`bottom_kernel` beyond the proven kernel (doubled while too small)."""
CERTIFY_FLOOR = 1e3
"""The Cholesky certificate of :func:`bottom_kernel` is trusted where τ exceeds this many times the
round-off of WᵀW, max(rows, m) ε σ_max²; below it the dense SVD decides."""


def bottom_kernel(W, proven: int = 0, entry_error: float = 0.0) -> KernelDecision:
    """:func:`coupling_kernel` for W too large for a dense SVD (dim M > :data:`~infsup_contact.la.bottom.DENSE_MAX_M`):
    the same η, the same count and the same margin, from the bottom singular values only.

    1. The singular values <= η, their right vectors and σ_{d+1} by block inverse subspace
       iteration (:func:`~infsup_contact.la.bottom.bottom_singular`; block p = proven + :data:`BLOCK_EXTRA`,
       doubled while too small, on one factorization). Each counted value is ‖W v‖ for an
       orthonormal block, an upper bound of σ_i(W): the d modes counted are certainly <= η.
    2. Nothing was missed below σ_{d+1}: WᵀW has at most d eigenvalues below τ = σ_{d+1}²/2,
       certified by one Cholesky factorization of WᵀW − τI + σ_max² Z Zᵀ with the d counted
       vectors Z (:func:`~infsup_contact.la.bottom.at_most_below`, Weyl's inequality); with the d Ritz values
       <= η < τ, exactly d.
    Where either step fails (a count that differs, proven modes above η, τ within
    :data:`CERTIFY_FLOOR` of WᵀW's round-off) the dense SVD decides, vectors included.
    ``singular`` holds the d counted values, σ_{d+1} and σ_max; ``vectors`` the d kernel vectors.
    """
    W = sp.csr_matrix(W)
    rows, m = W.shape
    proven = int(max(proven, m - rows, 0))
    gram = sp.csr_matrix(W.T @ W)
    smax = bottom.largest_singular(W, gram)
    tol = error_level(rows, m, smax, entry_error)
    res = certified_bottom(W, gram, min(proven + BLOCK_EXTRA, m - 1), tol, smax,
                           certify_floor(rows, m, smax), min_count=proven)
    if res is None:
        return coupling_kernel(W.toarray(), proven, entry_error, vectors=True)
    d = res.count
    s = np.concatenate([res.values[:d], [res.above, smax]])
    return decide(s, proven, tol, d, smax, res.vectors[:, :d])


def error_level(rows: int, m: int, smax: float, entry_error: float) -> float:
    """η = max(rows, m) ε σ_max + 2 ‖δW‖_F (module docstring)."""
    return max(rows, m) * np.finfo(float).eps * smax + 2.0 * float(entry_error)


def certify_floor(rows: int, m: int, smax: float) -> float:
    """The τ below which :func:`certified_bottom`'s Cholesky certificate is not trusted
    (:data:`CERTIFY_FLOOR` times WᵀW's round-off)."""
    return CERTIFY_FLOOR * max(rows, m) * np.finfo(float).eps * smax ** 2


def certified_bottom(W, gram, block: int, tol: float, smax: float, floor: float, min_count: int = 0):
    """Steps 1 and 2 of :func:`bottom_kernel` on the columns of W (``gram`` = WᵀW, ``smax`` =
    σ_max(W)): the :class:`~.bottom.BottomSingular` of the block iteration, certified by one
    Cholesky factorization at τ = σ_{d+1}²/2, or None where a step fails (no convergence, fewer
    than ``min_count`` values <= η, σ_{d+1} <= η, τ <= ``floor``, the certificate refused)."""
    res = bottom.bottom_singular(W, block, tol, smax, gram)
    if res is None or res.count < min_count or res.above <= tol:
        return None
    tau = 0.5 * res.above ** 2
    if tau <= floor or not bottom.at_most_below(gram, tau, res.vectors[:, :res.count], smax ** 2):
        return None
    return res


def scaled_couplings(couplings, trace_norms, multiplier_norms):
    """W = [B_1ᵀ/‖φ‖; B_2ᵀ/‖φ‖; …] / ‖μ‖: each side's coupling B_i (dim M × Γ dofs of side i)
    transposed, rows divided by the L² norms of that side's trace basis functions, columns by
    the L² norms of the multiplier basis functions. Sparse couplings give a CSR W with the
    same entries, bit for bit (each stored entry divided by the same two numbers, in order)."""
    if any(sp.issparse(B) for B in couplings):
        blocks = []
        for B, t in zip(couplings, trace_norms):
            Bt = sp.csr_matrix(B).T.tocsr()
            Bt.sort_indices()
            rows = np.repeat(np.arange(Bt.shape[0]), np.diff(Bt.indptr))
            data = Bt.data / np.asarray(t, float)[rows] / np.asarray(multiplier_norms, float)[Bt.indices]
            blocks.append(sp.csr_matrix((data, Bt.indices, Bt.indptr), shape=Bt.shape))
        return sp.vstack(blocks, format="csr")
    blocks = [np.asarray(B, float).T / np.asarray(t, float)[:, None] for B, t in zip(couplings, trace_norms)]
    return np.vstack(blocks) / np.asarray(multiplier_norms, float)[None, :]


def kernel_from_gap(ev: np.ndarray, gap_decades: float = GAP_DECADES) -> tuple[int, float]:
    """The pencil's own kernel count from an ascending spectrum by its gap (the cross-check).

    η = n ε λ_max is the error level of a backward-stable standard symmetric eigensolver (n the
    dimension, ε the machine epsilon). It is optimistic for the generalized pencil after a
    Cholesky reduction by G, which is why the reported kernel comes from
    :func:`coupling_kernel`. The d eigenvalues <= η form a kernel only if the next eigenvalue
    stands at least 10**gap_decades above η; a spectrum that decays smoothly into round-off
    (1, 1e-2, 1e-4, …) has no such gap and gives no kernel.

    Returns
    -------
    (int, float)
        d and λ_{d+1}/η (λ_1/η when d = 0; inf when every eigenvalue is at round-off level).
    """
    ev = np.asarray(ev, float)
    d = int(np.sum(ev <= pencil_roundoff(ev)))
    if d == len(ev):  # S = 0: everything is kernel
        return d, np.inf
    gap = gap_over_roundoff(ev, d)
    if d > 0 and gap < 10.0 ** gap_decades:
        return 0, gap_over_roundoff(ev, 0)
    return d, gap


def pencil_roundoff(ev: np.ndarray, lam_max: float | None = None, n: int | None = None) -> float:
    """η = n ε λ_max of an ascending spectrum (see :func:`kernel_from_gap`); ``lam_max`` and ``n``
    (the pencil's dimension) where ``ev`` holds only the bottom of the spectrum."""
    lam_max = float(ev[-1]) if lam_max is None else float(lam_max)
    return (len(ev) if n is None else n) * np.finfo(float).eps * max(lam_max, 0.0)


def gap_over_roundoff(ev: np.ndarray, d: int, lam_max: float | None = None, n: int | None = None) -> float:
    """λ_{d+1}/η: how far the first eigenvalue above a d-dimensional kernel stands above the
    pencil's round-off level (inf for an all-kernel spectrum or η = 0; 0 for λ <= 0);
    ``lam_max``, ``n`` as :func:`pencil_roundoff`."""
    eta = pencil_roundoff(ev, lam_max, n)
    if d >= len(ev) or eta <= 0:
        return np.inf
    return float(max(ev[d], 0.0) / eta)


def pencil_cross_check(decision: KernelDecision, ev, lam_max: float, n: int,
                       zeros_computed: bool = True) -> tuple[KernelDecision, float]:
    """A ``clear`` decision from Bᵀ checked against the pencil (B A⁻¹ Bᵀ, G) itself.

    ``ev`` are the bottom eigenvalues computed (ascending, the d = ``decision.dim`` kernel
    modes first), ``lam_max`` the largest eigenvalue, ``n`` the pencil's dimension; the pencil's
    round-off level is η_p = n ε λ_max (:func:`pencil_roundoff`). The decision stays clear only if

    * λ_{d+1} >= 10**MARGIN_DECADES · η_p: the first mode counted non-zero is visibly non-zero
      in the pencil too. A mode that the singular values call non-zero only because the
      entries' round-off was larger than η assumed (a zero singular value pushed above η)
      has λ ~ σ² λ_max, far below η_p: not clear;
    * where the kernel's eigenvalues were computed (``zeros_computed``, the dense routes),
      λ_d <= 10**GAP_DECADES · η_p: a mode counted as zero is not visibly non-zero in the
      pencil (η_p is optimistic after the Cholesky reduction by G, hence GAP_DECADES, the gap
      rule's own allowance).

    Returns the decision (``close``, its margin lowered to the pencil's, where a test fails) and
    log10(λ_{d+1}/η_p) (inf without a mode above the kernel).
    """
    d = decision.dim
    margin = float(np.log10(max(gap_over_roundoff(ev, d, lam_max, n), np.finfo(float).tiny)))
    fails = margin < MARGIN_DECADES
    if zeros_computed and 0 < d <= len(ev):
        fails |= float(ev[d - 1]) > 10.0 ** GAP_DECADES * pencil_roundoff(ev, lam_max, n)
    if fails and decision.decision == CLEAR:
        decision = replace(decision, decision=CLOSE, margin_decades=min(decision.margin_decades, margin))
    return decision, margin


def kernel_check(numerical: int, structural: int) -> str:
    """Compare the numerical count with the structural one (the proof).

    ``agree``; ``above_structural`` (zero modes beyond the proof, detected numerically);
    ``below_structural`` (fewer singular values below η than the proof guarantees: the
    stated error level was exceeded, so the row's decision is ``close``).
    """
    if numerical == structural:
        return "agree"
    return "below_structural" if numerical < structural else "above_structural"
