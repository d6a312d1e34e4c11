"""The membranes' full-pencil β_h routes, timed beside ours (:mod:`.beta_bench`).

Given the assembled stiffness A of both sides, per (case, norm) the couplings B = [−B1, B2], the
Gram matrix G and the saddle-point pencil [[A, Bᵀ], [B, 0]] x = σ [[A, 0], [0, G]] x, whose roots
σ ≤ 0 give β² = σ(σ − 1) (the others are ≥ 1):

``eigsh``
    Its bottom by sparse shift-invert Lanczos (``scipy.sparse.linalg.eigsh``, σ = −1e-6,
    ``tol=0``), as automated inf-sup testers do (ASCoT); only for N ≤ ``eigsh_max_n``.
``dense``
    The same pencil by dense ``scipy.linalg.eigh``, only while its size ≤ ``dense_max_size``.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..discretization.gamma.coupling import coupling_matrix
from ..discretization.spaces import registry

INCLUDES = {
    "eigsh": "couplings+Gram+pencil+shift-invert eigsh per (case,norm) (assembled stiffness given)",
    "dense": "couplings+Gram+pencil+dense eigh per (case,norm) (assembled stiffness given)",
}


def full_coupling(setup, case: str) -> sp.csr_matrix:
    """B = [−B1, B2] on all free dofs (sparse; Γ dofs last on each side)."""
    blocks = []
    for sign, s in zip((-1.0, 1.0), setup.sides):
        Bi = coupling_matrix(s.trace, setup.spaces[case], setup.k)
        blocks += [sp.csr_matrix((Bi.shape[0], s.ndof - Bi.shape[1])), sp.csr_matrix(sign * Bi)]
    B = sp.hstack(blocks, format="csr")
    B.eliminate_zeros()
    return B


def _pencil_matrices(A, B, G):
    lhs = sp.bmat([[A, B.T], [B, None]]).tocsc()
    rhs = sp.block_diag([A, sp.csr_matrix(G)]).tocsc()
    return lhs, rhs


def _beta2_from_sigma(sigma: np.ndarray) -> np.ndarray:
    """β² = σ(σ − 1) of the pencil eigenvalues σ ≤ 0 (the others are ≥ 1), ascending."""
    low = sigma[sigma < 0.5]
    return np.sort(low * (low - 1.0))


def beta_eigsh(A, B, G, n_kernel: int = 0) -> np.ndarray:
    """The bottom β² of the full pencil by shift-invert Lanczos around σ = −1e-6.

    Kernel modes sit at σ = 0 and small β at σ ≈ −β²: ask for the kernel and 3 more.
    ``tol=0`` (machine precision). With a kernel next to the shift (R5.2, R5.4) the first
    nonzero β is found to ~1e-8 only (the kernel's huge shift-inverted eigenvalues cost
    ARPACK accuracy); the start vector is fixed, so runs are reproducible.
    """
    lhs, rhs = _pencil_matrices(A, B, G)
    v0 = np.random.default_rng(0).standard_normal(lhs.shape[0])  # reproducible Lanczos start
    vals = spla.eigsh(lhs, k=min(n_kernel + 3, B.shape[0]), M=rhs, sigma=-1e-6, which="LM",
                      return_eigenvectors=False, v0=v0)
    return _beta2_from_sigma(vals)


def beta_dense(A, B, G, n_kernel: int = 0) -> np.ndarray:
    """Every β² of the same pencil by dense generalized ``eigh`` (small sizes only)."""
    lhs, rhs = _pencil_matrices(A, B, G)
    return _beta2_from_sigma(sla.eigh(lhs.toarray(), rhs.toarray(), eigvals_only=True, check_finite=False))


def pencil_route(setup, solver) -> dict:
    """{(case, norm): β² values} of a full-pencil route given the assembled stiffness."""
    A = sp.block_diag([s.stiffness for s in setup.sides]).tocsc()
    out = {}
    for c in setup.cases:
        B = full_coupling(setup, c)
        kern = registry.structural_kernel_dim(c, setup.k, setup.n)
        for nm in setup.bench.norms:
            out[c, nm] = solver(A, B, setup.gamma.gram(setup.spaces[c], nm)[0], kern)
    return out


def pencil_routes(setup, dense_max_size: int = 2500, eigsh_max_n: int | None = None) -> dict:
    """{route: callable}: ``eigsh`` for N ≤ ``eigsh_max_n`` (None: always), ``dense`` while the
    pencil has at most ``dense_max_size`` rows."""
    routes = {}
    if eigsh_max_n is None or setup.n <= eigsh_max_n:
        routes["eigsh"] = lambda: pencil_route(setup, beta_eigsh)
    if setup.ndof + max(s.dim for s in setup.spaces.values()) <= dense_max_size:
        routes["dense"] = lambda: pencil_route(setup, beta_dense)
    return routes
