"""MKL PARDISO's partial factorization: the Γ Schur complement without a solve per Γ dof.

For an SPD matrix A whose last n_Γ unknowns are Γ, PARDISO eliminates the interior and
returns S = A_ΓΓ − A_ΓI A_II⁻¹ A_IΓ as a dense matrix (``iparm[35]``, the Schur rows marked
in ``perm``) after one supernodal, BLAS-3 factorization of A_II in its own nested-dissection
order (METIS). It is the Γ-last Schur complement of :mod:`infsup_contact.la.schur`
computed by a sparse direct solver built for it: on a 3D body (Q2 hexahedra, 254,016 dofs,
n_Γ = 3,969) it fits in a few GB, where SuperLU with the Γ-last nested dissection needs
tens of GB (``results/benchmarks/face.csv``, ``bench --what face``). :func:`gamma_schur` frees the interior factor
at once (``iparm[35] = 1``: a β_h sweep never solves); :class:`SchurFactor` keeps it
(``iparm[35] = 2``) and solves A x = b with it and S, so a contact scene factorizes each body
once (face patch, membranes3d, k = 2, one body N = 20: the first solve an order of magnitude faster).

The library is Intel oneMKL from the ``mkl`` wheel (``environment.lock``), called through
ctypes with the documented C interface ``pardiso(pt, maxfct, mnum, mtype, phase, n, a, ia,
ja, perm, nrhs, iparm, msglvl, b, x, error)`` (oneMKL Developer Reference, "pardiso" and
"pardiso iparm Parameter"). :func:`available` says whether it loads; the Schur routes fall
back to SuperLU when it does not. Threads: MKL_NUM_THREADS, else OPENBLAS_NUM_THREADS, else 1
(an oversubscribed 2-core machine loses more than it gains).
"""
from __future__ import annotations

import ctypes
from functools import lru_cache

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .mkl import mkl_rt

_P = ctypes.POINTER
_I32 = ctypes.c_int32
MTYPE_SPD = 2
"""PARDISO's matrix type of a real symmetric positive definite matrix (upper triangle given)."""
MTYPE_SYMMETRIC_INDEFINITE = -2
"""PARDISO's matrix type of a real symmetric indefinite matrix (Bunch–Kaufman LDLᵀ, :func:`inertia`)."""


@lru_cache(maxsize=1)
def _library():
    """The loaded ``mkl_rt`` (:func:`~infsup_contact.la.mkl.mkl_rt`) with pardiso's signature, or None."""
    lib = mkl_rt()
    if lib is not None:
        lib.pardiso.restype = None
        lib.pardiso.argtypes = [_P(ctypes.c_int64), _P(_I32), _P(_I32), _P(_I32), _P(_I32), _P(_I32),
                                ctypes.c_void_p, _P(_I32), _P(_I32), _P(_I32), _P(_I32), _P(_I32),
                                _P(_I32), ctypes.c_void_p, ctypes.c_void_p, _P(_I32)]
    return lib


def available() -> bool:
    """Whether MKL PARDISO could be loaded."""
    return _library() is not None


MIN_INTERIOR = 8
"""Interiors with fewer dofs are eliminated densely by :func:`gamma_schur` (module text)."""


_FLOPS = {"on": False, "mflop": 0.0, "factorizations": 0}


def count_flops(on: bool = True) -> None:
    """Start (or stop) counting the factorizations' flops, from zero: PARDISO reports the MFLOP
    its analysis plans for the numerical factorization (``iparm[18] < 0`` on entry, read after
    phase 1), summed over the factorizations until :func:`counted_flops`. Off by default (the
    count is a measurement's, not a result's)."""
    _FLOPS.update(on=bool(on), mflop=0.0, factorizations=0)


def counted_flops() -> tuple[float, int]:
    """(GFLOP, factorizations) counted since :func:`count_flops`."""
    return _FLOPS["mflop"] / 1e3, _FLOPS["factorizations"]


class PardisoError(RuntimeError):
    """PARDISO returned a nonzero error code (oneMKL: -4 zero pivot, i.e. A is not SPD)."""


def _upper_csr(A) -> sp.csr_matrix:
    """The upper triangle of A in CSR with 32-bit indices, sorted: PARDISO's input for SPD."""
    U = sp.triu(sp.csr_matrix(A), format="csr")
    U.sort_indices()
    return sp.csr_matrix((np.ascontiguousarray(U.data, dtype=np.float64),
                          U.indices.astype(np.int32), U.indptr.astype(np.int32)), shape=U.shape)


class _Handle:
    """One PARDISO instance (its internal ``pt``) on the upper triangle of a symmetric matrix:
    SPD (``mtype`` :data:`MTYPE_SPD`, Cholesky) or indefinite (:data:`MTYPE_SYMMETRIC_INDEFINITE`)."""

    def __init__(self, A, perm=None, schur: int = 0, mtype: int = MTYPE_SPD):
        self.mtype = mtype
        self.lib = _library()
        if self.lib is None:
            raise PardisoError("MKL PARDISO is not available (the mkl wheel is not installed)")
        self.U = _upper_csr(A)
        self.n = self.U.shape[0]
        self.pt = np.zeros(64, dtype=np.int64)
        self.iparm = np.zeros(64, dtype=np.int32)
        self.iparm[0] = 1    # the parameters below, not the defaults
        self.iparm[1] = 2    # METIS nested dissection
        self.iparm[9] = 8    # pivot perturbation 1e-8 (not used for SPD: no pivoting)
        self.iparm[34] = 1   # zero-based ia, ja
        self.iparm[35] = schur
        self.iparm[18] = -1 if _FLOPS["on"] else 0   # report the factorization's MFLOP (count_flops)
        self.perm = np.zeros(self.n, dtype=np.int32) if perm is None else perm
        self.alive = False

    def call(self, phase: int, b=None, x=None, nrhs: int = 1) -> None:
        err = _I32(0)
        # phases that take no right-hand side may still use b and x as work arrays of n · nrhs
        b = np.zeros(self.n * nrhs) if b is None else b
        x = np.zeros(self.n * nrhs) if x is None else x
        self.lib.pardiso(self.pt.ctypes.data_as(_P(ctypes.c_int64)), ctypes.byref(_I32(1)),
                         ctypes.byref(_I32(1)), ctypes.byref(_I32(self.mtype)), ctypes.byref(_I32(phase)),
                         ctypes.byref(_I32(self.n)), self.U.data.ctypes.data,
                         self.U.indptr.ctypes.data_as(_P(_I32)), self.U.indices.ctypes.data_as(_P(_I32)),
                         self.perm.ctypes.data_as(_P(_I32)), ctypes.byref(_I32(nrhs)),
                         self.iparm.ctypes.data_as(_P(_I32)), ctypes.byref(_I32(0)),
                         b.ctypes.data, x.ctypes.data, ctypes.byref(err))
        self.alive = self.alive or phase > 0
        if err.value:
            raise PardisoError(f"PARDISO phase {phase} returned error {err.value}")
        if _FLOPS["on"] and phase in (11, 12, 13):
            _FLOPS["mflop"] += float(self.iparm[18])
            _FLOPS["factorizations"] += 1

    def release(self) -> None:
        if self.alive:
            self.call(-1)
            self.alive = False

    def __del__(self):
        try:
            self.release()
        except Exception:  # interpreter shutdown: the library may be gone already
            pass


def _dense_schur(A, n_gamma: int) -> tuple[np.ndarray, np.ndarray]:
    """(A dense, S) by dense elimination: the route of interiors below :data:`MIN_INTERIOR`.

    MKL 2026.2 reads past its arrays (valgrind: mkl_pds_lp64_permutetips) for a 2 × 2 matrix
    with one Schur row, and crashed a test run that way; an interior this small is eliminated
    densely instead (the same S, exactly as cheap)."""
    n = A.shape[0]
    D = A.toarray() if sp.issparse(A) else np.asarray(A, dtype=float)
    I, G = slice(0, n - n_gamma), slice(n - n_gamma, n)
    S = D[G, G] - D[G, I] @ np.linalg.solve(D[I, I], D[I, G]) if n > n_gamma else D[G, G].copy()
    return D, 0.5 * (S + S.T)


def _partial_factorization(A, n_gamma: int, schur: int) -> tuple["_Handle", np.ndarray]:
    """One PARDISO analysis and partial factorization (phase 12) of A with the last ``n_gamma``
    rows marked in ``perm`` and ``iparm[35] = schur``: the handle and S (symmetrized)."""
    n = A.shape[0]
    perm = np.zeros(n, dtype=np.int32)
    perm[n - n_gamma:] = 1
    handle = _Handle(A, perm, schur=schur)
    S = np.zeros(max(n_gamma * n_gamma, n))  # the Schur block, in PARDISO's x (at least n long)
    try:
        handle.call(12, x=S)
    except BaseException:
        handle.release()
        raise
    S = S[:n_gamma * n_gamma].reshape(n_gamma, n_gamma)
    return handle, 0.5 * (S + S.T)


def gamma_schur(A, n_gamma: int) -> np.ndarray:
    """S = A_ΓΓ − A_ΓI A_II⁻¹ A_IΓ (Γ = the last ``n_gamma`` unknowns of the SPD A), dense.

    One PARDISO analysis and partial factorization (phase 12) with the Γ rows marked in
    ``perm`` and ``iparm[35] = 1``; the interior factor is discarded (:class:`SchurFactor`
    keeps it, for solves).
    """
    n = A.shape[0]
    if n_gamma == 0:
        return np.zeros((0, 0))
    if n - n_gamma < MIN_INTERIOR:
        return _dense_schur(A, n_gamma)[1]
    handle, S = _partial_factorization(A, n_gamma, schur=1)
    handle.release()
    return S


class SchurFactor:
    """S and solves A x = b from one partial factorization that keeps the interior factor.

    With ``iparm[35] = 2`` PARDISO computes S (the same matrix as :func:`gamma_schur`) and keeps
    the Cholesky factor of A_II (oneMKL Developer Reference, "pardiso iparm Parameter":
    Schur complement with partial solving). Writing A = [L_II 0; L_ΓI I] [I 0; 0 S] [L_IIᵀ L_ΓIᵀ;
    0 I], a solve is the forward substitution (phase 331: y_I = L_II⁻¹ b_I, y_Γ = b_Γ − L_ΓI y_I),
    the Γ block S x_Γ = y_Γ solved here with a Cholesky factor of S (LAPACK, made on the first
    solve), and the backward substitution (phase 333: x_I = L_II⁻ᵀ (y_I − L_ΓIᵀ x_Γ)). For an SPD
    matrix (mtype 2, L Lᵀ) there is no diagonal phase 332 to apply. Interiors below
    :data:`MIN_INTERIOR` are eliminated densely (:func:`gamma_schur`) and solved by a dense
    Cholesky factor of A.

    Attributes
    ----------
    schur : ndarray (n_gamma, n_gamma)
        S = A_ΓΓ − A_ΓI A_II⁻¹ A_IΓ, symmetrized.
    """

    def __init__(self, A, n_gamma: int):
        self.n, self.n_gamma = A.shape[0], int(n_gamma)
        self.handle, self._dense, self._full, self._cho = None, None, None, None
        if self.n - self.n_gamma < MIN_INTERIOR:
            D, self.schur = _dense_schur(A, self.n_gamma)
            self._dense = sla.cho_factor(D, check_finite=False)
        elif self.n_gamma == 0:  # no Γ: a plain factorization
            self.schur, self._full = np.zeros((0, 0)), Factor(A)
        else:
            self.handle, self.schur = _partial_factorization(A, self.n_gamma, schur=2)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """A⁻¹ b for a vector or a matrix of right-hand sides (columns)."""
        b = np.asarray(b, dtype=np.float64)
        if self._dense is not None:
            return sla.cho_solve(self._dense, b, check_finite=False)
        if self._full is not None:
            return self._full.solve(b)
        if self._cho is None:
            self._cho = sla.cho_factor(self.schur, check_finite=False)
        rhs = np.array(b.reshape(self.n, -1), dtype=np.float64, order="F")
        nrhs, gamma = rhs.shape[1], slice(self.n - self.n_gamma, self.n)
        y = np.zeros_like(rhs, order="F")
        self.handle.call(331, b=rhs, x=y, nrhs=nrhs)
        y[gamma] = sla.cho_solve(self._cho, y[gamma], check_finite=False)
        x = np.zeros_like(rhs, order="F")
        self.handle.call(333, b=y, x=x, nrhs=nrhs)
        return x.reshape(b.shape)

    def release(self) -> None:
        """Free PARDISO's memory (also done when the object is collected)."""
        for h in (self.handle, self._full and self._full.handle):
            if h is not None:
                h.release()


class Factor:
    """A PARDISO Cholesky factorization of an SPD matrix, for repeated solves A⁻¹ b."""

    def __init__(self, A):
        self.handle = _Handle(A)
        self.handle.call(12)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """A⁻¹ b for a vector or a matrix of right-hand sides (columns)."""
        b = np.asarray(b, dtype=np.float64)
        cols = b.reshape(self.handle.n, -1)
        rhs = np.asfortranarray(cols)
        x = np.zeros_like(rhs, order="F")
        self.handle.call(33, b=rhs, x=x, nrhs=rhs.shape[1])
        return x.reshape(b.shape)


def inertia(A) -> tuple[int, int, int]:
    """(positive, negative, perturbed) pivots of the LDLᵀ of a symmetric A (PARDISO, matrix type
    −2: Bunch–Kaufman pivoting in METIS order, pivots below 1e-8 ‖A‖ perturbed, ``iparm[9]``).
    By Sylvester's law the first two are A's inertia where nothing was perturbed; a perturbed pivot
    marks a (numerically) singular A. One factorization, released at once."""
    handle = _Handle(A, mtype=MTYPE_SYMMETRIC_INDEFINITE)
    handle.iparm[20] = 1   # Bunch–Kaufman pivoting (1x1 and 2x2)
    try:
        handle.call(12)
        return int(handle.iparm[21]), int(handle.iparm[22]), int(handle.iparm[13])
    finally:
        handle.release()
