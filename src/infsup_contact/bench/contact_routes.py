"""Contact (:func:`bench_contact`): the membranes scene, case T3, the QP
``min ½uᵀAu − Fᵀu s.t. B u ≥ 0`` (:mod:`infsup_contact.bench.peers`). Every route except
``ours_end_to_end`` gets the same assembled (A, B, F) — exactly what the peers get:

``ours``
    :func:`infsup_contact.contact.reduced_qp.solve_reduced_qp`: the unknowns B touches (Γ) read off B, one
    factorization per block of A with Γ last, interface operator, PDAS on the Γ-reduced
    LCP, recovery of u.
``ours_end_to_end``
    End to end (:func:`infsup_contact.contact.contact.solve_contact`): meshes, NGSolve assembly, loads,
    and the same linear algebra built side by side.
``floor``
    One sparse direct solve of the linear saddle-point system with the contact set
    known (:func:`infsup_contact.contact.contact.linear_saddle_solve`: symmetric quasi-definite, SuperLU
    in minimum-degree order without pivoting); its u and λ are compared too.
``limit``
    One best-order (``MMD_AT_PLUS_A``) sparse LU of each side's stiffness and one solve
    with it (:func:`contact_limit`): what no route can avoid, like β's ``limit``.
``osqp``, ``clarabel``
    The peers through their own Python APIs (:mod:`infsup_contact.bench.peers`), given the
    assembled (A, B, F), one thread, at the loosest tolerance of
    :data:`peers.TOLERANCES` that reproduces our u and λ to ``rtol`` = 1e-8 relative
    (``tolerance``, ``accuracy_reached``). They get the load normalized to max|F| = 1
    (the QP is positively homogeneous in F: u and λ are scaled back), otherwise their
    absolute tolerance floors make the needed tolerances depend on the mesh size.
``kkt_sparse``
    PDAS on the full sparse KKT system (:func:`infsup_contact.contact.kkt.solve_kkt_sparse`), N ≤ ``kkt_max_n``.
"""
from __future__ import annotations

import json
import time

import numpy as np

from ..discretization.segment import meshes
from ..discretization.spaces import registry
from ..discretization.spaces.registry import REFERENCE_SPACE
from ..discretization.gamma.coupling import coupling_matrix
from ..models.membranes import side_operator
from .beta_bench import splu_best_order
from .harness import ROUTE_BUDGET, _log, _row, run_interleaved


RTOL = 1e-8
"""Peers must reproduce our u and λ to this relative accuracy (max norm)."""
CONTACT_COLUMNS = ("what", "route", "k", "N", "seconds_median", "seconds_min", "seconds_max",
                   "ratio_to_ours", "ratio_to_limit", "max_abs_diff", "rel_diff_u",
                   "rel_diff_lambda", "iterations", "tolerance", "accuracy_reached", "repeats",
                   "ndof", "dim_M", "includes")


def _contact_problem(n: int, k: int, case: str = REFERENCE_SPACE):
    """Membranes scene on the structured N×N pair: sides, couplings, loads (c = 1), as
    :func:`infsup_contact.contact.contact.solve_contact` builds them."""
    from ..models.membranes import MEMBRANES
    from ..study.contact.scenes import membranes

    sc = membranes()
    m1, m2 = meshes.mesh_pair("structured", n, n)
    sides = [side_operator(m, k) for m in (m1, m2)]
    gamma = sides[0].trace.gamma
    space = registry.case_space(case, k, gamma.multiplier_partition(*(s.trace.partition for s in sides)), gamma)
    Bs = [coupling_matrix(s.trace, space, k) for s in sides]
    return sc, sides, Bs, [MEMBRANES.load(s, sc, i)[0] for i, s in enumerate(sides)]


def contact_limit(sides, F, c=(1.0, 1.0)):
    """The cost no contact solver avoids: one sparse factorization of each side's stiffness
    in SuperLU's best order (``MMD_AT_PLUS_A``, symmetric mode) and one solve with it."""

    def run():
        for s, Fi, ci in zip(sides, F, c):
            splu_best_order(ci * s.stiffness).solve(Fi)

    return run


def _ours_u(sol) -> np.ndarray:
    return np.concatenate([gf.vec.FV().NumPy()[s.free] for gf, s in zip(sol.u, sol.sides)])


def _peer_route(solver, A, B, F, tol, **kwargs):
    """A peer on the normalized problem (max|F| = 1); returns the QpResult scaled back."""
    scale = float(np.abs(F).max()) or 1.0

    def run():
        res = solver(A, B, F / scale, tol, **kwargs)
        res.u, res.lam = res.u * scale, res.lam * scale
        return res

    return run


CONTACT_INCLUDES = {
    "ours": "Γ from B+LU per block of A (Γ last)+interface+PDAS+recovery (assembled A, B, F given)",
    "ours_end_to_end": "mesh+assembly+loads+Γ-last LU+Schur+interface+PDAS+recovery",
    "floor": "one sparse LU solve of the quasi-definite saddle-point system (assembled, contact set known)",
    "limit": "best-order sparse LU of each side's stiffness + one solve (assembled A given)",
    "osqp": "triu/CSC conversion+OSQP setup (scaling, KKT LDL)+ADMM+polishing (assembled A, B, F given)",
    "clarabel": "triu/CSC conversion+Clarabel setup+interior point (assembled A, B, F given)",
    "kkt_sparse": "PDAS with one sparse saddle-point LU per iteration (assembled A, B, F given)",
}


def bench_contact(ns, ks, repeats: int = 3, case: str = REFERENCE_SPACE, peers=("osqp", "clarabel"),
                  peer_options: dict | None = None, tolerances=None, peer_time_limit: float = 600.0,
                  kkt_max_n: int = 64, budget: float = ROUTE_BUDGET, tune_budget: float = 1200.0):
    """Contact solves of the membranes scene: ours against the floor and the peers.

    Parameters
    ----------
    ns, ks : mesh sizes N and degrees k.
    repeats : repetitions per route (interleaved; median, min, max reported).
    case : multiplier case (T3).
    peers : names in :data:`peers.SOLVERS`.
    peer_options : {peer: kwargs}, default ``{"clarabel": {"method": "faer"}}``.
    tolerances : tolerances tried per peer (default :data:`peers.TOLERANCES`); the search
        starts at the tolerance found for the previous N of the same k.
    peer_time_limit : time limit of one peer solve (seconds; passed to the peer).
    tune_budget : the tolerance search of one peer stops tightening after this many seconds.
    kkt_max_n : the kkt_sparse route runs for N ≤ this.
    budget : a route is not repeated once its accumulated time exceeds this (seconds).

    Returns
    -------
    list of dict with the columns :data:`CONTACT_COLUMNS`; also ``tuning`` (the trials of
    the tolerance search: tol, rel. diff u, rel. diff λ, iterations, seconds, status).
    """
    from . import peers as peer_mod
    from ..contact.kkt import solve_kkt_sparse
    from ..contact.contact import linear_saddle_solve, solve_contact
    from ..contact.reduced_qp import solve_reduced_qp
    from ..study.contact.scenes import membranes

    peer_options = {"clarabel": {"method": "faer"}} if peer_options is None else peer_options
    tolerances = tuple(tolerances or peer_mod.TOLERANCES)
    rows = []
    for k in ks:
        start = {p: None for p in peers}
        for n in ns:
            _log(f"contact k={k} N={n}: setup")
            sc, sides, Bs, F = _contact_problem(n, k, case)
            c = (sc.c1, sc.c2)
            A, B, Fv = peer_mod.contact_qp(sides, Bs, F, c)
            ref = solve_contact(membranes(), case, k, "structured", n, n, time_floor=False)
            u_ref, lam_ref = _ours_u(ref), ref.lam
            routes = {"ours": lambda: solve_reduced_qp(A, B, Fv),
                      "ours_end_to_end": lambda: solve_contact(membranes(), case, k, "structured", n, n,
                                                        time_floor=False),
                      "floor": lambda: linear_saddle_solve(A, B, Fv, ref.pdas.active),
                      "limit": contact_limit(sides, F, c)}
            tuned = {}
            for p in peers:
                solver, opts = peer_mod.SOLVERS[p], dict(peer_options.get(p, {}))
                opts["time_limit"] = peer_time_limit
                tol, res, ok, trials = tune_peer(solver, A, B, Fv, u_ref, lam_ref, tolerances,
                                                 start[p], opts, time_budget=tune_budget)
                start[p] = tol if ok else start[p]
                tuned[p] = (tol, ok, trials)
                _log(f"  {p}: tolerance {tol:g} reached={ok} trials={[(t[0], f'{t[1]:.1e}', f'{t[2]:.1e}', t[3], round(t[4], 2)) for t in trials]}")
                routes[p] = _peer_route(solver, A, B, Fv, tol, **opts)
            if n <= kkt_max_n:
                routes["kkt_sparse"] = lambda: solve_kkt_sparse(A, B, Fv)
            res = run_interleaved(routes, repeats, budget)
            med_ours = float(np.median(res["ours"][1]))
            med_limit = float(np.median(res["limit"][1]))
            common = dict(ndof=A.shape[0], dim_M=B.shape[0])
            for name, (out, times) in res.items():
                u, lam, its, extra = _contact_outcome(name, out, tuned)
                if u is None:
                    diffs = dict(max_abs_diff=np.nan, rel_diff_u=np.nan, rel_diff_lambda=np.nan)
                else:
                    du, dl = peer_mod.relative_differences(peer_mod.QpResult(u, lam, 0, "", 0.0),
                                                           u_ref, lam_ref)
                    diffs = dict(max_abs_diff=float(np.abs(lam - lam_ref).max(initial=0.0)),
                                 rel_diff_u=du, rel_diff_lambda=dl)
                rows.append(_row("contact", name, k, n, times, med_ours, med_limit, "ratio_to_limit",
                                 iterations=its, includes=CONTACT_INCLUDES[name], **diffs, **extra,
                                 **common))
                _log(f"  {name:10s} {np.median(times):9.4f} s  its {its}  rel.diff λ {diffs['rel_diff_lambda']:.2e}")
    return rows


def _contact_outcome(name, out, tuned):
    """(u, λ, iterations, extra columns) of one contact route's last result."""
    extra = dict(tolerance=np.nan, accuracy_reached=np.nan, tuning="")
    if name == "ours":
        return out.u, out.lam, out.iterations, extra
    if name == "ours_end_to_end":
        return _ours_u(out), out.lam, out.pdas.iterations, extra
    if name == "floor":
        return out[0], out[1], 1, extra
    if name == "limit":
        return None, None, 1, extra
    if name == "kkt_sparse":
        return *out, extra
    tol, ok, trials = tuned[name]
    extra = dict(tolerance=tol, accuracy_reached=ok, settings=json.dumps(out.settings),
                 status=out.status,
                 tuning="; ".join(f"{t[0]:g}:{t[1]:.1e}/{t[2]:.1e}/{t[3]}it/{t[4]:.3g}s"
                                  for t in trials))
    return out.u, out.lam, out.iterations, extra


def tune_peer(solver, A, B, F, u_ref, lam_ref, tolerances, start=None, opts=None, rtol: float = RTOL,
              time_budget: float = np.inf):
    """Loosest tolerance of ``tolerances`` at which a peer reproduces (u_ref, λ_ref) to
    ``rtol`` (relative, max norm), on the normalized problem (max|F| = 1).

    The search starts at ``start`` (e.g. the tolerance found on the previous mesh):
    if that reproduces the solution, looser ones are tried until one fails; otherwise
    tighter ones until one succeeds (or the list ends, or the trials have taken more than
    ``time_budget`` seconds).

    Returns (tol, QpResult, reached, trials); trials are tuples
    (tol, rel. diff u, rel. diff λ, iterations, seconds, status).
    """
    from .peers import relative_differences

    opts = opts or {}
    tolerances = sorted(tolerances, reverse=True)  # loosest first
    i = tolerances.index(start) if start in tolerances else 0
    trials, results = [], {}

    def attempt(j):
        tol = tolerances[j]
        t = time.perf_counter()
        try:
            res = _peer_route(solver, A, B, F, tol, **opts)()
        except Exception as exc:  # noqa: BLE001 - a failing peer is a data point
            trials.append((tol, np.inf, np.inf, -1, time.perf_counter() - t, repr(exc)[:80]))
            return False
        du, dl = relative_differences(res, u_ref, lam_ref)
        trials.append((tol, du, dl, res.iterations, time.perf_counter() - t, res.status))
        results[j] = res
        return du <= rtol and dl <= rtol

    if attempt(i):
        best = i
        while best > 0 and attempt(best - 1):
            best -= 1
        return tolerances[best], results[best], True, trials
    for j in range(i + 1, len(tolerances)):
        if sum(t[4] for t in trials) > time_budget:
            break
        if attempt(j):
            return tolerances[j], results[j], True, trials
    last = max(results) if results else len(tolerances) - 1
    return tolerances[last], results.get(last), False, trials
