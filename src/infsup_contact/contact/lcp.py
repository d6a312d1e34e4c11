"""The LCP of (4.1), g = g0 + Kλ, λ ≥ 0, g ≥ 0, λ∘g = 0: when a computed (λ, g) solves it,
and which solution is returned when there are many.

Both solvers (:mod:`.pdas` on the Γ-reduced K, :mod:`.kkt` on the sparse saddle-point system)
stop and verify with the same test: :func:`kkt_ok` at the :func:`tolerances` of the data's
scale. g is unique; λ is not when K is singular on the contact set (the discrete inf-sup
condition fails, paper end of §4). The solution set is then a polyhedron;
:func:`min_norm_representative` picks its minimum-norm point (a least-distance programme) and
:func:`has_free_direction` decides whether the set has more than one point.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
from scipy.optimize import linprog, nnls

_EPS = np.finfo(float).eps


# ------------------------------------------------------------------ when (λ, g) solves it
def tolerances(g0, lam, lam_max, tol):
    """Absolute zero tolerances for g and λ, relative to the data scale.

    g = g0 + Kλ is a sum of terms of size ‖g0‖ and λ_max‖λ‖, so round-off in g scales
    with their sum; the λ scale is that gap scale divided by λ_max (units of K⁻¹g).
    """
    m = max(g0.size, 1)
    rel = max(tol, 16 * m * _EPS)
    gscale = np.abs(g0).max(initial=0.0) + lam_max * np.abs(lam).max(initial=0.0)
    gscale = max(gscale, np.finfo(float).tiny)
    lscale = max(np.abs(lam).max(initial=0.0), gscale / lam_max if lam_max > 0 else 0.0,
                 np.finfo(float).tiny)
    return rel * gscale, rel * lscale


def kkt_ok(lam, g, gtol, ltol):
    """λ ≥ −ltol, g ≥ −gtol and |λ_j g_j| within the product of tolerance and scale."""
    return (g.min(initial=0.0) >= -gtol and lam.min(initial=0.0) >= -ltol
            and np.max(np.abs(lam * g), initial=0.0) <= max(gtol * np.abs(lam).max(initial=0.0),
                                                            ltol * np.abs(g).max(initial=0.0)))


def natural_residual(lam, g):
    """max_j |min(λ_j, g_j)|: zero iff (λ, g) solves the LCP."""
    return float(np.max(np.abs(np.minimum(lam, g)), initial=0.0))


# ------------------------------------------------------------------ the solution set
def min_norm_solve(M, rhs, cutoff, definite=False):
    """Minimum-norm solution of M z = rhs (M symmetric PSD) and the kernel basis.

    Spectral pseudo-inverse: eigen-directions with eigenvalue ≤ cutoff are the
    numerical kernel and get no component (= scipy.linalg.pinvh with that cutoff).
    ``definite``: M is known to have all eigenvalues above the cutoff (a principal
    submatrix of a K whose smallest eigenvalue is, by Cauchy interlacing), so the kernel
    is empty and a Cholesky solve gives the same z at a fraction of the cost.
    """
    if definite:
        z = sla.cho_solve(sla.cho_factor(M, check_finite=False), rhs, check_finite=False)
        return z, np.zeros((len(rhs), 0))
    w, V = sla.eigh(M)
    keep = w > cutoff
    Vr = V[:, keep]
    z = Vr @ ((Vr.T @ rhs) / w[keep])
    return z, V[:, ~keep]


def least_distance(G, h):
    """min ‖z‖ s.t. G z ≥ h (Lawson & Hanson LDP, via NNLS); None if infeasible."""
    k = G.shape[1]
    E = np.vstack([G.T, h[None, :]])
    f = np.zeros(k + 1)
    f[-1] = 1.0
    u, _ = nnls(E, f, maxiter=50 * max(E.shape[1], 1))
    r = E @ u - f
    if abs(r[-1]) < 1e-14:
        return None
    return -r[:k] / r[-1]


def min_norm_representative(K, g0, lam, S, cutoff, definite=False):
    """Replace λ by the minimum-norm solution of the LCP (see module docstring).

    All solutions are λ = λ* + Z z ≥ 0 (support in S), λ* the min-norm solution of
    K_SS λ_S = −g0_S and Z an orthonormal kernel basis of K_SS; since λ* ⊥ Z,
    ‖λ‖² = ‖λ*‖² + ‖z‖², so the task is the LDP  min ‖z‖ s.t. Z z ≥ −λ*.
    Returns (lam, Z, idx) with Z = None when the kernel is trivial.
    """
    idx = np.flatnonzero(S)
    if idx.size == 0:
        return lam, None, idx
    if definite:  # K_SS nonsingular: the solution is unique, nothing to choose
        return lam, None, idx
    lam_s, Z = min_norm_solve(K[np.ix_(idx, idx)], -g0[idx], cutoff)
    if Z.shape[1] == 0:
        return lam, None, idx
    z = least_distance(Z, -lam_s)
    if z is None:  # numerically infeasible: keep the (verified) input solution
        return lam, Z, idx
    out = np.zeros_like(lam)
    out[idx] = lam_s + Z @ z  # ≥ 0 up to round-off; the final KKT check verifies it
    return out, Z, idx


def has_free_direction(Z, idx, positive):
    """Whether a kernel direction d = Z t ≠ 0 keeps λ + εd ≥ 0 for small ε > 0.

    d may have any sign on the positive multipliers P; on the zero multipliers S0 of
    the contact set it must be ≥ 0.  If ker K_PP ≠ 0 the answer is yes; otherwise
    t ↦ d_S0 is injective and the LP  max Σ d_S0  s.t. 0 ≤ d_S0 ≤ 1  is bounded with a
    positive optimum iff such a direction exists.
    """
    if Z is None:
        return False
    Z0 = Z[~positive[idx]]
    if Z0.shape[0] == 0 or np.linalg.matrix_rank(Z0, tol=1e-8) < Z.shape[1]:
        return True  # some direction lives on P only: ker K_PP ≠ 0
    res = linprog(-Z0.sum(axis=0), A_ub=np.vstack([Z0, -Z0]),
                  b_ub=np.concatenate([np.ones(len(Z0)), np.zeros(len(Z0))]),
                  bounds=[(None, None)] * Z.shape[1], method="highs")
    return bool(res.status == 0 and -res.fun > 1e-8)
