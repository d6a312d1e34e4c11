"""Intel oneMKL, loaded once through ctypes: PARDISO (:mod:`infsup_contact.la.pardiso`)
and the pointer-level triangular solve of :func:`trailing_solve`; the code branch MKL runs
(:func:`cbwr_branch`, for the cross-machine checks of :mod:`infsup_contact.study.machines.paths`).

The library is the ``mkl`` wheel's ``mkl_rt`` (``environment.lock``), called with its documented
C interfaces (oneMKL Developer Reference: "pardiso", "cblas_?trsm"). numpy and scipy keep their
own OpenBLAS; MKL serves where scipy's wrappers cannot: PARDISO's Schur complement, and BLAS on
a sub-block of a matrix in place (scipy's f2py wrappers copy every non-contiguous slice, about
half of a 4,225² inverse standard form, :func:`~infsup_contact.la.bottom.inverse_standard_form`).
Every caller keeps a scipy route for a machine without it (:func:`available`). Threads: as
:func:`~infsup_contact.la.threaded.threads` (MKL_NUM_THREADS, else OPENBLAS_NUM_THREADS, else 1) when
MKL loads; later :func:`~infsup_contact.la.threaded.use_threads` (the request's count) and
:func:`~infsup_contact.la.threaded.run_concurrently` (one thread per task, ``MKL_Set_Num_Threads_Local``).
"""
from __future__ import annotations

import ctypes
import glob
import os
import sys
from functools import lru_cache

import numpy as np

from . import threaded
from .threaded import threads

_COL_MAJOR, _LEFT, _LOWER, _NO_TRANS, _NON_UNIT = 102, 141, 122, 111, 131
"""CBLAS enumerations (cblas.h): CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit."""


FALLBACK_NOTE = ("infsup-contact: note: MKL (libmkl_rt) not loaded{why}: PARDISO and the in-place "
                 "triangular solve are off, the scipy routes run (same results, slower on large 3D "
                 "meshes; the mkl wheel: Linux x86_64, or INFSUP_MKL_RT=/path/to/libmkl_rt.so)")
"""The one line :func:`mkl_rt` prints when it finds no usable library (once per process)."""


@lru_cache(maxsize=1)
def mkl_rt():
    """The loaded ``mkl_rt`` (or None): $INFSUP_MKL_RT, else the environment's ``lib/``.

    None where nothing loads (no ``mkl`` wheel: it is installed on Linux x86_64 only, pyproject's
    marker) or a library lacks the symbols used here; then every caller takes its scipy route
    and one note on stderr says so (the results are the same; the routes differ in speed)."""
    candidates = [os.environ.get("INFSUP_MKL_RT", "")]
    for prefix in (sys.prefix, sys.base_prefix):
        candidates += sorted(glob.glob(os.path.join(prefix, "lib", "libmkl_rt.so*")))
    failures = []
    for path in filter(None, candidates):
        try:
            lib = ctypes.CDLL(path)
            lib.MKL_Set_Num_Threads(ctypes.c_int(threads()))
            lib.cblas_dtrsm.restype = None
        except (OSError, AttributeError) as err:  # not loadable, or not MKL's runtime
            failures.append(f"{path}: {' '.join(str(err).split())}")
            continue
        lib.cblas_dtrsm.argtypes = [ctypes.c_int] * 7 + [ctypes.c_double, ctypes.c_void_p, ctypes.c_int,
                                                         ctypes.c_void_p, ctypes.c_int]
        # later decisions reach MKL too: a request's thread count, one thread per concurrent task
        threaded.GLOBAL_THREADS_HOOKS.append(lambda n: lib.MKL_Set_Num_Threads(ctypes.c_int(n)))
        threaded.LOCAL_THREADS_HOOKS.append(lambda n: lib.MKL_Set_Num_Threads_Local(ctypes.c_int(n)))
        return lib
    _note(FALLBACK_NOTE.format(why=f" ({failures[0]})" if failures else ""))
    return None


def _note(line: str) -> None:
    if sys.stderr is not None:
        try:
            print(line, file=sys.stderr, flush=True)
        except OSError:
            pass


def available() -> bool:
    """Whether MKL could be loaded."""
    return mkl_rt() is not None


def trailing_solve(R: np.ndarray, K: np.ndarray, j: int, e: int) -> None:
    """K[j:, j:e] ← R[j:, j:]⁻¹ K[j:, j:e] in place (cblas_dtrsm on the sub-blocks, no copy), for
    Fortran-ordered float64 R (lower triangular, m × m) and K (m × n)."""
    for M in (R, K):
        if not (M.flags.f_contiguous and M.dtype == np.float64):
            raise ValueError("trailing_solve needs Fortran-ordered float64 arrays")
    m, n = R.shape[0], K.shape[1]
    if not (K.shape[0] == m and 0 <= j < m and j < e <= n):
        raise ValueError(f"trailing_solve: block {j}:{e} outside K ({K.shape}) or R ({R.shape})")
    size = R.itemsize
    mkl_rt().cblas_dtrsm(_COL_MAJOR, _LEFT, _LOWER, _NO_TRANS, _NON_UNIT, m - j, e - j, 1.0,
                         R.ctypes.data + (j * m + j) * size, m, K.ctypes.data + (j * m + j) * size, m)


CBWR_BRANCHES = {1: "OFF", 2: "AUTO", 3: "COMPATIBLE", 4: "SSE2", 6: "SSSE3", 7: "SSE4_1", 8: "SSE4_2", 9: "AVX",
                 10: "AVX2", 11: "AVX512_MIC", 12: "AVX512", 13: "AVX512_MIC_E1", 14: "AVX512_E1"}
"""MKL's conditional-numerical-reproducibility branches by value (mkl_types.h, ``MKL_CBWR_*``;
``OFF`` = MKL_CBWR_BRANCH_OFF, no branch fixed: MKL dispatches as it likes)."""
_CBWR_BRANCH = 1
"""``MKL_CBWR_BRANCH``: the option of ``MKL_CBWR_Get`` that asks for the branch (not the flags)."""


def cbwr_branch() -> str:
    """The code branch MKL runs in this process (``MKL_CBWR_Get``): what ``MKL_CBWR`` selected,
    or ``AUTO`` where MKL refused the requested branch (an unsupported one falls back), ``OFF``
    without ``MKL_CBWR``."""
    value = mkl_rt().MKL_CBWR_Get(ctypes.c_int(_CBWR_BRANCH))
    return CBWR_BRANCHES.get(value, f"unknown ({value})")


def cbwr_auto_branch() -> str:
    """The branch MKL's ``AUTO`` dispatch picks on this CPU (``MKL_CBWR_Get_Auto_Branch``)."""
    value = mkl_rt().MKL_CBWR_Get_Auto_Branch()
    return CBWR_BRANCHES.get(value, f"unknown ({value})")
