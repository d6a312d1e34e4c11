"""β_h (:func:`bench_beta`): the problem is β_h of **every valid case × both norms (H, L2)**
on the structured N × N pair; every route answers all of them. What each time includes
(also in the ``includes`` column):

``ours``
    End to end, as ``infsup-contact beta`` runs it (:func:`infsup_contact.solvers.infsup.beta_rows`): meshes,
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
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..discretization.segment import meshes
from ..discretization.spaces import registry
from ..discretization.gamma.coupling import coupling_matrix
from ..models.membranes import side_operator
from ..models.contract import SideOperator
from ..solvers.interface_operator import interface_operator
from ..solvers.infsup import beta_rows
from .harness import ROUTE_BUDGET, _log, _row, run_interleaved


NORMS = ("H", "L2")
KERNEL_BETA = 1e-6
"""An inf-sup value below this counts as a (structural) kernel value in ``kernel_ok``."""
BETA_COLUMNS = ("what", "route", "k", "N", "seconds_median", "seconds_min", "seconds_max",
                "ratio_to_ours", "ratio_to_ours_core", "max_abs_diff", "kernel_ok", "repeats",
                "n_problems", "ndof", "includes")


def _all_cases(k: int):
    return registry.ids_valid_for(k, registry.PAPER_CASES)


def _bottom(beta2: np.ndarray, kern: int):
    """(β values of the kernel, first β above it) from ascending β² values."""
    b = np.sqrt(np.clip(np.sort(beta2), 0.0, None))
    return b[:kern], float(b[kern]) if kern < len(b) else np.nan


def _factorize_side(side: SideOperator) -> SideOperator:
    """The Γ-last factorization + Schur complement of an assembled side: the linear
    algebra of :func:`~infsup_contact.models.membranes.side_operator` without the NGSolve assembly."""
    from ..models.contract import factorized_side

    return factorized_side(side.trace, side.free, side.stiffness)


class BetaSetup:
    """Assembled data of one (N, k): sides (assembled; factorized only for reuse by the
    reference computations, never inside a timed route), multiplier spaces per case."""

    def __init__(self, n: int, k: int):
        self.n, self.k = n, k
        m1, m2 = meshes.mesh_pair("structured", n, n)
        self.sides = [side_operator(m, k) for m in (m1, m2)]
        self.gamma = self.sides[0].trace.gamma
        g_h = self.gamma.multiplier_partition(*(s.trace.partition for s in self.sides))
        self.cases = _all_cases(k)
        self.spaces = {c: registry.case_space(c, k, g_h, self.gamma) for c in self.cases}
        self.kernel = {c: registry.structural_kernel_dim(c, k, n) for c in self.cases}
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
                ops[c, nm] = (S, self.gamma.gram(self.spaces[c], nm)[0])
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

    Returns {(case, norm): (β, β above the kernel)} from :func:`infsup_contact.solvers.infsup.beta_rows`.
    """
    rows = beta_rows("structured", k, n, n, _all_cases(k), norms=NORMS)
    out = {}
    for r in rows:
        kern = registry.structural_kernel_dim(r["case"], k, n)
        # beta_rows reports the first value above its numerical kernel; with the
        # structural kernel found (as it is, see the claims) that is the same value
        nz = r["beta"] if kern == 0 else (r["smallest_nonzero"] if r["kernel_dim"] == kern else np.nan)
        out[r["case"], r["norm"]] = (np.array([r["beta"]] * kern), float(nz))
    return out


def beta_ours_core(setup: BetaSetup):
    """Γ-reduced route given the assembled stiffness: factorization, couplings,
    interface operator, Gram, dense eigh (:func:`~infsup_contact.solvers.spectra.spectrum` without the extras)."""
    sides = [_factorize_side(s) for s in setup.sides]
    out = {}
    for c in setup.cases:
        Bs = [coupling_matrix(s.trace, setup.spaces[c], setup.k) for s in sides]
        S = interface_operator(Bs, sides)
        for nm in NORMS:
            G, _ = setup.gamma.gram(setup.spaces[c], nm)
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
            G, _ = setup.gamma.gram(setup.spaces[c], nm)
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
               budget: float = ROUTE_BUDGET):
    """β_h routes on the structured N×N pairs, every valid case × both norms.

    Parameters
    ----------
    ns, ks : mesh sizes N and degrees k.
    repeats : repetitions per route (median, min, max reported; interleaved).
    dense_max_size : the dense route runs while the pencil has at most this many rows.
    eigsh_max_n : the eigsh route runs for N ≤ this (None: always).
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
            _log(f"beta k={k} N={n}: routes {list(routes)}")
            res = run_interleaved(routes, repeats, budget)
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
