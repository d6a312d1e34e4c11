"""The contact QP from its assembled matrices, solved through the Γ-reduced LCP.

The discrete contact problem (4.1) is the convex QP

    minimize ½ uᵀ A u − Fᵀ u   subject to   B u ≥ 0,

with KKT conditions A u = F + Bᵀ λ, λ ≥ 0, B u ≥ 0, λ∘(B u) = 0 (the convention of
:mod:`infsup_contact.contact.pdas` and :mod:`infsup_contact.bench.peers`). This module takes exactly the
data a general QP solver gets — (A, B, F), nothing about meshes or sides — and uses only one
structural fact: B touches few unknowns (the Γ dofs, read off B's sparsity). With those
unknowns Γ ordered last, one factorization of A gives X = (A⁻¹)_ΓΓ
(:func:`~infsup_contact.la.schur.gamma_factorization`), the LCP g = g0 + K λ with K = B_Γ X B_Γᵀ and
g0 = B A⁻¹ F is solved by :func:`~infsup_contact.contact.pdas.solve_pdas` on the small dense multiplier space, and
u = A⁻¹(F + Bᵀ λ) is recovered with the same factorization.

Compared with :func:`infsup_contact.contact.contact.solve_contact`, which builds the same operators side by
side from the meshes, this is the route timed against the peers in the benchmarks (same
input, same answer).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .kkt import _check_kkt
from .pdas import PdasResult, solve_pdas
from ..la.schur import gamma_factorization

__all__ = ["ReducedQpSolution", "solve_reduced_qp", "touched_columns"]


@dataclass
class ReducedQpSolution:
    """Solution of the contact QP.

    Attributes
    ----------
    u : ndarray (n,)
    lam : ndarray (m,)
        Multipliers, A u = F + Bᵀ λ, λ ≥ 0.
    pdas : PdasResult
        The Γ-reduced LCP solve (iterations, contact set, uniqueness).
    n_gamma : int
        Number of unknowns B touches.
    route : str
        Route of the factorization (:func:`~infsup_contact.la.schur.gamma_factorization`).
    """

    u: np.ndarray
    lam: np.ndarray
    pdas: PdasResult
    n_gamma: int
    route: str

    @property
    def iterations(self) -> int:
        return self.pdas.iterations


def touched_columns(B: sp.csr_matrix) -> np.ndarray:
    """Sorted indices of the columns of B with a stored nonzero (the Γ unknowns)."""
    B = sp.csr_matrix(B)
    return np.unique(B.indices[B.data != 0])


def solve_reduced_qp(A, B, F, *, route: str = "auto", **pdas_options) -> ReducedQpSolution:
    """Solve min ½uᵀAu − Fᵀu s.t. Bu ≥ 0 (A sparse SPD) on the unknowns B touches.

    Parameters
    ----------
    A : (n, n) sparse symmetric positive definite
    B : (m, n) sparse
    F : (n,) array_like
    route : str
        Factorization route of :func:`~infsup_contact.la.schur.gamma_factorization`.
    **pdas_options
        Passed to :func:`~infsup_contact.contact.pdas.solve_pdas` (``max_iter``, ``tol``, ``kernel_rtol``).

    Returns
    -------
    ReducedQpSolution

    Raises
    ------
    InputError
        Inconsistent shapes or bad options.
    PdasDidNotConverge
        As :func:`~infsup_contact.contact.pdas.solve_pdas`.
    """
    A, B, F = _check_kkt(A, B, F)
    gamma = touched_columns(B)
    parts = [_Part(A, B, idx, gamma, route) for idx in _components(A)]
    K = sum(p.K for p in parts)
    g0 = sum(p.gap(F) for p in parts)
    pdas = solve_pdas(0.5 * (K + K.T), g0, **pdas_options)
    u = np.empty(A.shape[0])
    for p in parts:
        u[p.idx] = p.recover(F, pdas.lam)
    return ReducedQpSolution(u, pdas.lam, pdas, len(gamma), "+".join(sorted({p.route for p in parts})))


def _components(A) -> list[np.ndarray]:
    """Unknowns of each connected component of A's graph (two membranes: two blocks),
    so that X = (A⁻¹)_ΓΓ is computed block by block, never its zero off-diagonal blocks."""
    count, label = connected_components(A, directed=False)
    order = np.argsort(label, kind="stable")
    return np.split(order, np.cumsum(np.bincount(label, minlength=count))[:-1])


class _Part:
    """One diagonal block of A: its factorization with its Γ unknowns last, B on them."""

    def __init__(self, A, B, idx, gamma, route):
        on_gamma = np.isin(idx, gamma)
        self.idx = np.concatenate([idx[~on_gamma], idx[on_gamma]])   # Γ last
        self.ng = int(on_gamma.sum())
        fac = gamma_factorization(A[self.idx][:, self.idx], self.ng, route, gamma_dim=None)  # a QP: no Γ told
        self.solve, self.route = fac.solve, fac.route
        self.B = B[:, self.idx[len(self.idx) - self.ng:]].toarray()   # B on Γ of this block
        self.K = self.B @ fac.steklov_times(self.B.T)

    def gap(self, F) -> np.ndarray:
        """This block's share of g0 = B A⁻¹ F."""
        return self.B @ self.solve(F[self.idx])[len(self.idx) - self.ng:]

    def recover(self, F, lam) -> np.ndarray:
        """u on this block: A⁻¹(F + Bᵀλ)."""
        rhs = F[self.idx]
        rhs[len(self.idx) - self.ng:] += self.B.T @ lam
        return self.solve(rhs)
