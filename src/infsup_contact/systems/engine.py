"""β_h of a foreign saddle-point system: β_h² = min eig(B A⁻¹ Bᵀ, G) on one mesh level.

A (n × n) is SPD, B (m × n) couples the multipliers to the dofs it touches, G (m × m) is the
multiplier norm. Three routes, chosen by the sizes (:func:`choose_route`):

``gamma-dense``
    the dofs B touches (Γ) are few: they are ordered last and one sparse factorization of
    A gives X = (A⁻¹)_ΓΓ (:func:`infsup_contact.la.schur.gamma_factorization`, the
    suite's own Γ-last machinery), S = B_Γ X B_Γᵀ, then the dense pencil
    ``scipy.linalg.eigh(S, G)``;
``solves-dense``
    B touches many dofs but m is small (a Stokes pressure on a coarse mesh): one sparse LU of
    A, S = B (A⁻¹ Bᵀ) from m solves, the dense pencil;
``shift-invert``
    m is large: the bottom of the pencil by shift-invert Lanczos
    (``scipy.sparse.linalg.eigsh`` with ``sigma = −δ``), whose operator (S + δG)⁻¹ comes
    from one sparse LU of the quasi-definite matrix [[A, Bᵀ], [B, −δG]]: for r,
    [[A, Bᵀ], [B, −δG]] [u; p] = [0; r] gives p = −(S + δG)⁻¹ r. S itself (S v = B A⁻¹ Bᵀ v)
    comes from an independent LU of A: the eigenvalues are its Rayleigh quotients, and the
    residuals are measured with it. The kernel of Bᵀ (its basis from the kernel decision
    below) is deflated first (:func:`_shift_invert`): Lanczos computes the :data:`N_ABOVE`
    eigenvalues above it, never the d-fold zero itself (single-vector Lanczos resolves a multiple
    eigenvalue copy by copy, through round-off only: on the d = 400, m = 1600 system of
    ``tests/systems/test_systems_deflation.py`` it found 351 of the zero modes and reported β_h = 0.5846
    with ``known_kernel: 400``, where the dense route gives 0.5473).

The kernel of B A⁻¹ Bᵀ is the kernel of Bᵀ (A is SPD), decided from the singular values of
W = D_A^{-1/2} Bᵀ D_G^{-1/2} restricted to the touched dofs
(:func:`infsup_contact.solvers.kernel.coupling_kernel`; dense SVD while W is small, else the
bottom singular values by block subspace iteration, measured directly as ‖W v‖ and certified
by an inertia count, :func:`infsup_contact.solvers.kernel.bottom_kernel`). A declared kernel (``known_kernel`` in the manifest: the
hydrostatic pressure of an enclosed Stokes flow) is the ``proven`` part; β_h is then the
smallest eigenvalue above it, i.e. β_h on the complement of the declared kernel.

The entries of B carry the producer's round-off: η includes 2 E(r), E(r) the bound on ‖δW‖_F
from the entries' relative accuracy r (declared ``entry_rtol``, else estimated from B;
:mod:`.roundoff`), and a ``clear`` decision is checked against the pencil's own bottom
(:func:`~infsup_contact.solvers.kernel.pencil_cross_check`, λ_max by Lanczos): a first mode
counted non-zero at the pencil's round-off level is ``close``, and :func:`close_advice` says
what the user can do.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .. import resources
from ..la.schur import gamma_factorization
from ..la.bottom import SEED, lam_max
from ..solvers.kernel import (MARGIN_DECADES, KernelDecision, bottom_kernel, coupling_kernel,
                              pencil_cross_check)
from .roundoff import EntryRoundoff, entry_error_bound, entry_roundoff

DENSE_MAX_M = 1500
"""Largest m for the dense pencil (above it shift-invert Lanczos is faster: on scikit-fem's P2–P0,
m = 2048, about 5× faster than the dense pencil)."""
DENSE_MAX_BYTES = 1.5e9
"""Largest dense block (X = (A⁻¹)_ΓΓ, or A⁻¹ Bᵀ) a dense route may allocate."""
SVD_MAX_BYTES = 3e7
"""Largest W (touched dofs × m doubles) decided by a dense SVD; above it :func:`bottom_kernel`."""
N_BOTTOM = 6
"""Eigenvalues above the kernel of Bᵀ the dense routes compute (kernel dim + N_BOTTOM from the bottom)."""
N_ABOVE = N_BOTTOM
"""Eigenvalues above the deflated kernel the shift-invert route computes: as many as the dense
routes give (``LevelSpectrum.bottom`` holds the same values on every route; the Stokes tests
compare three). A row reads λ_{d+1} only: 1 would take 61 KKT solves where 6 take 140 (3: 149;
R5.2, k = 2, N = 12 face export, the same λ_{d+1} to 15 digits)."""
SHIFT = 1e-8
"""δ of the shift-invert route relative to σ_max(W)², the Jacobi scale of the pencil."""
NCV_MIN = 40
"""Fewest Lanczos vectors of the shift-invert route (as :func:`~infsup_contact.la.bottom.bottom_pencil`:
the bottom of an H^{-1/2} pencil is clustered)."""

ROUTES = ("auto", "gamma-dense", "solves-dense", "shift-invert")


@dataclass(frozen=True)
class LevelSpectrum:
    """The bottom of (B A⁻¹ Bᵀ) m = β² G m on one level, and how it was obtained.

    Attributes
    ----------
    beta : float
        β_h on the complement of the kernel *declared* (``known_kernel``); exactly 0 when the
        kernel of Bᵀ is larger than declared.
    smallest_nonzero : float
        sqrt of the first eigenvalue above the whole kernel.
    kernel : KernelDecision
        The kernel of Bᵀ (``proven`` = the declared kernel only; ``detected`` = everything
        beyond it, a structural deficiency m − n_touched included).
    bottom : ndarray
        The smallest eigenvalues β² computed (ascending).
    route : str
        One of :data:`ROUTES` (not ``auto``).
    residual : float
        max over the bottom eigenpairs of ‖S x − λ G x‖ / ((‖S‖ + |λ| ‖G‖) ‖x‖).
    n_touched : int
        Dofs B touches.
    seconds : dict
        ``factorize``, ``eigen``, ``kernel`` wall times.
    roundoff : EntryRoundoff
        r, the entries' relative accuracy in η, and its source (:mod:`.roundoff`).
    entry_error_unit : float
        E(1): E(r) = r · E(1) is the bound on ‖δW‖_F in η (:mod:`.roundoff`, (1)).
    pencil_margin : float
        log10(λ_{d+1} / (m ε λ_max)): the first eigenvalue above the kernel over the pencil's
        round-off level, in decades (the cross-check of the kernel decision).
    schur : ndarray or None
        S = B A⁻¹ Bᵀ as the dense routes formed it, where asked for (``keep_schur``: β_C of a
        stabilised level adds C to it instead of factorizing A again); None on shift-invert.
    mode : ndarray or None
        The worst mode where asked for (``vectors``): the eigenvector of β_h² (the smallest
        eigenvalue above the declared kernel), or where β_h = 0 the first kernel vector of Bᵀ
        beyond the declared count (ascending singular values); in B's rows, Euclidean norm 1.
    """

    beta: float
    smallest_nonzero: float
    kernel: KernelDecision
    bottom: np.ndarray
    route: str
    residual: float
    n_touched: int
    seconds: dict = field(default_factory=dict)
    roundoff: EntryRoundoff | None = None
    entry_error_unit: float = 0.0
    pencil_margin: float = np.inf
    mode: np.ndarray | None = None
    schur: np.ndarray | None = None


def touched_dofs(B: sp.spmatrix) -> np.ndarray:
    """Columns of B holding a non-zero entry (the dofs b(·, μ) sees), sorted."""
    B = sp.csc_matrix(B)
    B.eliminate_zeros()
    return np.flatnonzero(np.diff(B.indptr) > 0)


SPARSE_G_DENSE_MAX_M = 300
"""With a sparse G, the dense routes only up to this m: shift-invert was 20-50× faster at
m = 1152 and 2048 (scikit-fem P2–P0, same β to 1e-13)."""


INTERFACE_FRACTION = resources.INTERFACE_FRACTION
"""Above :data:`DENSE_MAX_M` with a dense G, a system whose B touches at most this fraction of
its dofs (a contact interface, not a Stokes pressure) keeps the ``gamma-dense`` route: on a 3D
contact export (membranes3d, hex, k = 2, N = 20, m = 1,681, B touching 2 % of the dofs) it took
a quarter or less of the time of the shift-invert route, whose sparse LU of [[A, Bᵀ], [B, −δG]]
with a dense G dominates."""


def choose_route(n: int, m: int, n_touched: int, sparse_g: bool = False) -> str:
    """``gamma-dense`` where X = (A⁻¹)_ΓΓ is the smaller dense block, ``solves-dense`` where
    A⁻¹ Bᵀ is, ``shift-invert`` when m > :data:`DENSE_MAX_M` (with a sparse G: m >
    :data:`SPARSE_G_DENSE_MAX_M`) or both dense blocks are too large. Above DENSE_MAX_M a dense
    G on an interface (B touching at most :data:`INTERFACE_FRACTION` of the dofs) stays on
    ``gamma-dense`` while X and S fit in :data:`DENSE_MAX_BYTES`."""
    gamma_bytes, solves_bytes = 8.0 * n_touched ** 2, 8.0 * n * m
    if m > (SPARSE_G_DENSE_MAX_M if sparse_g else DENSE_MAX_M):
        interface = not sparse_g and n_touched <= INTERFACE_FRACTION * n
        fits = max(gamma_bytes, 8.0 * m * m) <= DENSE_MAX_BYTES
        return "gamma-dense" if interface and fits else "shift-invert"
    if min(gamma_bytes, solves_bytes) > DENSE_MAX_BYTES:
        return "shift-invert"
    return "gamma-dense" if gamma_bytes <= solves_bytes else "solves-dense"


def scaled_coupling(A, B, G, touched, with_bound: bool = False):
    """W = D_A^{-1/2} Bᵀ D_G^{-1/2} on the touched dofs (D = the diagonals); ``with_bound``:
    (W, E(1)) with E(r) = r · E(1) the bound on the round-off ‖δW‖_F of entries accurate to
    r · max |b| (:func:`.roundoff.entry_error_bound`)."""
    da = np.sqrt(sp.csr_matrix(A).diagonal()[touched])
    dg = np.sqrt(np.asarray(G.diagonal() if sp.issparse(G) else np.diag(G), float))
    Bt = sp.csc_matrix(B)[:, touched].T.tocsr()
    W = sp.diags(1.0 / da) @ Bt @ sp.diags(1.0 / dg)
    return (W, entry_error_bound(Bt, da, dg, 1.0)) if with_bound else W


def level_spectrum(A, B, G, known_kernel: int = 0, route: str = "auto", entry_rtol=None,
                   vectors: bool = False, keep_schur: bool = False) -> LevelSpectrum:
    """β_h and the bottom of the pencil for one level (checked matrices: :mod:`.checks`).

    Parameters
    ----------
    A : sparse (n × n), SPD.
    B : sparse (m × n).
    G : sparse or dense (m × m), SPD.
    known_kernel : int
        Dimension of a kernel of Bᵀ the producer declares (``proven``).
    route : str
        One of :data:`ROUTES`.
    entry_rtol : float, optional
        The declared accuracy of B's entries relative to max |b_ij| (manifest ``entry_rtol``);
        raised to what the data show (:func:`.roundoff.entry_roundoff`).
    vectors : bool
        Also the worst mode (``LevelSpectrum.mode``): the kernel's basis from the dense SVD too.
    keep_schur : bool
        Keep S = B A⁻¹ Bᵀ of the dense routes (``LevelSpectrum.schur``) for a stabilised level's β_C.
    """
    A = sp.csc_matrix(A)
    B = sp.csr_matrix(B)
    n, m = A.shape[0], B.shape[0]
    touched = touched_dofs(B)
    if route == "auto":
        route = choose_route(n, m, len(touched), sp.issparse(G))
    seconds = {}
    t0 = time.perf_counter()
    roundoff = entry_roundoff(B, entry_rtol)
    W, unit = scaled_coupling(A, B, G, touched, with_bound=True)
    E = roundoff.rtol * unit
    deflate = route == "shift-invert"  # the kernel's basis is deflated there (:func:`_shift_invert`)
    if 8.0 * W.shape[0] * W.shape[1] <= SVD_MAX_BYTES:
        kernel = coupling_kernel(W.toarray(), known_kernel, entry_error=E, vectors=deflate or vectors)
    else:
        kernel = bottom_kernel(W, known_kernel, entry_error=E)
    seconds["kernel"] = time.perf_counter() - t0
    # Only the *declared* kernel is discounted. The decision counts m − (touched dofs) as a
    # proof (exact zero singular values), but a foreign B with a zero row, duplicate rows or
    # more rows than the dofs it touches has that kernel whether or not anyone declared it:
    # it is part of ``detected`` (UNSTABLE), never of ``proven``.
    kernel = replace(kernel, proven=int(known_kernel), detected=int(kernel.dim - known_kernel))
    dg = np.sqrt(np.asarray(G.diagonal() if sp.issparse(G) else np.diag(G), float))
    if deflate:
        Z = kernel.vectors[:, :kernel.dim] / dg[:, None] if kernel.dim else None  # W v = 0 ⇔ Bᵀ (v / dg) = 0
        ev, resid, sec, top, x = _shift_invert(A, B, G, N_ABOVE, float(kernel.singular[-1]) ** 2, Z)
        S = None
    else:
        ev, resid, sec, top, x, S = _dense(A, B, G, touched, route, kernel.dim + N_BOTTOM)
    seconds.update(sec)
    kernel, pencil_margin = pencil_cross_check(kernel, ev, top, m, zeros_computed=not deflate)
    d = kernel.dim
    above = float(np.sqrt(max(ev[d], 0.0))) if d < len(ev) else np.nan
    p = min(kernel.proven, len(ev) - 1)
    beta = 0.0 if kernel.detected > 0 else float(np.sqrt(max(ev[p], 0.0)))
    mode = None
    if vectors:
        mode = (kernel.vectors[:, kernel.proven] / dg if kernel.detected > 0  # W v = 0 ⇔ Bᵀ (v / dg) = 0
                else x[:, p - (len(ev) - x.shape[1])])  # x: the eigenvectors of ev's last columns
        mode = mode / np.linalg.norm(mode)
    return LevelSpectrum(beta, above, kernel, ev, route, resid, len(touched), seconds, roundoff, unit, pencil_margin,
                         mode, S if keep_schur else None)


def _pencil_words(margin: float) -> str:
    """Where the first eigenvalue above the kernel stands against the pencil's round-off level."""
    if margin <= 0.0:  # at or below it (a zero eigenvalue gives log10 of the tiniest float)
        return "the first eigenvalue above the kernel is at or below the pencil's round-off level"
    return f"the first eigenvalue above the kernel is only {margin:.2f} decades above the pencil's round-off"


def close_advice(res: LevelSpectrum) -> str:
    """What the user of a ``close`` decision can do, in one line: the accuracy r* of B's entries
    that would put η at 20 × the singular value below the widest gap of the bottom of the
    spectrum, if that gap leaves the next value 20 × above η too (the decision would then be
    clear by 1.3 decades on both sides; rounding r* to one digit keeps more than one) — to
    declare only if the entries are that accurate — and the export with 17 significant digits."""
    k = res.kernel
    r = res.roundoff.rtol if res.roundoff is not None else 0.0
    where = (f"kernel decision close (margin {k.margin_decades:.2f} decades from eta = {k.tol:.2g}; entry "
             f"round-off {r:.2g} x max|b|, {res.roundoff.source if res.roundoff else 'exact'}"
             + (f"; {_pencil_words(res.pencil_margin)}: the entries carry more round-off than eta assumes"
                if res.pencil_margin < MARGIN_DECADES else "") + ")")
    s = np.asarray(k.singular[:-1], float)  # the bottom values (σ_max last on the large-W route)
    s = s[s > 0]
    advice = ""
    if len(s) >= 2 and res.entry_error_unit > 0:
        gaps = np.log10(s[1:] / s[:-1])
        j = int(np.argmax(gaps))
        svd = k.tol - 2.0 * r * res.entry_error_unit  # η = svd + 2 r E(1)
        lift = 2.0 * 10.0 ** MARGIN_DECADES  # η at 20 s_j: the counted zeros 1.3 decades below it
        want = (lift * s[j] - svd) / (2.0 * res.entry_error_unit)
        if gaps[j] >= 2.0 * np.log10(lift) and want > r:
            advice = (f"if B's entries are accurate to {float(f'{want:.1g}'):g} x max|b| (the singular values of the "
                      f"scaled B^T jump from {s[j]:.2g} to {s[j + 1]:.2g}), declare entry_rtol: "
                      f"{float(f'{want:.1g}'):g} in the manifest; ")
    return (f"{where}: {advice}export B with 17 significant digits (a text format with fewer digits rounds every "
            "entry), or declare entry_rtol: the accuracy of B's entries relative to max|b|")


def _dense(A, B, G, touched, route, n_pairs):
    t0 = time.perf_counter()
    if route == "gamma-dense":
        rest = np.setdiff1d(np.arange(A.shape[0]), touched)
        order = np.concatenate([rest, touched])
        fac = gamma_factorization(A[order][:, order], len(touched), gamma_dim=None)  # Γ not told: SuperLU, as before
        Bg = B[:, touched].toarray()
        t1 = time.perf_counter()
        S = Bg @ fac.steklov_times(Bg.T)
    else:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
        t1 = time.perf_counter()
        S = B @ lu.solve(B.T.toarray())
    S = 0.5 * (S + S.T)
    Gd = G.toarray() if sp.issparse(G) else np.asarray(G, float)
    k = min(n_pairs, S.shape[0])
    ev, x = sla.eigh(S, Gd, subset_by_index=[0, k - 1])
    res = np.linalg.norm(S @ x - (Gd @ x) * ev[:k], axis=0)
    scale = (np.linalg.norm(S, 2) + np.abs(ev[:k]) * np.linalg.norm(Gd, 2)) * np.linalg.norm(x, axis=0)
    t2 = time.perf_counter()
    top = lam_max(S, sla.cholesky(Gd, lower=True, check_finite=False)) if k < S.shape[0] else float(ev[-1])
    # S = 0 (B = 0): every pair exact, res = scale = 0
    return (ev, float(np.max(np.divide(res, scale, out=np.zeros_like(res), where=scale > 0))),
            {"factorize": t1 - t0, "eigen": t2 - t1, "lam_max": time.perf_counter() - t2}, top, x, S)


def kernel_projector(Z, G):
    """y ↦ P y, P = I − Z (ZᵀGZ)⁻¹ ZᵀG: the G-orthogonal projector onto the G-orthogonal
    complement of span Z (P² = P, G P symmetric, P Z = 0); the identity for Z None or empty.
    Z need not be G-orthonormal (one Cholesky factorization of ZᵀGZ, d × d)."""
    if Z is None or not Z.shape[1]:
        return lambda y: y
    GZ = np.asarray(G @ Z)
    F = sla.cho_factor(Z.T @ GZ, lower=True, check_finite=False)
    return lambda y: y - Z @ sla.cho_solve(F, GZ.T @ y, check_finite=False)


def _shift_invert(A, B, G, n_values, smax2, Z=None):
    """The n_values smallest eigenvalues of the pencil above the kernel span ``Z`` (m × d, Bᵀ Z = 0;
    None: no kernel) by shift-invert Lanczos (module docstring); ``smax2`` = σ_max(W)², the
    Jacobi scale that sets the shift δ. Returns (d zeros then the eigenvalues found, ascending;
    the residual of those; timings; λ_max; the eigenvectors of the eigenvalues found, in their order).

    The kernel is deflated as :func:`infsup_contact.la.bottom.bottom_pencil` deflates it,
    in the limit γ → ∞: there Z is moved to λ = γ by S' = S + γ G Z (ZᵀGZ)⁻¹ ZᵀG; here the
    operator (S + δG)⁻¹ G is followed by the G-orthogonal projector P = I − Z (ZᵀGZ)⁻¹ ZᵀG.
    Z and its G-orthogonal complement are invariant subspaces of (S + δG)⁻¹ G (S Z = 0), so
    P commutes with it and P (S + δG)⁻¹ G is G-self-adjoint, with eigenvalue 0 on Z (λ = ∞)
    and 1/(λ + δ) on the complement: ARPACK's largest θ are the smallest λ above the kernel,
    without γ, i.e. without λ_max. Without the deflation a kernel of dimension d is a
    d-fold eigenvalue θ = 1/δ that single-vector Lanczos must resolve copy by copy, split only
    by round-off, before it reaches λ_{d+1}: it needs k ≥ d + 1 vectors and may return a
    copy of θ = 1/δ in place of λ_{d+1} (docs/foreign-systems.md, "The engine").
    """
    m = B.shape[0]
    d = 0 if Z is None else Z.shape[1]
    if d >= m:  # Bᵀ = 0: everything is kernel, nothing to factorize
        return np.zeros(d), 0.0, {"factorize": 0.0, "eigen": 0.0, "residual": 0.0}, 0.0, np.zeros((m, 0))
    Gs = sp.csc_matrix(G)
    delta = SHIFT * smax2
    t0 = time.perf_counter()
    K = sp.bmat([[A, B.T], [B, -delta * Gs]], format="csc")
    lu = spla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
    n = A.shape[0]
    rhs = np.zeros(n + m)
    project = kernel_projector(Z, Gs)

    def inv(r):
        rhs[:] = 0.0
        rhs[n:] = np.ravel(r)
        return project(-lu.solve(rhs)[n:])

    # S = B A⁻¹ Bᵀ through an independent LU of A: the operator eigsh is given, and the
    # Rayleigh quotients and residuals below
    luA = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))

    def schur(x):
        return B @ luA.solve(np.asarray(B.T @ x))

    t1 = time.perf_counter()
    k = min(n_values, m - d - 1)
    v0 = project(np.random.default_rng(SEED).standard_normal(m))  # seeded, in the complement of Z
    if k < 1:  # a one-dimensional complement: P v0 is its eigenvector (too small for Lanczos)
        x = v0[:, None]
    else:
        op = spla.LinearOperator((m, m), matvec=inv, dtype=float)
        S_op = spla.LinearOperator((m, m), matvec=schur, matmat=schur, dtype=float)
        _, x = spla.eigsh(S_op, k=k, M=Gs, sigma=-delta, OPinv=op, which="LM", tol=1e-12, v0=v0,
                          ncv=min(m - d, max(2 * k + 1, NCV_MIN)))
    t2 = time.perf_counter()
    Sx = schur(x)
    s_norm = float(np.max(np.linalg.norm(Sx, axis=0) / np.linalg.norm(x, axis=0)))  # a lower bound of ‖S‖
    Gx = Gs @ x
    ev = np.einsum("ij,ij->j", x, Sx) / np.einsum("ij,ij->j", x, Gx)  # Rayleigh quotients, exact S
    g_norm = float(spla.eigsh(Gs, k=1, which="LA", tol=1e-3, return_eigenvectors=False)[0])
    res = np.linalg.norm(Sx - Gx * ev, axis=0) / ((s_norm + np.abs(ev) * g_norm) * np.linalg.norm(x, axis=0))
    order = np.argsort(ev)
    ev = np.concatenate([np.zeros(d), ev[order]])  # a kernel of Bᵀ is one of S: exact zeros
    t3 = time.perf_counter()
    top = _pencil_top(schur, Gs)
    return ev, float(np.max(res)), {"factorize": t1 - t0, "eigen": t2 - t1, "residual": t3 - t2,
                                    "lam_max": time.perf_counter() - t3}, top, x[:, order]


def _pencil_top(schur, Gs) -> float:
    """λ_max of (S, G), ``schur(x)`` = S x, by Lanczos to
    :data:`~infsup_contact.la.bottom.LAM_MAX_RTOL` (a round-off level needs no more), G⁻¹
    from one sparse LU of G."""
    from ..la.bottom import LAM_MAX_RTOL

    S_op = spla.LinearOperator(Gs.shape, matvec=schur, dtype=float)
    luG = spla.splu(sp.csc_matrix(Gs))
    Minv = spla.LinearOperator(Gs.shape, matvec=lambda y: luG.solve(np.ravel(y)), dtype=float)
    return float(spla.eigsh(S_op, k=1, M=Gs, Minv=Minv, which="LA", tol=LAM_MAX_RTOL,
                            v0=np.ones(Gs.shape[0]), return_eigenvectors=False)[0])
