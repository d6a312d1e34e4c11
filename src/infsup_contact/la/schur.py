"""The Γ Schur complement of one factorized body, for any model (the engine's spine).

Because b(v, μ) touches only Γ dofs, B A⁻¹ Bᵀ = Σ_i B_i (A_i⁻¹)_ΓΓ B_iᵀ (paper, Section 4:
the operator behind (4.5); assembled in :mod:`infsup_contact.solvers.interface_operator`). With the Γ dofs ordered last, (A⁻¹)_ΓΓ = S⁻¹ for the Schur
complement S = A_ΓΓ − A_ΓI A_II⁻¹ A_IΓ, and for a sparse LU factorization P A Pᵀ = L U
whose ordering keeps Γ last, S = L_ΓΓ U_ΓΓ: the Schur complement is the trailing block of
the factors — no solve with many right-hand sides.

SuperLU takes no user ordering beyond a pre-permuted matrix: the interior is ordered by a
graph nested dissection (:mod:`infsup_contact.la.ordering`), Γ appended, and the
permuted matrix factorized once as given.

On small problems the Python-side ordering costs more than it saves, so
:func:`gamma_factorization` switches (``route="auto"``) by the work estimate n · n_Γ: up to
:data:`SOLVES_MAX_WORK` it factorizes with SuperLU's own minimum-degree order and reads
X = (A⁻¹)_ΓΓ off n_Γ solves with unit vectors (the Steklov inverse directly); above it the
nested-dissection route. Both give the same X to round-off (tested); the crossover was
measured on the structured meshes (``results/benchmarks``: at n · n_Γ ≈ 2.5e5 both take
the same time).

A model assembles its stiffness at unit material scale (A_i = c_i K_i), so X_i = S_i⁻¹ / c_i:
one computation per (mesh, k) serves every (c1, c2), every multiplier space, both norms
and the contact solver.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import InputError
from .threaded import symmetric_sandwich
from . import pardiso
from .ordering import nested_dissection_gamma_last


class SteklovProduct:
    """X M for X = S⁻¹ = (A⁻¹)_ΓΓ, for a class with ``schur`` (S) and ``steklov`` (X or None):
    a product where X is known, else a solve with the Cholesky factor of S, computed on
    first use and kept (a β_h sweep asks for X M for every multiplier space on one side)."""

    def steklov_times(self, M: np.ndarray) -> np.ndarray:
        if self.steklov is not None:
            return self.steklov @ M
        return sla.cho_solve(self._schur_cholesky, M, check_finite=False)

    @cached_property
    def _schur_cholesky(self):
        return sla.cho_factor(self.schur, check_finite=False)

    def steklov_sandwich(self, B: sp.csr_matrix) -> np.ndarray:
        """B X Bᵀ for a sparse B (dim M × n_Γ): two sparse-times-dense products with the explicit
        X = S⁻¹ (:attr:`_steklov_explicit`, made once per side), nnz(B) · n_Γ multiply-adds each,
        where B X Bᵀ by :meth:`steklov_times` costs 2 n_Γ² dim M (the triangular solves) per space."""
        return symmetric_sandwich(B, self._steklov_explicit).T  # bit for bit (B (B X)ᵀ)ᵀ

    @cached_property
    def _steklov_explicit(self) -> np.ndarray:
        """X = S⁻¹: ``steklov`` where known, else from the Cholesky factor of S by LAPACK potri
        (n_Γ³/3 multiply-adds once, the cost of n_Γ/6 right-hand sides of :meth:`steklov_times`;
        n_Γ² doubles kept on the side: 126 MB at n_Γ = 3,969), both triangles filled."""
        if self.steklov is not None:
            return self.steklov
        c, lower = self._schur_cholesky
        X, info = sla.lapack.dpotri(c, lower=lower)
        if info != 0:
            raise np.linalg.LinAlgError(f"potri failed (info = {info}) on the Schur complement")
        X = np.tril(X) if lower else np.triu(X)
        X += (np.tril(X, -1) if lower else np.triu(X, 1)).T
        return X




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


SOLVES_MAX_WORK = 2.0e5
"""Largest n · n_Γ for which :func:`gamma_factorization` takes the ``"solves"`` route."""

GAMMA_ROUTES = ("auto", "solves", "nested", "pardiso")

GAMMA_DIMS = (1, 2, None)
"""What a caller says of Γ's dimension: a curve, a face, or not told (a foreign system's unknowns)."""


class _LazyPardisoSolve:
    """b ↦ A⁻¹ b with a PARDISO factorization made on the first call: the ``"pardiso"``
    route's Schur complement discards its interior factor unless asked to keep it
    (``keep_factor``), and a β_h sweep never solves."""

    def __init__(self, A):
        self.A, self.factor = A, None

    def __call__(self, b):
        if self.factor is None:
            self.factor = pardiso.Factor(self.A)
        return self.factor.solve(b)


@dataclass(frozen=True)
class GammaFactorization(SteklovProduct):
    """One factorization of A (Γ = its last n_Γ unknowns) and what Γ needs from it.

    Attributes
    ----------
    solve : callable
        b ↦ A⁻¹ b.
    schur : ndarray
        S = A_ΓΓ − A_ΓI A_II⁻¹ A_IΓ.
    steklov : ndarray or None
        X = S⁻¹ = (A⁻¹)_ΓΓ where the route computed it directly (``"solves"``).
    route : str
        ``"solves"`` or ``"nested"``.
    """

    solve: object
    schur: np.ndarray
    steklov: np.ndarray | None
    route: str



def gamma_factorization(A, n_gamma: int, route: str = "auto", *, gamma_dim: int | None,
                        keep_factor: bool = False) -> GammaFactorization:
    """Factorize the SPD matrix A once and get its Γ Schur complement (Γ = last n_gamma).

    ``gamma_dim``: the dimension of the Γ the last n_gamma unknowns live on, from the caller's Γ
    (``trace.gamma.dim`` of a side; 1 a curve, 2 a face), or None where the caller is not told
    one (a foreign system's or a general QP's unknowns that B touches): no default, so that no
    caller's Γ is taken for the segment. It only steers ``"auto"``.

    ``route``:

    ``"nested"``
        Γ-last nested-dissection order, one LU, S = L_ΓΓ U_ΓΓ (:func:`schur_from_lu`).
    ``"solves"``
        SuperLU's minimum-degree order (``MMD_AT_PLUS_A``, symmetric mode), then
        X = (A⁻¹)_ΓΓ from n_Γ solves with unit vectors and S = X⁻¹.
    ``"pardiso"``
        MKL PARDISO's partial factorization returns S directly (:mod:`.pardiso`). With
        ``keep_factor`` it keeps the interior factor and solves with it and a Cholesky factor of
        S (:class:`~.pardiso.SchurFactor`, ``iparm[35] = 2``: one factorization for S and the
        solves of a contact scene); without, the factor is freed at once (a β_h sweep never
        solves, and the memory of the large runs is that of S alone) and a solve factorizes A
        once more, on first use.
    ``"auto"``
        ``"solves"`` while n · n_Γ ≤ :data:`SOLVES_MAX_WORK`; above it ``"pardiso"`` on a face
        (``gamma_dim`` = 2) where MKL loads, else (a curve, or Γ not told) ``"nested"``. Measured on the structured
        meshes, one body, k = 2: on a face with n_Γ = 529 (N = 12) PARDISO is about 3× faster
        than nested and 10× faster than solves; on the segment both factorizations take the
        same time at N = 128, so the segment keeps SuperLU and its results bit for bit.
    """
    if route not in GAMMA_ROUTES:
        raise InputError("route", ", ".join(GAMMA_ROUTES), got=route)
    if gamma_dim not in GAMMA_DIMS:
        raise InputError("gamma_dim", "1, 2 or None (Γ not told)", got=gamma_dim)
    A = sp.csc_matrix(A)
    n = A.shape[0]
    if route == "auto":
        route = ("solves" if n * n_gamma <= SOLVES_MAX_WORK else
                 "pardiso" if gamma_dim == 2 and pardiso.available() else "nested")
    if route == "pardiso" and keep_factor:
        factor = pardiso.SchurFactor(A, n_gamma)
        return GammaFactorization(factor.solve, factor.schur, None, route)
    if route == "pardiso":
        return GammaFactorization(_LazyPardisoSolve(A), pardiso.gamma_schur(A, n_gamma), None, route)
    if route == "nested":
        lu = _gamma_last_lu(A, n_gamma)
        return GammaFactorization(lu.solve, schur_from_lu(lu, n_gamma), None, route)
    lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options=dict(SymmetricMode=True))
    unit = np.zeros((n, n_gamma))
    unit[np.arange(n - n_gamma, n), np.arange(n_gamma)] = 1.0
    X = lu.solve(unit)[n - n_gamma:]
    X = 0.5 * (X + X.T)
    S = sla.inv(X, check_finite=False) if n_gamma else np.zeros((0, 0))
    return GammaFactorization(lu.solve, 0.5 * (S + S.T), X, route)


def schur_from_lu(lu: "_Reordered", n_gamma: int) -> np.ndarray:
    """S = L_ΓΓ U_ΓΓ: the trailing block of the factors when Γ is pivoted last."""
    n = len(lu.order)
    tail = slice(n - n_gamma, n)
    L = lu.lu.L[tail, tail].toarray()
    U = lu.lu.U[tail, tail].toarray()
    S = L @ U
    return 0.5 * (S + S.T)
