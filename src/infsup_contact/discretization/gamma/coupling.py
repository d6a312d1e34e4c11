"""The coupling matrices B_i of b(v, μ) = ∫_Γ (v2 − v1) μ (paper, eqs. (3.5), (3.11)).

B_i[j, d] = ∫_Γ μ_j φ_d for the multiplier basis μ_j and the Γ dofs φ_d of V_{h,i}; then
b(v, μ) = μᵀ (B_2 v_2 − B_1 v_1). Both factors are polynomial on every interval of the
common refinement of the trace partition and G_h, so the interface's quadrature there
(:meth:`~.gamma.interface.Interface.coupling_quadrature`; Gauss–Legendre with ⌈(k + s + 1)/2⌉ points
per interval on the segment) is exact. Everything that depends on the shape of Γ — the trace,
its basis values, the quadrature — comes from the trace's interface, ``trace.gamma``.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .trace import GammaTrace
from .protocol import MultiplierSpace


def coupling_matrix(trace: GammaTrace, space: MultiplierSpace, k: int, extra_degree: int = 0,
                    sparse: bool = False):
    """B_i[j, d] = ∫_Γ μ_j φ_d, dense, shape (dim M, number of Γ dofs); exact.

    ``extra_degree`` > 0 uses a rule exact for that much higher degree: the same matrix up
    to round-off, which is how the kernel decision measures the round-off of the entries.
    ``sparse``: the same entries, bit for bit, as a CSR matrix (the large route: a face's B at
    dim M ≈ 4,000 is 130 MB dense and 99.8 % zeros)."""
    return coupling_matrices([trace], space, k, extra_degree, sparse)[0]


def coupling_matrices(traces: list, space: MultiplierSpace, k: int, extra_degree: int = 0,
                      sparse: bool = False) -> list:
    """[:func:`coupling_matrix` of each trace], bit for bit, the multiplier's values made once for
    the traces whose coupling rule has the same points and weights (the sides of a matching pair:
    half the values of μ, a third of a face's couplings at k = 2)."""
    rules = [trace.gamma.coupling_points(trace, space, k + space.degree + extra_degree) for trace in traces]
    out = [None] * len(traces)
    for group in _same_rules(rules):
        x, _, w = rules[group[0]]
        # μ and the trace at their own points: the same ones unless Γ couples the sides by projection
        phis = [traces[i].cached_sparse_basis(rules[i][1]) for i in group]  # CSR, once per point set
        acc = [sp.csr_matrix((space.dim, phi.shape[1])) if sparse else np.zeros((space.dim, phi.shape[1]))
               for phi in phis]
        # each point sees (k + 1)^d trace and (s + 1)^d multiplier functions: a sparse product
        # costs O(n_q) where the dense one costs n_q · dim M · n_Γ (a face at N = 32: 1e11 flops)
        for rows in _chunks(len(w), space.dim):
            mu_t = weighted_values(space, x[rows], w[rows]).T
            for j, phi in enumerate(phis):
                acc[j] = _add(acc[j], mu_t @ phi[rows], sparse)
        for i, a in zip(group, acc):
            out[i] = a.tocsr() if sparse else a
    return out


def _add(out, part, sparse: bool):
    """out + part: sparse, 0 + a = a and a + b as the dense route's sums, entry by entry."""
    if sparse:
        return out + part
    part = part.tocoo()
    # = out += part.toarray() bit for bit: the product stores no zeros and out holds no −0.0,
    # so the entries it skips would add +0.0 to them (and a single product, over the points
    # of a chunk in ascending order per entry, is the same whatever built the CSR of μ)
    out[part.row, part.col] += part.data
    return out


def _same_rules(rules: list) -> list:
    """Groups of indices of ``rules`` (x_μ, x_trace, w) with equal x_μ and w, in first-seen order."""
    groups = []
    for i, (x, _, w) in enumerate(rules):
        for g in groups:
            x0, _, w0 = rules[g[0]]
            if x.shape == x0.shape and w.shape == w0.shape and np.array_equal(x, x0) and np.array_equal(w, w0):
                g.append(i)
                break
        else:
            groups.append([i])
    return groups


def weighted_values(space, x: np.ndarray, w: np.ndarray) -> sp.csr_matrix:
    """CSR of μ_j(x_q) w_q, shape (len(x), dim M): exactly ``csr_matrix(space.evaluate(x) * w[:, None])``
    (the same products, sorted indices, no stored zeros), built from the space's nonzero pattern
    (``space.local_values``: each point sees (s + 1)^d basis functions) without the dense
    n_q × dim M array where the space has one, else from :meth:`evaluate`."""
    local = space.local_values(x)
    if local is None:
        return sp.csr_matrix(space.evaluate(x) * w[:, None])
    vals, dofs = local
    data = vals * w[:, None]
    keep = (dofs >= 0) & (data != 0)
    rows = np.broadcast_to(np.arange(len(x))[:, None], dofs.shape)
    mu = sp.coo_matrix((data[keep], (rows[keep], dofs[keep])), shape=(len(x), space.dim)).tocsr()
    mu.sum_duplicates()  # sorts the column indices (there are no duplicates: distinct local dofs)
    return mu


_CHUNK_ENTRIES = 2 ** 24
"""Dense entries of one chunk of multiplier values in :func:`coupling_matrix` (128 MB)."""


def _chunks(n_points: int, dim: int):
    """Slices of the quadrature points, each with at most :data:`_CHUNK_ENTRIES` values."""
    step = max(1, _CHUNK_ENTRIES // max(dim, 1))
    return [slice(i, min(i + step, n_points)) for i in range(0, n_points, step)]


def trace_l2_norms(trace: GammaTrace, k: int) -> np.ndarray:
    """‖φ_d‖_{L²(Γ)} of the Γ-dof basis functions (exact Gauss rule for the degree-2k squares):
    the row scaling of the kernel decision (:func:`infsup_contact.solvers.kernel.scaled_couplings`).
    On an interface with a sparse trace basis (the face) from its nonzeros only: the dense values
    are points × n_Γ (1.6 GB a side at k = 2, N = 48, 3 s to make and square), of which each point
    holds (k + 1)² or fewer; the same sums but for the order of their terms (round-off)."""
    x, w = trace.gamma.quadrature(trace.partition, 2 * k)
    if getattr(trace.gamma, "sparse_trace_basis", None) is not None:
        phi = trace.cached_sparse_basis(x)
        return np.sqrt(np.asarray(phi.multiply(phi).T @ w).ravel())
    return np.sqrt(w @ trace.gamma.trace_basis(trace, x) ** 2)
