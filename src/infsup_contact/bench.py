"""Speed measured as ratios in one run on one machine (never in unit tests).

β_h routes, same problem and same answer:

``ours``
    Γ-reduced: one factorization per side with Γ last, Schur complement from the
    factors, dense ``eigh`` on the multiplier space (:mod:`infsup_contact.infsup`).
``limit``
    the floor of any route: one sparse factorization of A (both sides) + one dense
    ``eigh`` of the multiplier size.
``eigsh``
    the full saddle-point pencil [[A, Bᵀ], [B, 0]] x = σ [[A, 0], [0, G]] x by sparse
    shift-invert Lanczos (``scipy.sparse.linalg.eigsh`` with ``sigma``), as automated
    inf-sup testers do (ASCoT).
``dense``
    the same pencil by dense ``scipy.linalg.eigh`` (small N only).
"""
from __future__ import annotations

import os
import platform
import time

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from . import meshes, multipliers
from .coupling import coupling_matrix
from .infsup import beta_rows, saddle_point_beta, spectrum
from .interface import interface_operator, side_operator
from .norms import gram


def timed(fn, repeats: int):
    """Run ``fn`` ``repeats`` times; return (last result, median, min, max seconds)."""
    times, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return out, float(np.median(times)), float(np.min(times)), float(np.max(times))


def machine_info() -> dict:
    """CPU model, cores and BLAS thread setting of this run."""
    model = platform.processor()
    try:
        with open("/proc/cpuinfo") as fh:
            model = next((ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")), model)
    except OSError:
        pass
    return dict(cpu_model=model, cores=os.cpu_count(),
                openblas_threads=os.environ.get("OPENBLAS_NUM_THREADS", "unset"))


def _all_cases(k: int):
    return [c for c in multipliers.CASE_IDS if k >= multipliers.CASES[c][4]]


def beta_ours(n: int, k: int):
    """All valid cases × both norms on the structured N×N pair, from one interface operator."""
    return beta_rows("structured", k, n, n, _all_cases(k), norms=("H", "L2"))


def beta_limit(n: int, k: int):
    """One sparse factorization of A (both sides, SuperLU's best ordering) + one dense eigh."""
    sides = [side_operator(m, k) for m in meshes.mesh_pair("structured", n, n)]
    stiff = [s.stiffness for s in sides]
    dim = n * k + 1

    def run():
        for K in stiff:
            spla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options=dict(SymmetricMode=True))
        M = np.random.default_rng(0).standard_normal((dim, dim))
        return sla.eigh(M @ M.T + dim * np.eye(dim), np.eye(dim), eigvals_only=True)

    return run


def _pencil(n: int, k: int, case: str, norm: str):
    """Full sparse A, B (both sides) and G of one case on the structured N×N pair."""
    m1, m2 = meshes.mesh_pair("structured", n, n)
    sides = [side_operator(m, k) for m in (m1, m2)]
    space = multipliers.case_space(case, k, meshes.multiplier_breakpoints(m1, m2))
    cols = []
    for sign, side in zip((-1.0, 1.0), sides):
        ng = len(side.trace.gamma_dofs)
        Bi = sp.lil_matrix((space.dim, side.ndof))
        Bi[:, side.ndof - ng:] = sign * coupling_matrix(side.trace, space, k)
        cols.append(Bi.tocsr())
    A = sp.block_diag([s.stiffness for s in sides]).tocsc()
    G, _ = gram(space, norm)
    return A, sp.hstack(cols).tocsr(), G, sides, space


def beta_eigsh(A, B, G, n_kernel: int = 0) -> float:
    """Smallest β from the full pencil by shift-invert Lanczos around σ slightly below 0."""
    m = B.shape[0]
    lhs = sp.bmat([[A, B.T], [B, None]]).tocsc()
    rhs = sp.block_diag([A, sp.csr_matrix(G)]).tocsc()
    # kernel modes sit at σ = 0 and small β at σ ≈ −β²: ask for a few beyond the kernel
    vals = spla.eigsh(lhs, k=min(n_kernel + 3, m), M=rhs, sigma=-1e-6, which="LM",
                      return_eigenvectors=False)
    low = vals[vals < 0.5]
    return float(np.sqrt(max(np.min(low * (low - 1.0)), 0.0)))


def bench_beta(ns, ks, repeats: int = 3, dense_max_n: int = 8):
    """Rows ``what,route,k,N,seconds_median,seconds_min,seconds_max,ratio_to_ours,max_abs_diff``."""
    rows = []
    for k in ks:
        for n in ns:
            ours_rows, *t_ours = timed(lambda: beta_ours(n, k), repeats)
            _, *t_lim = timed(beta_limit(n, k), repeats)
            ref = {(r["case"], r["norm"]): r["beta"] for r in ours_rows}
            rows.append(_row("beta", "ours", k, n, t_ours, t_ours, 0.0))
            rows.append(_row("beta", "limit", k, n, t_lim, t_ours, np.nan))
            peers = [("eigsh", beta_eigsh)] + ([("dense", saddle_point_beta)] if n <= dense_max_n else [])
            for name, solver in peers:
                def run(solver=solver):
                    out = {}
                    for case in _all_cases(k):
                        kern = multipliers.structural_kernel_dim(case, k, n)
                        for norm in ("H", "L2"):
                            A, B, G, _, _ = _pencil(n, k, case, norm)
                            out[case, norm] = (solver(A, B, G, kern) if name == "eigsh"
                                               else solver(A, B.toarray(), G))
                    return out
                got, *t = timed(run, 1 if n > 32 else repeats)
                diff = max(abs(got[key] - ref[key]) for key in ref)
                rows.append(_row("beta", name, k, n, t, t_ours, diff))
    return rows


def _row(what, route, k, n, t, t_ours, diff):
    return dict(what=what, route=route, k=k, N=n, seconds_median=t[0], seconds_min=t[1],
                seconds_max=t[2], ratio_to_ours=t[0] / t_ours[0], max_abs_diff=diff)


# --- contact -----------------------------------------------------------------------------

def _contact_problem(n: int, k: int, case: str = "T3"):
    """Membranes scene on the structured N×N pair: sides, couplings, loads (c = 1)."""
    from .contact_problem import load_vector
    from .scenes import membranes

    sc = membranes()
    m1, m2 = meshes.mesh_pair("structured", n, n)
    sides = [side_operator(m, k) for m in (m1, m2)]
    space = multipliers.case_space(case, k, meshes.multiplier_breakpoints(m1, m2))
    Bs = [coupling_matrix(s.trace, space, k) for s in sides]
    F = [load_vector(s, f) for s, f in zip(sides, (sc.f1, sc.f2))]
    return sc, sides, Bs, F


def bench_contact(ns, ks, repeats: int = 3, case: str = "T3"):
    """PDAS on the Γ-reduced problem (all of it: factorizations, interface, iterations,
    recovery) against the floor (one sparse saddle-point solve, contact set known) and the
    same PDAS on the full sparse KKT system."""
    from .contact import solve_kkt_sparse
    from .contact_problem import _embed, linear_saddle_time, solve_contact
    from .scenes import membranes

    rows = []
    for k in ks:
        for n in ns:
            sol, *t_ours = timed(lambda: solve_contact(membranes(), case, k, "structured", n, n,
                                                       time_floor=False), repeats)
            _, sides, Bs, F = _contact_problem(n, k, case)
            floor = [linear_saddle_time(sides, Bs, (1.0, 1.0)) for _ in range(repeats)]
            t_floor = (float(np.median(floor)), float(np.min(floor)), float(np.max(floor)))
            A = sp.block_diag([s.stiffness for s in sides]).tocsc()
            B = sp.csr_matrix(np.hstack([-_embed(sides[0], Bs[0]), _embed(sides[1], Bs[1])]))
            Fall = np.concatenate(F)
            (u, lam, its), *t_kkt = timed(lambda: solve_kkt_sparse(A, B, Fall), 1 if n > 64 else repeats)
            r = _row("contact", "ours", k, n, t_ours, t_ours, 0.0)
            r["iterations"] = sol.pdas.iterations
            rows.append(r)
            rows.append(dict(_row("contact", "floor", k, n, t_floor, t_ours, np.nan), iterations=1))
            rows.append(dict(_row("contact", "kkt_sparse", k, n, t_kkt, t_ours,
                                  float(np.abs(lam - sol.lam).max())), iterations=its))
    return rows
