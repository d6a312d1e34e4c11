"""Primal–dual active set solver for the discrete contact problem (4.1).

The discrete mixed inequality (4.1) of Bathe & Brezzi (2001) reads, with stiffness A,
load F and constraint matrix B (row j = b(·, μ_j) for the multiplier basis μ_j),

    A u = F + Bᵀ λ,     λ_j ≥ 0,     g_j ≥ 0,     λ_j g_j = 0,      g = B u,

where the cone "λ_h ≥ 0 at the nodes" is λ_j ≥ 0 per multiplier dof (paper §5) and the
componentwise complementarity is the nodal form of b(u, μ − λ) ≥ 0 ∀ μ ≥ 0.
Eliminating u gives the Γ-reduced linear complementarity problem (LCP)

    g = g0 + K λ,   g0 = B A⁻¹ F,   K = B A⁻¹ Bᵀ   (symmetric positive SEMI-definite),

which is the optimality system of the dual QP  min_{λ ≥ 0} ½ λᵀKλ + g0ᵀλ, and K is
singular exactly when the discrete inf-sup condition fails already in its weak form
(4.2) — then λ is not unique (paper end of §4).

Two routes, both stopped and verified by the test of :mod:`.lcp` (which also holds the
choice of solution when λ is not unique):

:func:`solve_pdas`
    Primal–dual active set (PDAS) = semismooth Newton on the NCP function
    λ − max(0, λ − c g) (Hintermüller, Ito & Kunisch, SIAM J. Optim. 13 (2002)) on the
    small dense Γ-reduced problem, with a documented treatment of singular K.
:func:`~infsup_contact.contact.kkt.solve_kkt_sparse`
    The same PDAS iteration, each step solving the full sparse saddle-point system
    [[A, −B_𝒜ᵀ], [B_𝒜, 0]] — used to cross-check the Γ-reduced route.

Singular K (non-unique λ)
-------------------------
* Each PDAS step solves K_𝒜𝒜 λ_𝒜 = −g0_𝒜 in the minimum-norm sense (spectral
  pseudo-inverse with eigenvalue cutoff ``kernel_rtol · λ_max(K)``).  For the contact
  problem this system is consistent (range K_𝒜𝒜 = range B_𝒜 ∋ g0_𝒜), so g_𝒜 = 0 still
  holds; only the kernel component of λ_𝒜 is fixed by the min-norm choice.
* A min-norm λ_𝒜 may have negative entries; PDAS then drops those dofs, as it does in
  the regular case.  If an earlier active set reappears (cycling — possible since K is
  not an M-matrix in general) the iteration is abandoned and the dual QP is solved by
  non-negative least squares on the kernel-reduced problem (Lawson–Hanson NNLS on the
  factor K = LᵀL built from the non-kernel eigenpairs).
* Whatever route produced a solution, the returned λ is the documented representative
  **the minimum-Euclidean-norm solution of the LCP**.  It is well defined because the
  solution set {λ ≥ 0 : K_SS λ_S = −g0_S, λ = 0 off S} (S = contact set, g unique for a
  monotone LCP) is a closed convex polyhedron; it is computed exactly by a least-distance
  programme (Lawson & Hanson 1974, ch. 23) over the kernel of K_SS, solved with NNLS.
* ``nonunique`` is exact: True iff that polyhedron has more than one point (kernel of
  K on the strictly positive multipliers, or — degenerate case — a kernel direction
  that is feasible for the zero multipliers in the contact set, decided by a small LP).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.optimize import nnls

from ..errors import InputError
from .lcp import (has_free_direction, kkt_ok, min_norm_representative, min_norm_solve, natural_residual,
                  tolerances)

_EPS = np.finfo(float).eps


class PdasDidNotConverge(RuntimeError):
    """PDAS stopped without a verified solution.

    Attributes
    ----------
    history : list of dict
        One record per iteration (see :class:`PdasResult`).
    """

    def __init__(self, message: str, history):
        super().__init__(message)
        self.history = list(history)


@dataclass
class PdasResult:
    """Solution of the Γ-reduced LCP g = g0 + Kλ, λ ≥ 0, g ≥ 0, λ∘g = 0.

    Attributes
    ----------
    lam : ndarray (m,)
        Multiplier dofs; the minimum-norm solution when λ is not unique.
    gap : ndarray (m,)
        g0 + K lam.
    active : ndarray of bool (m,)
        Contact set: dofs with λ_j > 0 (numerically: above a relative zero tolerance).
        Equals the converged PDAS active set in the non-degenerate case.
    iterations : int
        Number of PDAS linear solves (the fallback and post-processing not counted).
        A problem whose first active set {g0 < 0} is already right takes 1.
    complementarity : float
        max_j |λ_j g_j|.
    min_gap, min_lambda : float
        min_j g_j and min_j λ_j (≥ −tolerance for a verified solution).
    nonunique : bool
        Whether the LCP has more than one solution λ (g is always unique).
    kernel_dim : int
        Nullity of K_𝒜𝒜 on the contact set ``active``.
    kernel_dim_K : int
        Nullity of the full K (numerical, relative cutoff ``kernel_rtol``).
    history : list of dict
        Per PDAS iteration: ``iteration``, ``n_active`` (size of the set solved on),
        ``nullity`` (of that K_𝒜𝒜), ``residual`` (natural residual max|min(λ, g)|),
        ``n_changed`` (dofs switching for the next step); then, if used, a record
        ``{"fallback": "nnls", "reason", "residual"}`` and a record
        ``{"postprocess": "min-norm", "kernel_dim_S", "accepted", "change"}``.
    route : str
        ``"pdas"`` or ``"pdas+nnls"`` (cycling or failed check triggered the fallback).
    """

    lam: np.ndarray
    gap: np.ndarray
    active: np.ndarray
    iterations: int
    complementarity: float
    min_gap: float
    min_lambda: float
    nonunique: bool
    kernel_dim: int
    kernel_dim_K: int
    history: list = field(default_factory=list)
    route: str = "pdas"


# ------------------------------------------------------------------ input checking
def _check_options(max_iter, tol, kernel_rtol):
    """InputError unless max_iter ≥ 1 is an integer and tol, kernel_rtol lie in (0, 1)."""
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise InputError("max_iter", "an integer >= 1", got=max_iter)
    if not (isinstance(tol, (int, float)) and 0 < tol < 1):
        raise InputError("tol", "a real number in (0, 1)", got=tol)
    if not (isinstance(kernel_rtol, (int, float)) and 0 < kernel_rtol < 1):
        raise InputError("kernel_rtol", "a real number in (0, 1)", got=kernel_rtol)


def _check_lcp(K, g0):
    """Dense float copies of (K, g0); K symmetrised after a symmetry check."""
    K = np.array(K.toarray() if sp.issparse(K) else K, dtype=float)
    g0 = np.array(g0, dtype=float).reshape(-1) if np.ndim(g0) <= 2 else None
    if K.ndim != 2 or K.shape[0] != K.shape[1]:
        raise InputError("K", "a square matrix", got=f"shape {K.shape}")
    if g0 is None or g0.shape != (K.shape[0],):
        raise InputError("g0", f"a vector of length {K.shape[0]}", got=np.shape(g0))
    if not (np.all(np.isfinite(K)) and np.all(np.isfinite(g0))):
        raise InputError("K, g0", "finite values", got="nan/inf")
    scale = max(np.abs(K).max(initial=0.0), np.finfo(float).tiny)
    if np.abs(K - K.T).max(initial=0.0) > 1e-10 * scale:
        raise InputError("K", "a symmetric matrix", got="non-symmetric")
    return 0.5 * (K + K.T), g0


# ------------------------------------------------------------------ linear algebra
def _nullity(M, cutoff, definite=False):
    """Number of eigenvalues of the symmetric M at or below ``cutoff`` (0 if ``definite``)."""
    return int(np.sum(sla.eigvalsh(M) <= cutoff)) if M.size and not definite else 0


def _solve_on_active(K, g0, active, cutoff, definite=False):
    """One PDAS step: λ_𝒜 = min-norm solution of K_𝒜𝒜 λ_𝒜 = −g0_𝒜, λ_ℐ = 0."""
    lam = np.zeros_like(g0)
    if not active.any():
        return lam, 0
    idx = np.flatnonzero(active)
    lam_a, Z = min_norm_solve(K[np.ix_(idx, idx)], -g0[idx], cutoff, definite)
    lam[idx] = lam_a
    return lam, Z.shape[1]


# ------------------------------------------------------------------ PDAS iteration
def _scaling(K, lam_max):
    """Per-dof c_j = 1/K_jj (global 1/λ_max(K) where K_jj vanishes).

    g = g0 + Kλ means a unit of λ_j moves g_j by K_jj, so λ_j and c_j g_j are in the same
    units.  With exact solves the iterates do not depend on c (λ = 0 off 𝒜, g = 0 on 𝒜);
    c only arbitrates dofs where both λ_j and g_j are at round-off level.
    """
    d = np.diag(K).copy()
    fallback = 1.0 / lam_max if lam_max > 0 else 1.0
    c = np.full_like(d, fallback)
    pos = d > _EPS * max(lam_max, 0.0)
    c[pos] = 1.0 / d[pos]
    return c


def _pdas_loop(K, g0, c, cutoff, max_iter, tol, lam_max, definite=False):
    """Plain PDAS from λ = 0.  Returns (lam, iterations, history, status).

    status is "converged" (active set repeated, or the iterate already passes the KKT
    check — without the latter a degenerate dof with λ_j ≈ g_j ≈ 0 can flip on
    round-off forever), "cycle" (an older active set reappeared) or "max_iter" (``max_iter``
    solves, every active set new: PDAS can wander on a singular K, e.g. T3 at k = 2 on the
    union of two non-matching face traces, 50 distinct active sets).
    """
    active = (-c * g0) > 0  # λ⁰ = 0, g⁰ = g0
    seen, history = {active.tobytes()}, []
    for it in range(1, max_iter + 1):
        lam, nullity = _solve_on_active(K, g0, active, cutoff, definite)
        g = g0 + K @ lam
        new = (lam - c * g) > 0
        history.append(dict(iteration=it, n_active=int(active.sum()), nullity=nullity,
                            residual=natural_residual(lam, g),
                            n_changed=int(np.sum(new != active))))
        if np.array_equal(new, active) or kkt_ok(lam, g, *tolerances(g0, lam, lam_max, tol)):
            return lam, it, history, "converged"
        if new.tobytes() in seen:
            return lam, it, history, "cycle"
        seen.add(new.tobytes())
        active = new
    return lam, max_iter, history, "max_iter"


def _nnls_dual(K, g0, cutoff):
    """Robust fallback: the dual QP min_{λ≥0} ½λᵀKλ + g0ᵀλ as an NNLS problem.

    With K = V diag(w) Vᵀ and the non-kernel part K = LᵀL, L = diag(√w_r) V_rᵀ, the QP
    equals min_{λ≥0} ½‖Lλ + d‖² + const with d = diag(1/√w_r) V_rᵀ g0, i.e. NNLS with
    right-hand side −d (the kernel-reduced problem).  This assumes g0 ∈ range K, which
    holds for the contact problem (g0 = B A⁻¹F, range K = range B); the final KKT check
    catches anything else.  Lawson–Hanson is finite, so this cannot cycle.
    """
    w, V = sla.eigh(K)
    keep = w > cutoff
    if not keep.any():
        return np.zeros_like(g0)
    sw = np.sqrt(w[keep])
    L = sw[:, None] * V[:, keep].T
    d = (V[:, keep].T @ g0) / sw
    try:
        lam, _ = nnls(L, -d, maxiter=50 * max(K.shape[0], 1))
    except RuntimeError as exc:  # iteration cap of Lawson–Hanson
        raise PdasDidNotConverge(f"NNLS fallback failed: {exc}", []) from exc
    return lam


# ------------------------------------------------------------------ public solvers
def solve_pdas(K, g0, *, max_iter=50, tol=1e-12, kernel_rtol=1e-10) -> PdasResult:
    """Solve the Γ-reduced contact LCP of (4.1) by primal–dual active sets.

    Finds λ ∈ ℝᵐ with g = g0 + Kλ and λ ≥ 0, g ≥ 0, λ_j g_j = 0 (the nodal cone
    "μ_h ≥ 0 at the nodes" of §5 and the complementarity b(u, μ − λ) ≥ 0 of (4.1)).

    Algorithm (Hintermüller–Ito–Kunisch 2002): from λ⁰ = 0,
    𝒜ᵏ = {j : λ_j − c_j g_j > 0} with c_j = 1/K_jj; solve K_𝒜𝒜 λ_𝒜 = −g0_𝒜 (small
    dense eigen-solve), λ = 0 off 𝒜; stop when 𝒜 repeats (or the iterate already
    passes the KKT check, which settles round-off ties at degenerate dofs), then verify
    the KKT conditions.  On a singular K_𝒜𝒜 the min-norm λ_𝒜 is used; on cycling, after
    ``max_iter`` solves or on a failed check the dual QP is solved by NNLS; finally the minimum-norm solution of the LCP is
    returned as the representative (module docstring).

    Parameters
    ----------
    K : (m, m) array_like or sparse, symmetric positive semi-definite
        Γ-reduced operator B A⁻¹ Bᵀ.
    g0 : (m,) array_like
        Gap of the unconstrained solution, B A⁻¹ F.
    max_iter : int
        Maximum number of PDAS linear solves; then the NNLS route finishes (``route``
        ``"pdas+nnls"``, the history records ``reason`` = ``"max_iter"``).
    tol : float
        Relative tolerance of the final KKT check (raised to 16·m·eps if smaller): the
        violations of g ≥ 0, λ ≥ 0 and λ∘g = 0 are measured against ‖g0‖ + λ_max(K)‖λ‖
        and that scale over λ_max(K).
    kernel_rtol : float
        Eigenvalues ≤ kernel_rtol · λ_max(K) count as kernel (numerical rank).

    Returns
    -------
    PdasResult

    Raises
    ------
    InputError
        Non-square / non-symmetric / indefinite K, wrong g0 length, non-finite data,
        bad options.
    PdasDidNotConverge
        If no route passes the KKT check (an infeasible LCP, or NNLS' own iteration cap);
        carries ``history``.
    """
    _check_options(max_iter, tol, kernel_rtol)
    prob = _Lcp.build(*_check_lcp(K, g0), tol, kernel_rtol)
    K, g0 = prob.K, prob.g0
    lam, iters, history, status = _pdas_loop(K, g0, _scaling(K, prob.lam_max), prob.cutoff,
                                             max_iter, tol, prob.lam_max, prob.definite)
    route = "pdas"
    if status != "converged" or not prob.kkt_ok(lam):
        lam = _nnls_dual(K, g0, prob.cutoff)
        route = "pdas+nnls"
        history.append(dict(fallback="nnls", reason=status,
                            residual=natural_residual(lam, g0 + K @ lam)))
    if not prob.kkt_ok(lam):
        raise PdasDidNotConverge(f"no verified LCP solution ({prob.violations(lam)})", history)
    lam, Z, idx = _representative(prob, lam, history)
    return _result(prob, lam, Z, idx, iters, history, route)


@dataclass(frozen=True)
class _Lcp:
    """The validated LCP data plus the spectral quantities every step needs."""

    K: np.ndarray
    g0: np.ndarray
    eigs: np.ndarray  # eigenvalues of K
    lam_max: float
    cutoff: float     # kernel_rtol · λ_max(K)
    tol: float

    @classmethod
    def build(cls, K, g0, tol, kernel_rtol):
        eigs = sla.eigvalsh(K) if K.size else np.zeros(0)
        lam_max = float(eigs.max(initial=0.0))
        if eigs.min(initial=0.0) < -1e-8 * max(lam_max, np.finfo(float).tiny):
            raise InputError("K", "a positive semi-definite matrix",
                             got=f"min eigenvalue {eigs.min():.3e}")
        return cls(K, g0, eigs, lam_max, kernel_rtol * lam_max, tol)

    @property
    def definite(self) -> bool:
        """Every eigenvalue of K above the kernel cutoff: K and all K_𝒜𝒜 are nonsingular."""
        return bool(self.eigs.size and self.eigs.min() > self.cutoff)

    def tolerances(self, lam):
        return tolerances(self.g0, lam, self.lam_max, self.tol)

    def kkt_ok(self, lam):
        return kkt_ok(lam, self.g0 + self.K @ lam, *self.tolerances(lam))

    def violations(self, lam):
        g = self.g0 + self.K @ lam
        return (f"min gap {g.min(initial=0.0):.3e}, min lambda {lam.min(initial=0.0):.3e}, "
                f"complementarity {np.max(np.abs(lam * g), initial=0.0):.3e}")


def _representative(prob, lam, history):
    """Swap a verified λ for the minimum-norm solution of the LCP (if λ can move).

    The min-norm λ is only accepted if it passes the KKT check itself; otherwise the
    verified input is kept and the history says so.  Returns (lam, Z, idx) for the
    uniqueness analysis.
    """
    gtol, _ = prob.tolerances(lam)
    S = prob.g0 + prob.K @ lam <= gtol  # g is the same for all solutions: S bounds supports
    lam_mn, Z, idx = min_norm_representative(prob.K, prob.g0, lam, S, prob.cutoff, prob.definite)
    if Z is None:
        return lam, Z, idx
    ok = prob.kkt_ok(lam_mn)
    history.append(dict(postprocess="min-norm", kernel_dim_S=Z.shape[1], accepted=ok,
                        change=float(np.abs(lam_mn - lam).max(initial=0.0))))
    return (lam_mn if ok else lam), Z, idx


def _result(prob, lam, Z, idx, iters, history, route):
    """Assemble the PdasResult: contact set, kernels, uniqueness, KKT measures."""
    g = prob.g0 + prob.K @ lam
    active = lam > prob.tolerances(lam)[1]
    kdim = _nullity(prob.K[np.ix_(active, active)], prob.cutoff, prob.definite)
    return PdasResult(
        lam=lam, gap=g, active=active, iterations=iters,
        complementarity=float(np.max(np.abs(lam * g), initial=0.0)),
        min_gap=float(g.min(initial=np.inf)), min_lambda=float(lam.min(initial=np.inf)),
        nonunique=bool(kdim > 0 or has_free_direction(Z, idx, active)),
        kernel_dim=kdim, kernel_dim_K=int(np.sum(prob.eigs <= prob.cutoff)),
        history=history, route=route)


__all__ = ["PdasDidNotConverge", "PdasResult", "solve_pdas"]
