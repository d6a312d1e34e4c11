"""Peer QP solvers for the discrete contact problem (4.1), for the speed benchmarks.

The contact problem is the convex QP

    minimize ½ uᵀ A u − Fᵀ u   subject to   B u ≥ 0,

with A = diag(c1 K1, c2 K2) the stiffness on the free dofs of both membranes, F the
loads and B = [−B1, B2] the weighted gaps (B_i embedded on the Γ dofs, which are the
last block of each side). Its KKT conditions are exactly (4.1) in the convention of
:mod:`infsup_contact.contact.pdas`:

    A u = F + Bᵀ λ,   λ ≥ 0,   B u ≥ 0,   λ∘(B u) = 0,

so the multiplier λ is the dual of the constraint B u ≥ 0. Each peer's own sign
convention is translated here:

* **OSQP** (``l ≤ C x ≤ u``, KKT ``P x + q + Cᵀ y = 0``): with C = B, l = 0, u = +∞ an
  active lower bound has y ≤ 0, hence λ = −y.
* **Clarabel** (``C x + s = b, s ∈ K``, KKT ``P x + q + Cᵀ z = 0, z ∈ K*``): with
  C = −B, b = 0, K = ℝ₊ᵐ, λ = z.
* **qpsolvers** (``G x ≤ h``, KKT ``P x + q + Gᵀ z = 0``, z ≥ 0): with G = −B, h = 0,
  λ = z.

All peers get the same assembled data (A sparse SPD, B sparse, F) and are run with one
thread. Their time includes the conversion of the data to their input format (upper
triangle, CSC), setup (scaling, KKT factorization) and the solve.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..contact.contact import contact_qp  # the assembled QP all peers get

TOLERANCES = tuple(10.0 ** -e for e in range(3, 16))
"""Tolerances tried, loosest first, when tuning a peer to reproduce our solution."""

PEERS = ("osqp", "clarabel")
"""The peers of the contact benchmark (their own Python APIs)."""


@dataclass
class QpResult:
    """A peer's solution of the contact QP.

    Attributes
    ----------
    u : ndarray (n,)
    lam : ndarray (m,)
        Multipliers in the convention A u = F + Bᵀ λ, λ ≥ 0.
    iterations : int
        The peer's own iteration count (ADMM iterations, interior-point iterations).
    status : str
        The peer's status string.
    tolerance : float
        The tolerance the peer was run with (see the solver functions).
    settings : dict
        Every non-default setting passed.
    """

    u: np.ndarray
    lam: np.ndarray
    iterations: int
    status: str
    tolerance: float
    settings: dict = field(default_factory=dict)


# ----------------------------------------------------------------------------- OSQP
def solve_osqp(A, B, F, tol: float = 1e-6, *, polishing: bool = True, polish_refine_iter: int = 10,
               max_iter: int = 1_000_000, time_limit: float = 0.0) -> QpResult:
    """OSQP (ADMM; its own Python API ``osqp.OSQP``) with eps_abs = eps_rel = ``tol``.

    ``polishing`` (OSQP's solution polishing: one reduced KKT solve on the active set
    guessed by ADMM) is on by default: without it ADMM needs very tight tolerances (many
    thousand iterations) to reproduce a solution to 1e-8. ``polish_refine_iter`` = 10
    (OSQP's default is 3): the polished KKT system is regularized (delta = 1e-6) and on
    the finer meshes 3 refinement steps leave a relative error ~1e-7 in λ, 10 reach
    round-off at a small cost (N = 256, k = 1). ``time_limit`` in seconds, 0 = none.
    """
    import osqp

    settings = dict(eps_abs=tol, eps_rel=tol, polishing=polishing, max_iter=max_iter,
                    verbose=False)
    if polishing:
        settings["polish_refine_iter"] = int(polish_refine_iter)
    if time_limit > 0:
        settings["time_limit"] = float(time_limit)
    solver = osqp.OSQP()
    m = B.shape[0]
    solver.setup(sp.triu(A, format="csc"), -np.asarray(F, dtype=float), sp.csc_matrix(B),
                 np.zeros(m), np.full(m, np.inf), **settings)
    res = solver.solve(raise_error=False)  # a failed solve is reported by its status
    status = str(res.info.status)
    if polishing:
        status += f" (polish {int(res.info.status_polish)})"
    lam = -np.asarray(res.y, dtype=float)
    return QpResult(np.asarray(res.x, dtype=float), lam, int(res.info.iter), status, tol,
                    {k: v for k, v in settings.items() if k != "verbose"})


# ------------------------------------------------------------------------- Clarabel
def solve_clarabel(A, B, F, tol: float = 1e-8, *, method: str = "qdldl",
                   time_limit: float = 0.0) -> QpResult:
    """Clarabel (interior point; its own Python API) with tol_gap_abs = tol_gap_rel =
    tol_feas = ``tol`` and tol_ktratio = min(tol, its default 1e-6).

    ``method``: Clarabel's ``direct_solve_method`` (``qdldl``, or ``faer``: supernodal),
    one thread (``max_threads = 1``). ``time_limit`` in seconds, 0 = none.
    """
    import clarabel

    s = clarabel.DefaultSettings()
    s.verbose = False
    s.max_threads = 1
    s.direct_solve_method = method
    s.tol_gap_abs = s.tol_gap_rel = s.tol_feas = tol
    s.tol_ktratio = min(s.tol_ktratio, tol)
    s.max_iter = 500
    if time_limit > 0:
        s.time_limit = float(time_limit)
    m = B.shape[0]
    solver = clarabel.DefaultSolver(sp.triu(A, format="csc"), -np.asarray(F, dtype=float),
                                    sp.csc_matrix(-B), np.zeros(m),
                                    [clarabel.NonnegativeConeT(m)], s)
    res = solver.solve()
    settings = dict(tol_gap_abs=tol, tol_gap_rel=tol, tol_feas=tol, tol_ktratio=s.tol_ktratio,
                    direct_solve_method=method, max_threads=1, max_iter=500)
    return QpResult(np.asarray(res.x, dtype=float), np.asarray(res.z, dtype=float),
                    int(res.iterations), str(res.status), tol, settings)


# ------------------------------------------------------------------------ qpsolvers
def solve_qpsolvers(A, B, F, solver: str, **options) -> QpResult:
    """Any QP solver through ``qpsolvers.solve_problem`` (cross-check of the conventions)."""
    try:
        import qpsolvers
    except ImportError as err:  # an optional peer: pyproject's extra `peers`
        raise ImportError("solve_qpsolvers needs qpsolvers: pip install 'infsup-contact[peers]'") from err

    m = B.shape[0]
    prob = qpsolvers.Problem(sp.csc_matrix(A), -np.asarray(F, dtype=float),
                             sp.csc_matrix(-B), np.zeros(m))
    sol = qpsolvers.solve_problem(prob, solver=solver, **options)
    if not sol.found:
        raise RuntimeError(f"qpsolvers/{solver}: no solution found")
    return QpResult(np.asarray(sol.x, dtype=float), np.asarray(sol.z, dtype=float), -1,
                    "found", float("nan"), dict(options))


SOLVERS = {"osqp": solve_osqp, "clarabel": solve_clarabel}


# --------------------------------------------------------------------------- compare
def relative_differences(res: QpResult, u_ref, lam_ref) -> tuple[float, float]:
    """(max|u − u_ref| / max|u_ref|, max|λ − λ_ref| / max|λ_ref|)."""
    du = np.abs(res.u - u_ref).max(initial=0.0) / max(np.abs(u_ref).max(initial=0.0), 1e-300)
    dl = np.abs(res.lam - lam_ref).max(initial=0.0) / max(np.abs(lam_ref).max(initial=0.0), 1e-300)
    return float(du), float(dl)


__all__ = ["QpResult", "contact_qp", "solve_osqp", "solve_clarabel", "solve_qpsolvers",
           "relative_differences", "SOLVERS", "PEERS", "TOLERANCES"]
