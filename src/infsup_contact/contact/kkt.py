"""PDAS on the full sparse KKT system (4.1): the independent route the Γ-reduced solver is checked
against (tests, ``bench``'s ``kkt_sparse``).

Each active-set step solves the saddle-point system [[A, −B_𝒜ᵀ], [B_𝒜, 0]] by sparse LU, never
forming the interface operator; the stopping test is :mod:`.lcp`'s, the result :mod:`.pdas`'s.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import InputError
from .lcp import kkt_ok, natural_residual, tolerances
from .pdas import PdasDidNotConverge, _check_options


def _check_kkt(A, B, F):
    """Sparse A (csc), B (csr) and dense F with consistent shapes, else InputError."""
    A = sp.csc_matrix(A, dtype=float)
    B = sp.csr_matrix(B, dtype=float)
    F = np.asarray(F, dtype=float).reshape(-1)
    n = A.shape[0]
    if A.shape != (n, n):
        raise InputError("A", "a square matrix", got=f"shape {A.shape}")
    if B.shape[1] != n:
        raise InputError("B", f"a matrix with {n} columns", got=f"shape {B.shape}")
    if F.shape != (n,):
        raise InputError("F", f"a vector of length {n}", got=F.shape)
    return A, B, F


def _saddle_solve(A, Ba, F, lu_A):
    """Solve [[A, −Baᵀ], [Ba, 0]] [u; λ_𝒜] = [F; 0] by sparse LU (never forms K)."""
    k = Ba.shape[0]
    if k == 0:
        return lu_A.solve(F), np.zeros(0)
    M = sp.bmat([[A, -Ba.T], [Ba, None]], format="csc")
    try:
        sol = spla.splu(M).solve(np.concatenate([F, np.zeros(k)]))
    except RuntimeError as exc:  # exactly singular: dependent active rows
        raise np.linalg.LinAlgError(
            "saddle-point system singular: active rows of B are linearly dependent "
            "(λ not unique); use solve_pdas") from exc
    if not np.all(np.isfinite(sol)):
        raise np.linalg.LinAlgError("saddle-point solve produced non-finite values")
    n = A.shape[0]
    return sol[:n], sol[n:]


def solve_kkt_sparse(A, B, F, *, max_iter=50):
    """PDAS on the full sparse saddle-point system (cross-check of :func:`solve_pdas`).

    Same iteration as :func:`solve_pdas` — 𝒜 = {λ_j − c_j g_j > 0} from λ⁰ = 0, stop
    when 𝒜 repeats or the iterate passes the KKT check — but each step solves the (n + |𝒜|) sparse system

        [[A, −B_𝒜ᵀ], [B_𝒜, 0]] [u; λ_𝒜] = [F; 0]

    (the first equation of (4.1) with g_𝒜 = B_𝒜 u = 0) by sparse LU, never forming K.
    The scaling is the Jacobi estimate c_j = 1/(b_jᵀ diag(A)⁻¹ b_j) of 1/K_jj (iterates
    are independent of c up to round-off ties, see :func:`solve_pdas`).

    Parameters
    ----------
    A : (n, n) sparse SPD
    B : (m, n) sparse
    F : (n,) array_like
    max_iter : int

    Returns
    -------
    u : ndarray (n,)
    lam : ndarray (m,)
    iterations : int

    Raises
    ------
    InputError
        Shape mismatch or bad ``max_iter``.
    numpy.linalg.LinAlgError
        If the active rows are linearly dependent (non-unique λ: use solve_pdas).
    PdasDidNotConverge
        After ``max_iter`` steps or on cycling (no fallback on this route).
    """
    _check_options(max_iter, 1e-12, 1e-10)
    A, B, F = _check_kkt(A, B, F)
    lu_A = spla.splu(A)
    dinv = 1.0 / A.diagonal()
    kjj = np.asarray(B.multiply(B) @ dinv).reshape(-1)
    c = np.where(kjj > 0, 1.0 / np.where(kjj > 0, kjj, 1.0), 1.0)
    u = lu_A.solve(F)
    g0 = B @ u
    kscale = float(kjj.max(initial=0.0))  # stands in for λ_max(K) in the tolerances
    lam = np.zeros(B.shape[0])
    active = (lam - c * g0) > 0
    seen, history = {active.tobytes()}, []
    for it in range(1, max_iter + 1):
        u, lam_a = _saddle_solve(A, B[active], F, lu_A)
        lam = np.zeros(B.shape[0])
        lam[active] = lam_a
        g = B @ u
        new = (lam - c * g) > 0
        history.append(dict(iteration=it, n_active=int(active.sum()),
                            residual=natural_residual(lam, g),
                            n_changed=int(np.sum(new != active))))
        if np.array_equal(new, active) or kkt_ok(lam, g, *tolerances(g0, lam, kscale, 1e-12)):
            return u, lam, it
        if new.tobytes() in seen:
            raise PdasDidNotConverge("sparse PDAS cycles; use solve_pdas", history)
        seen.add(new.tobytes())
        active = new
    raise PdasDidNotConverge(f"sparse PDAS did not converge in {max_iter} iterations",
                             history)
