"""Speed measured as ratios in one run on one machine (never asserted in unit tests).

Every timing is repeated and reported as median, min and max; the routes of one size
are run interleaved (repeat 1 of every route, then repeat 2, ...) so that a change in
machine load hits all of them alike. ``ratio_to_ours`` = route seconds / ``ours``
seconds; β tables add ``ratio_to_ours_core`` (/ ``ours_core``), contact tables
``ratio_to_limit`` (/ ``limit``: how close a route comes to the unavoidable
factorization). All ratios are of medians.
Run with one BLAS thread (``OPENBLAS_NUM_THREADS=1``, the CLI's default).

β_h (:func:`bench_beta`): the problem is β_h of **every valid case × both norms (H, L2)**
on the structured N × N pair; every route answers all of them. What each time includes
(also in the ``includes`` column):

``ours``
    End to end, as ``infsup-contact beta`` runs it (:func:`infsup.beta_rows`): meshes,
    NGSolve assembly, one Γ-last factorization per side + Schur complement, per case the
    couplings and the interface operator, per norm the Gram matrix and the dense ``eigh``
    — plus what ``beta_rows`` reports besides β (β with v1 = 0: a second operator and
    ``eigh`` per case and norm).
``ours_core``
    Given the assembled stiffness matrices (Γ last) and the multiplier spaces: Γ-last
    factorization + Schur complement per side, couplings, interface operator, Gram
    matrix and one dense ``eigh`` per (case, norm) — exactly what β_h needs.
``limit``
    The floor of any route, given the assembled stiffness matrices and (precomputed)
    interface operators and Gram matrices: one sparse factorization of each side's
    stiffness in SuperLU's best order (``MMD_AT_PLUS_A``, symmetric mode) + one dense
    generalized ``eigh`` of multiplier size per (case, norm). ``ours_core / limit`` is
    the apples-to-apples overhead of the Γ-reduced route.
``eigsh``
    Given the same assembled data as ``ours_core``: couplings, Gram matrix, the full
    saddle-point pencil [[A, Bᵀ], [B, 0]] x = σ [[A, 0], [0, G]] x and its bottom by
    sparse shift-invert Lanczos (``scipy.sparse.linalg.eigsh``, σ = −1e-6, ``tol=0``),
    per (case, norm), as automated inf-sup testers do (ASCoT).
``dense``
    The same pencil by dense ``scipy.linalg.eigh`` (only while its size ≤ ``dense_max_size``).

``max_abs_diff`` compares each route with ``ours`` on the same (case, norm): the
largest |β_route − β_ours| over all (case, norm), where β is the smallest inf-sup value
above the structural kernel (β_h itself for the stable pairs, the first nonzero value
for R5.2 / R5.4, whose kernel values are 0 up to round-off). ``kernel_ok`` says whether
the route's kernel values are all below ``KERNEL_BETA``.

Contact (:func:`bench_contact`): the membranes scene, case T3, the QP
``min ½uᵀAu − Fᵀu s.t. B u ≥ 0`` (:mod:`infsup_contact.peers`). Every route except
``ours_end_to_end`` gets the same assembled (A, B, F) — exactly what the peers get:

``ours``
    :func:`reduced_qp.solve_reduced_qp`: the unknowns B touches (Γ) read off B, one
    factorization per block of A with Γ last, interface operator, PDAS on the Γ-reduced
    LCP, recovery of u.
``ours_end_to_end``
    End to end (:func:`contact_problem.solve_contact`): meshes, NGSolve assembly, loads,
    and the same linear algebra built side by side.
``floor``
    One sparse direct solve of the linear saddle-point system with the contact set
    known (:func:`contact_problem.linear_saddle_solve`: symmetric quasi-definite, SuperLU
    in minimum-degree order without pivoting); its u and λ are compared too.
``limit``
    One best-order (``MMD_AT_PLUS_A``) sparse LU of each side's stiffness and one solve
    with it (:func:`contact_limit`): what no route can avoid, like β's ``limit``.
``osqp``, ``clarabel``
    The peers through their own Python APIs (:mod:`infsup_contact.peers`), given the
    assembled (A, B, F), one thread, at the loosest tolerance of
    :data:`peers.TOLERANCES` that reproduces our u and λ to ``rtol`` = 1e-8 relative
    (``tolerance``, ``accuracy_reached``). They get the load normalized to max|F| = 1
    (the QP is positively homogeneous in F: u and λ are scaled back), otherwise their
    absolute tolerance floors make the needed tolerances depend on the mesh size.
``kkt_sparse``
    PDAS on the full sparse KKT system (:func:`contact.solve_kkt_sparse`), N ≤ ``kkt_max_n``.
"""
from __future__ import annotations

import importlib.metadata as _md
import json
import os
import platform
import sys
import time

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .discretization import meshes, multipliers
from .discretization.coupling import coupling_matrix
from .solvers.infsup import beta_rows
from .models.schur import SideOperator, interface_operator
from .models.membranes import side_operator
from .discretization.norms import gram

NORMS = ("H", "L2")
KERNEL_BETA = 1e-6
"""An inf-sup value below this counts as a (structural) kernel value in ``kernel_ok``."""
RTOL = 1e-8
"""Peers must reproduce our u and λ to this relative accuracy (max norm)."""
PEER_LIBRARIES = ("osqp", "clarabel", "qpsolvers", "scikit-sparse")

BETA_COLUMNS = ("what", "route", "k", "N", "seconds_median", "seconds_min", "seconds_max",
                "ratio_to_ours", "ratio_to_ours_core", "max_abs_diff", "kernel_ok", "repeats",
                "n_problems", "ndof", "includes")
CONTACT_COLUMNS = ("what", "route", "k", "N", "seconds_median", "seconds_min", "seconds_max",
                   "ratio_to_ours", "ratio_to_limit", "max_abs_diff", "rel_diff_u",
                   "rel_diff_lambda", "iterations", "tolerance", "accuracy_reached", "repeats",
                   "ndof", "dim_M", "includes")


def _log(msg: str) -> None:
    print(f"[bench {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


# ------------------------------------------------------------------------ timing
def timed(fn, repeats: int):
    """Run ``fn`` ``repeats`` times; return (last result, median, min, max seconds)."""
    times, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return out, float(np.median(times)), float(np.min(times)), float(np.max(times))


def run_interleaved(routes: dict, repeats: int, budget: float = np.inf, max_repeats: dict | None = None,
                    self_timed=()):
    """Time several routes round-robin: repeat r of every route before repeat r + 1.

    Parameters
    ----------
    routes : {name: callable}
    repeats : int
        Wanted repetitions per route.
    budget : float
        A route is not repeated once its accumulated time exceeds ``budget`` seconds
        (it always runs once).
    max_repeats : {name: int}, optional
        Per-route cap on the repetitions (slow routes).
    self_timed : names of routes that return their own time in seconds (the wall time
        of the call, which would include their untimed set-up, is then not used).

    Returns
    -------
    {name: (last result, [seconds, ...])}
    """
    max_repeats = max_repeats or {}
    out = {name: (None, []) for name in routes}
    for r in range(repeats):
        for name, fn in routes.items():
            res, times = out[name]
            if r >= max_repeats.get(name, repeats) or (times and sum(times) > budget):
                continue
            t = time.perf_counter()
            res = fn()
            times.append(float(res) if name in self_timed else time.perf_counter() - t)
            out[name] = (res, times)
    return out


def _stats(times):
    return float(np.median(times)), float(np.min(times)), float(np.max(times))


def _row(what, route, k, n, times, ref_ours, ref_other, other="ratio_to_ours_core", **extra):
    """One table row; ``other`` names the second ratio column (route / ``ref_other``)."""
    med, lo, hi = _stats(times)
    return {"what": what, "route": route, "k": k, "N": n, "seconds_median": med,
            "seconds_min": lo, "seconds_max": hi, "ratio_to_ours": med / ref_ours,
            other: med / ref_other if ref_other else np.nan, "repeats": len(times), **extra}


# ------------------------------------------------------------------ machine info
def library_versions() -> dict:
    """Versions of the libraries the numbers depend on (provenance + the peers)."""
    from .provenance import versions

    out = versions()
    for name in PEER_LIBRARIES:
        try:
            out[name] = _md.version(name)
        except _md.PackageNotFoundError:
            out[name] = "not installed"
    try:
        import numpy as _np
        cfg = _np.show_config(mode="dicts")
        blas = cfg.get("Build Dependencies", {}).get("blas", {})
        out["numpy_blas"] = f"{blas.get('name', '?')} {blas.get('version', '')}".strip()
    except Exception:  # noqa: BLE001 - purely informational
        pass
    return out


def machine_info() -> dict:
    """CPU model, cores, load, BLAS thread setting and library versions of this run."""
    model = platform.processor()
    try:
        with open("/proc/cpuinfo") as fh:
            model = next((ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")), model)
    except OSError:
        pass
    try:
        load = list(os.getloadavg())
    except OSError:
        load = None
    try:
        affinity = len(os.sched_getaffinity(0))
    except AttributeError:
        affinity = None
    return dict(cpu_model=model, cores=os.cpu_count(), cores_available=affinity,
                load_average_1_5_15=load, platform=platform.platform(),
                openblas_threads=os.environ.get("OPENBLAS_NUM_THREADS", "unset"),
                omp_threads=os.environ.get("OMP_NUM_THREADS", "unset"),
                versions=library_versions(),
                date=time.strftime("%Y-%m-%dT%H:%M:%S%z"))


def write_machine_info(path) -> None:
    """Write :func:`machine_info` as JSON, atomically."""
    from .io import write_atomic

    write_atomic(path, json.dumps(machine_info(), indent=2) + "\n")


# ===================================================================== β_h routes
def _all_cases(k: int):
    return [c for c in multipliers.CASE_IDS if k >= multipliers.CASES[c][4]]


def _bottom(beta2: np.ndarray, kern: int):
    """(β values of the kernel, first β above it) from ascending β² values."""
    b = np.sqrt(np.clip(np.sort(beta2), 0.0, None))
    return b[:kern], float(b[kern]) if kern < len(b) else np.nan


def _factorize_side(side: SideOperator) -> SideOperator:
    """The Γ-last factorization + Schur complement of an assembled side: the linear
    algebra of :func:`interface.side_operator` without the NGSolve assembly."""
    from .models.schur import factorized_side

    return factorized_side(side.trace, side.free, side.stiffness)


class BetaSetup:
    """Assembled data of one (N, k): sides (assembled; factorized only for reuse by the
    reference computations, never inside a timed route), multiplier spaces per case."""

    def __init__(self, n: int, k: int):
        self.n, self.k = n, k
        m1, m2 = meshes.mesh_pair("structured", n, n)
        self.sides = [side_operator(m, k) for m in (m1, m2)]
        x = meshes.multiplier_breakpoints(m1, m2)
        self.cases = _all_cases(k)
        self.spaces = {c: multipliers.case_space(c, k, x) for c in self.cases}
        self.kernel = {c: multipliers.structural_kernel_dim(c, k, n) for c in self.cases}
        self.ndof = sum(s.ndof for s in self.sides)

    def keys(self):
        return [(c, nm) for c in self.cases for nm in NORMS]

    def pencil_size(self) -> int:
        return self.ndof + max(s.dim for s in self.spaces.values())

    # -- the exact inputs of the limit route, computed once, outside any timing
    def operators(self):
        ops = {}
        for c in self.cases:
            Bs = [coupling_matrix(s.trace, self.spaces[c], self.k) for s in self.sides]
            S = interface_operator(Bs, self.sides)
            for nm in NORMS:
                ops[c, nm] = (S, gram(self.spaces[c], nm)[0])
        return ops

    def full_coupling(self, case: str) -> sp.csr_matrix:
        """B = [−B1, B2] on all free dofs (sparse; Γ dofs last on each side)."""
        blocks = []
        for sign, s in zip((-1.0, 1.0), self.sides):
            Bi = coupling_matrix(s.trace, self.spaces[case], self.k)
            blocks += [sp.csr_matrix((Bi.shape[0], s.ndof - Bi.shape[1])), sp.csr_matrix(sign * Bi)]
        B = sp.hstack(blocks, format="csr")
        B.eliminate_zeros()
        return B


def beta_ours(n: int, k: int):
    """All valid cases × both norms on the structured N×N pair, from one interface operator.

    Returns {(case, norm): (β, β above the kernel)} from :func:`infsup.beta_rows`.
    """
    rows = beta_rows("structured", k, n, n, _all_cases(k), norms=NORMS)
    out = {}
    for r in rows:
        kern = multipliers.structural_kernel_dim(r["case"], k, n)
        # beta_rows reports the first value above its numerical kernel; with the
        # structural kernel found (as it is, see the claims) that is the same value
        nz = r["beta"] if kern == 0 else (r["smallest_nonzero"] if r["kernel_dim"] == kern else np.nan)
        out[r["case"], r["norm"]] = (np.array([r["beta"]] * kern), float(nz))
    return out


def beta_ours_core(setup: BetaSetup):
    """Γ-reduced route given the assembled stiffness: factorization, couplings,
    interface operator, Gram, dense eigh (:func:`infsup.spectrum` without the extras)."""
    sides = [_factorize_side(s) for s in setup.sides]
    out = {}
    for c in setup.cases:
        Bs = [coupling_matrix(s.trace, setup.spaces[c], setup.k) for s in sides]
        S = interface_operator(Bs, sides)
        for nm in NORMS:
            G, _ = gram(setup.spaces[c], nm)
            ev = sla.eigh(S, G, eigvals_only=True, check_finite=False)
            out[c, nm] = _bottom(ev[: setup.kernel[c] + 1], setup.kernel[c])
    return out


def beta_limit(setup: BetaSetup, operators: dict | None = None):
    """The floor: best-order sparse factorization of each side's stiffness + one dense
    generalized eigh of multiplier size per (case, norm) on the precomputed operators."""
    ops = operators if operators is not None else setup.operators()

    def run():
        for s in setup.sides:
            spla.splu(s.stiffness, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options=dict(SymmetricMode=True))
        return {key: sla.eigh(S, G, eigvals_only=True, check_finite=False)[0]
                for key, (S, G) in ops.items()}

    return run


def _pencil_matrices(A, B, G):
    lhs = sp.bmat([[A, B.T], [B, None]]).tocsc()
    rhs = sp.block_diag([A, sp.csr_matrix(G)]).tocsc()
    return lhs, rhs


def _beta2_from_sigma(sigma: np.ndarray) -> np.ndarray:
    """β² = σ(σ − 1) of the pencil eigenvalues σ ≤ 0 (the others are ≥ 1)."""
    low = sigma[sigma < 0.5]
    return np.sort(low * (low - 1.0))


def beta_eigsh(A, B, G, n_kernel: int = 0):
    """Bottom of the full pencil by shift-invert Lanczos around σ = −1e-6.

    Kernel modes sit at σ = 0 and small β at σ ≈ −β²: ask for the kernel and 3 more.
    ``tol=0`` (machine precision). With a kernel next to the shift (R5.2, R5.4) the first
    nonzero β is found to ~1e-8 only (the kernel's huge shift-inverted eigenvalues cost
    ARPACK accuracy); the start vector is fixed, so runs are reproducible.
    Returns (kernel β values, first β above the kernel).
    """
    lhs, rhs = _pencil_matrices(A, B, G)
    m = B.shape[0]
    v0 = np.random.default_rng(0).standard_normal(lhs.shape[0])  # reproducible Lanczos start
    vals = spla.eigsh(lhs, k=min(n_kernel + 3, m), M=rhs, sigma=-1e-6, which="LM",
                      return_eigenvectors=False, v0=v0)
    return _bottom(_beta2_from_sigma(vals), n_kernel)


def beta_dense(A, B, G, n_kernel: int = 0):
    """The same pencil by dense generalized ``eigh`` (small sizes only)."""
    lhs, rhs = _pencil_matrices(A, B, G)
    sigma = sla.eigh(lhs.toarray(), rhs.toarray(), eigvals_only=True, check_finite=False)
    return _bottom(_beta2_from_sigma(sigma), n_kernel)


def beta_pencil_route(setup: BetaSetup, solver):
    """A full-pencil route given the assembled stiffness: couplings, Gram, pencil, solve."""
    A = sp.block_diag([s.stiffness for s in setup.sides]).tocsc()
    out = {}
    for c in setup.cases:
        B = setup.full_coupling(c)
        for nm in NORMS:
            G, _ = gram(setup.spaces[c], nm)
            out[c, nm] = solver(A, B, G, setup.kernel[c])
    return out


def _compare(got: dict, ref: dict):
    """(max |β_nz − β_nz,ref| over the same (case, norm), all kernel values < KERNEL_BETA)."""
    diff = max(abs(got[key][1] - ref[key][1]) for key in ref)
    kernel_ok = all(np.all(np.abs(got[key][0]) < KERNEL_BETA) and len(got[key][0]) == len(ref[key][0])
                    for key in ref)
    return float(diff), bool(kernel_ok)


BETA_INCLUDES = {
    "ours": "mesh+assembly+Γ-last LU+Schur+couplings+interface+Gram+eigh (+β with v1=0)",
    "ours_core": "Γ-last LU+Schur+couplings+interface+Gram+eigh (assembled stiffness given)",
    "limit": "best-order LU of each side + one eigh per (case,norm) (operators, Gram given)",
    "eigsh": "couplings+Gram+pencil+shift-invert eigsh per (case,norm) (assembled stiffness given)",
    "dense": "couplings+Gram+pencil+dense eigh per (case,norm) (assembled stiffness given)",
}


def bench_beta(ns, ks, repeats: int = 3, dense_max_size: int = 2500, eigsh_max_n: int | None = None,
               slow_repeats_above_n: int = 32, budget: float = 300.0):
    """β_h routes on the structured N×N pairs, every valid case × both norms.

    Parameters
    ----------
    ns, ks : mesh sizes N and degrees k.
    repeats : repetitions per route (median, min, max reported; interleaved).
    dense_max_size : the dense route runs while the pencil has at most this many rows.
    eigsh_max_n : the eigsh route runs for N ≤ this (None: always).
    slow_repeats_above_n : eigsh and dense run once for N above this.
    budget : a route is not repeated once its accumulated time exceeds this (seconds).

    Returns
    -------
    list of dict with the columns :data:`BETA_COLUMNS` (one row per route, k, N).
    """
    rows = []
    for k in ks:
        for n in ns:
            _log(f"beta k={k} N={n}: setup")
            setup = BetaSetup(n, k)
            ops = setup.operators()
            routes = {"ours": lambda: beta_ours(n, k),
                      "ours_core": lambda: beta_ours_core(setup),
                      "limit": beta_limit(setup, ops)}
            if eigsh_max_n is None or n <= eigsh_max_n:
                routes["eigsh"] = lambda: beta_pencil_route(setup, beta_eigsh)
            if setup.pencil_size() <= dense_max_size:
                routes["dense"] = lambda: beta_pencil_route(setup, beta_dense)
            slow = {r: 1 for r in ("eigsh", "dense")} if n > slow_repeats_above_n else {}
            _log(f"beta k={k} N={n}: routes {list(routes)}")
            res = run_interleaved(routes, repeats, budget, slow)
            ref, t_ours = res["ours"]
            t_core = res["ours_core"][1]
            med_ours, med_core = float(np.median(t_ours)), float(np.median(t_core))
            for name, (got, times) in res.items():
                if name == "limit":
                    diff, kok = np.nan, np.nan
                else:
                    diff, kok = _compare(got, ref)
                rows.append(_row("beta", name, k, n, times, med_ours, med_core,
                                 max_abs_diff=diff, kernel_ok=kok, n_problems=len(setup.keys()),
                                 ndof=setup.ndof, includes=BETA_INCLUDES[name]))
                _log(f"  {name:10s} {np.median(times):9.4f} s  diff {diff}")
    return rows


# ===================================================================== contact
def _contact_problem(n: int, k: int, case: str = "T3"):
    """Membranes scene on the structured N×N pair: sides, couplings, loads (c = 1), as
    :func:`contact_problem.solve_contact` builds them."""
    from .solvers.contact import load_vectors
    from .study.scenes import membranes

    sc = membranes()
    m1, m2 = meshes.mesh_pair("structured", n, n)
    sides = [side_operator(m, k) for m in (m1, m2)]
    space = multipliers.case_space(case, k, meshes.multiplier_breakpoints(m1, m2))
    Bs = [coupling_matrix(s.trace, space, k) for s in sides]
    return sc, sides, Bs, load_vectors(sides, sc)


def contact_limit(sides, F, c=(1.0, 1.0)):
    """The cost no contact solver avoids: one sparse factorization of each side's stiffness
    in SuperLU's best order (``MMD_AT_PLUS_A``, symmetric mode) and one solve with it."""

    def run():
        for s, Fi, ci in zip(sides, F, c):
            lu = spla.splu(ci * s.stiffness, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options=dict(SymmetricMode=True))
            lu.solve(Fi)

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


def bench_contact(ns, ks, repeats: int = 3, case: str = "T3", peers=("osqp", "clarabel"),
                  peer_options: dict | None = None, tolerances=None, peer_time_limit: float = 600.0,
                  kkt_max_n: int = 64, budget: float = 300.0, tune_budget: float = 1200.0):
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
    from .solvers.pdas import solve_kkt_sparse
    from .solvers.contact import linear_saddle_solve, solve_contact
    from .solvers.reduced_qp import solve_reduced_qp
    from .study.scenes import membranes

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


# ================================================================ speed–accuracy
def pareto_front(times, errors) -> np.ndarray:
    """Boolean mask of the Pareto-optimal points when minimizing both time and error.

    A point is on the front iff no other point is at least as fast and at least as
    accurate and strictly better in one of the two. Points with a non-finite time or
    error are never on the front and dominate nothing; exact duplicates are both kept.
    """
    t = np.asarray(times, dtype=float).reshape(-1)
    e = np.asarray(errors, dtype=float).reshape(-1)
    if t.shape != e.shape:
        raise ValueError(f"times and errors differ in length: {t.shape} vs {e.shape}")
    ok = np.isfinite(t) & np.isfinite(e)
    mask = np.zeros(t.shape, dtype=bool)
    for i in np.flatnonzero(ok):
        dominated = ok & (t <= t[i]) & (e <= e[i]) & ((t < t[i]) | (e < e[i]))
        mask[i] = not dominated.any()
    return mask


def time_contact_solve(case: str, k: int, n: int, repeats: int = 3, scene: str = "manufactured",
                       family: str = "structured", scene_params: dict | None = None, c=(1.0, 1.0)):
    """Median, min, max wall time of :func:`contact_problem.solve_contact` (whole call:
    mesh, assembly, interface operator, PDAS, recovery; no floor timing)."""
    from .solvers.contact import solve_contact
    from .study.scenes import scene as make_scene

    sc = make_scene(scene, c1=c[0], c2=c[1], **(scene_params or {}))
    _, med, lo, hi = timed(lambda: solve_contact(sc, case, k, family, n, n, time_floor=False), repeats)
    return med, lo, hi


def speed_accuracy_table(errors, repeats: int = 3, timing_scene: str = "manufactured",
                         timing_params: dict | None = None, c=(1.0, 1.0)):
    """Speed–accuracy points: the errors of every (scene, case, k, N) with wall times.

    Parameters
    ----------
    errors : pandas.DataFrame
        Contact rows (``infsup-contact contact`` / ``results/tables/contact.csv``) with
        scene, case, k, family, N1, N2, energy_error, lambda_hm12_error; matching meshes
        (N1 = N2) are used.
    repeats : timing repetitions (median reported).
    timing_scene, timing_params : the scene whose solves are timed; the cost of a
        discretization (case, k, family, N) does not depend on the load, so one timing
        serves every scene.

    Returns
    -------
    pandas.DataFrame with scene, case, k, family, N, seconds (median), seconds_min,
    seconds_max, energy_error, lambda_hm12_error, ndof, dim_M, pareto_energy,
    pareto_lambda (Pareto front per scene and family).
    """
    import pandas as pd

    frame = errors[errors.N1 == errors.N2].copy()
    frame["N"] = frame.N1.astype(int)
    keys = sorted({(r.case, int(r.k), r.family, int(r.N)) for r in frame.itertuples()},
                  key=lambda t: (t[2], t[1], t[0], t[3]))
    timing = {}
    for case, k, family, n in keys:
        timing[case, k, family, n] = time_contact_solve(case, k, n, repeats, timing_scene, family,
                                                        timing_params, c)
        _log(f"speed-accuracy {family} {case} k={k} N={n}: {timing[case, k, family, n][0]:.4f} s")
    t = np.array([timing[r.case, int(r.k), r.family, int(r.N)] for r in frame.itertuples()])
    frame["seconds"], frame["seconds_min"], frame["seconds_max"] = t[:, 0], t[:, 1], t[:, 2]
    frame["timing_scene"], frame["repeats"] = timing_scene, repeats
    cols = ["scene", "case", "k", "family", "N", "seconds", "seconds_min", "seconds_max",
            "energy_error", "lambda_hm12_error"]
    cols += [c_ for c_ in ("ndof", "dim_M", "cone", "nonunique", "kernel_dim") if c_ in frame.columns]
    out = frame[cols + ["timing_scene", "repeats"]].reset_index(drop=True)
    out["pareto_energy"] = False
    out["pareto_lambda"] = False
    for _, g in out.groupby(["scene", "family"]):
        out.loc[g.index, "pareto_energy"] = pareto_front(g.seconds, g.energy_error)
        out.loc[g.index, "pareto_lambda"] = pareto_front(g.seconds, g.lambda_hm12_error)
    return pd.DataFrame(out).sort_values(["scene", "family", "k", "case", "N"]).reset_index(drop=True)


def fastest_for_accuracy(table, error: str = "energy_error"):
    """Per scene: the Pareto-front rows (ascending time), i.e. for every accuracy level
    the cheapest discretization reaching it."""
    flag = "pareto_energy" if error == "energy_error" else "pareto_lambda"
    return table[table[flag]].sort_values(["scene", "seconds"])
