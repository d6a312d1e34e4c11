"""The interface operator: X_i = (A_i⁻¹)_ΓΓ, the discrete Steklov–Poincaré inverse.

Because b(v, μ) = ∫_Γ (v2 − v1) μ touches only Γ dofs, B A⁻¹ Bᵀ = Σ_i B_i (A_i⁻¹)_ΓΓ B_iᵀ
(paper, Section 4: the operator behind (4.5)). With the Γ dofs ordered last,
(A⁻¹)_ΓΓ = S⁻¹ for the Schur complement S = A_ΓΓ − A_ΓI A_II⁻¹ A_IΓ, and for a sparse
LU factorization P A Pᵀ = L U whose ordering keeps Γ last, S = L_ΓΓ U_ΓΓ: the Schur
complement is the trailing block of the factors — no solve with many right-hand sides.

SuperLU takes no user ordering beyond a pre-permuted matrix: the interior is ordered by a
graph nested dissection (:mod:`infsup_contact.ordering`), Γ appended, and the permuted
matrix factorized once as given.

A_i = c_i K_i with K_i the Laplace stiffness, so X_i = S_i⁻¹ / c_i: one computation per
(mesh, k) serves every (c1, c2), every multiplier space, both norms and the contact solver.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ngsolve
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .coupling import GammaTrace, gamma_trace
from .ordering import nested_dissection_gamma_last


@dataclass(frozen=True)
class SideOperator:
    """Factorized stiffness of one membrane and its Γ Schur complement (c = 1).

    Attributes
    ----------
    trace : GammaTrace
        Γ dofs and trace elements of V_{h,i}.
    free : ndarray of int
        Free NGSolve dofs (the unknowns of A_i), Γ dofs included.
    stiffness : scipy.sparse.csc_matrix
        K_i restricted to free dofs, in the order of ``free``.
    schur : ndarray
        S_i = Schur complement of K_i onto the Γ dofs (order of ``trace.gamma_dofs``).
    solve : callable
        b ↦ K_i⁻¹ b on free dofs (reuses the factorization).
    """

    trace: GammaTrace
    free: np.ndarray
    stiffness: sp.csc_matrix
    schur: np.ndarray
    solve: object

    @property
    def ndof(self) -> int:
        return len(self.free)

    def steklov_inverse(self, c: float = 1.0) -> np.ndarray:
        """X_i = (A_i⁻¹)_ΓΓ = S_i⁻¹ / c_i, symmetric positive definite."""
        return sla.inv(self.schur, check_finite=False) / c


def displacement_space(mesh, k: int):
    """V_{h,i}: continuous P_k, u_i = 0 on ∂Ω_i∖Γ (eq. (5.1))."""
    return ngsolve.H1(mesh, order=k, dirichlet="dir")


def laplace_stiffness(fes) -> sp.csr_matrix:
    """∫ ∇u·∇v assembled by NGSolve on all dofs (c = 1)."""
    u, v = fes.TnT()
    a = ngsolve.BilinearForm(fes)
    a += ngsolve.grad(u) * ngsolve.grad(v) * ngsolve.dx
    a.Assemble()
    mat = a.mat
    # CSR() returns views into NGSolve's memory, freed with the form: copy them
    data, cols, rows = (np.array(arr, copy=True) for arr in mat.CSR())
    return sp.csr_matrix((data, cols, rows), shape=(mat.height, mat.width))


def _gamma_last_lu(A: sp.csc_matrix, n_gamma: int):
    """LU of A (Γ = the last n_gamma rows/cols) in a fill-reducing order that keeps Γ last.

    SuperLU accepts no user ordering, so A is permuted beforehand to a nested-dissection
    order of the interior with Γ appended (``ordering.nested_dissection_gamma_last``) and
    factorized once as given (``permc_spec="NATURAL"``, symmetric mode, no pivoting: A is
    SPD), which keeps Γ last: S is the trailing block of the factors.
    """
    order = nested_dissection_gamma_last(A, n_gamma)
    lu = spla.splu(A[order][:, order].tocsc(), permc_spec="NATURAL", diag_pivot_thresh=0.0,
                   options=dict(SymmetricMode=True))
    return _Reordered(lu, order)


class _Reordered:
    """An LU of A[order][:, order], solving with A in the original numbering."""

    def __init__(self, lu, order):
        self.lu, self.order = lu, order

    def solve(self, b):
        out = np.empty_like(b)
        out[self.order] = self.lu.solve(b[self.order])
        return out


def schur_from_lu(lu: "_Reordered", n_gamma: int) -> np.ndarray:
    """S = L_ΓΓ U_ΓΓ: the trailing block of the factors when Γ is pivoted last."""
    n = len(lu.order)
    tail = slice(n - n_gamma, n)
    L = lu.lu.L[tail, tail].toarray()
    U = lu.lu.U[tail, tail].toarray()
    S = L @ U
    return 0.5 * (S + S.T)


def side_operator(mesh, k: int) -> SideOperator:
    """Factorize K_i once and extract its Γ Schur complement (c = 1)."""
    fes = displacement_space(mesh, k)
    trace = gamma_trace(fes)
    free_mask = np.array(fes.FreeDofs(), dtype=bool)
    is_gamma = np.zeros(fes.ndof, dtype=bool)
    is_gamma[trace.gamma_dofs] = True
    free = np.concatenate([np.flatnonzero(free_mask & ~is_gamma), trace.gamma_dofs])
    K = laplace_stiffness(fes)[free][:, free].tocsc()
    n, ng = len(free), len(trace.gamma_dofs)
    lu = _gamma_last_lu(K, ng)
    return SideOperator(trace, free, K, schur_from_lu(lu, ng), lu.solve)


def schur_by_solves(side: SideOperator) -> np.ndarray:
    """Reference route: S = K_ΓΓ − K_ΓI K_II⁻¹ K_IΓ by a multi-right-hand-side solve."""
    ng = len(side.trace.gamma_dofs)
    K = side.stiffness
    KII, KIG, KGG = K[:-ng, :-ng].tocsc(), K[:-ng, -ng:].toarray(), K[-ng:, -ng:].toarray()
    return KGG - KIG.T @ spla.splu(KII).solve(KIG)


def interface_operator(couplings, sides, c=(1.0, 1.0)) -> np.ndarray:
    """Σ_i B_i X_i B_iᵀ = B A⁻¹ Bᵀ on the multiplier space (dense, symmetric PSD)."""
    out = 0.0
    for B, side, ci in zip(couplings, sides, c):
        out = out + B @ sla.solve(side.schur, B.T, assume_a="pos") / ci
    return 0.5 * (out + out.T)
