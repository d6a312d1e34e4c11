"""scipy's and numpy's OpenBLAS: its thread count fitted to the cores that are idle when a request
starts, and scipy's LAPACK called without the GIL (the second half of this module).

numpy and scipy each load their own OpenBLAS (``scipy_openblas``), whose threads wait for work
by spinning. When another process holds a core, a multi-threaded call waits for a thread that is
not scheduled, and a request of thousands of medium-sized calls (the face's kernel decisions,
pencils and Grams) slows down by far more than the core it lost. Measured on this project's
2-core machine (AMD EPYC, Zen 4) with five other processes running, the same
``beta --model membranes3d --element hex --case all --k 2 --norm all`` request took 6.5×
(N = 12) and 13× (N = 20) the wall time with OPENBLAS_NUM_THREADS=2 that it took with 1
(MKL's threads, PARDISO's, did not matter; ``OPENBLAS_THREAD_TIMEOUT=4`` cut the slowdown to
2.5× the one-thread run; the measurements are in CHANGELOG.md). The rule
(:func:`fitted_threads`): run OpenBLAS on as many threads as cores are idle at the start
(sampled from /proc/stat), never more than asked, never fewer than one. ``INFSUP_BLAS_FIT=0``
keeps the count asked for (benchmarks that measure the threads themselves).
"""
from __future__ import annotations

import ctypes
import glob
import os
import time
from functools import lru_cache

_SUFFIX = {"numpy": "64_", "scipy": ""}
"""numpy's and scipy's OpenBLAS copies and the suffix of their ``scipy_openblas_*`` symbols."""


@lru_cache(maxsize=1)
def loaded() -> tuple:
    """(name, ctypes library, symbol suffix) of each OpenBLAS copy numpy and scipy load."""
    import numpy
    import scipy

    out = []
    for name, mod in (("numpy", numpy), ("scipy", scipy)):
        folder = os.path.join(os.path.dirname(os.path.dirname(mod.__file__)), f"{name}.libs")
        out += [(name, ctypes.CDLL(path), _SUFFIX[name]) for path in glob.glob(os.path.join(folder, "*openblas*"))]
    return tuple(out)


def libraries() -> tuple:
    """(name, set, get) of each copy's thread-count functions (ctypes)."""
    out = []
    for name, lib, sfx in loaded():
        setter = getattr(lib, f"scipy_openblas_set_num_threads{sfx}", None)
        getter = getattr(lib, f"scipy_openblas_get_num_threads{sfx}", None)
        if setter is not None and getter is not None:
            getter.restype = ctypes.c_int
            out.append((name, setter, getter))
    return tuple(out)


def corenames() -> dict:
    """{copy: the kernel set OpenBLAS chose in this process} (``OPENBLAS_CORETYPE`` overrides it)."""
    out = {}
    for name, lib, sfx in loaded():
        fn = getattr(lib, f"scipy_openblas_get_corename{sfx}", None)
        if fn is not None:
            fn.restype = ctypes.c_char_p
            out[name] = fn().decode()
    return out


def threads_now() -> dict:
    """{copy: its current thread count} of numpy's and scipy's OpenBLAS."""
    return {name: int(get()) for name, _, get in libraries()}


def set_threads(n: int) -> None:
    """Set both OpenBLAS copies to ``n`` threads (at least 1)."""
    for _, setter, _ in libraries():
        setter(ctypes.c_int(max(int(n), 1)))


def idle_cores(window: float = 0.2, stat: str = "/proc/stat") -> float | None:
    """Cores idle over ``window`` seconds (idle + iowait jiffies of all CPUs over all jiffies,
    times the CPUs this process may run on); None where /proc/stat cannot be read."""
    def sample():
        with open(stat) as f:
            fields = [int(x) for x in f.readline().split()[1:]]
        return fields[3] + fields[4], sum(fields[:8])
    try:
        idle0, total0 = sample()
        time.sleep(window)
        idle1, total1 = sample()
    except (OSError, ValueError, IndexError):
        return None
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return cpus * (idle1 - idle0) / max(total1 - total0, 1)


def fitted_threads(asked: int, idle: float | None) -> int:
    """The rule: as many threads as cores are idle (a core counts when it is at least 3/4 idle),
    at most ``asked``, at least 1; ``asked`` where the idle cores are unknown."""
    if idle is None:
        return max(asked, 1)
    return max(1, min(asked, int(idle + 0.25)))


def fit_to_idle_cores(asked: int) -> tuple[int, float | None]:
    """Apply :func:`fitted_threads` to both OpenBLAS copies when more than one thread is asked
    and ``INFSUP_BLAS_FIT`` is not "0"; returns (threads used, idle cores measured or None)."""
    if asked <= 1 or os.environ.get("INFSUP_BLAS_FIT", "1") == "0":
        return asked, None
    idle = idle_cores()
    n = fitted_threads(asked, idle)
    if n < asked:
        set_threads(n)
    return n, idle


# --- scipy's LAPACK without the GIL
# scipy.linalg's LAPACK wrappers (f2py) hold the GIL for the whole call: two threads calling
# potrf or gesdd run one after the other (k = 2 face sizes, order 1,500, one OpenBLAS thread: potrf
# 1.10×, gesdd 0.99× the speed of one thread on two threads; numpy's matmul 1.64×). The same
# routines of the same library called through ctypes release it, so the tasks of
# :func:`~.threaded.run_concurrently` overlap; the same routine with the same arguments and
# workspace gives the same bits (tests/la/test_nogil_lapack.py). Where scipy's OpenBLAS or one of
# the routines is not found (another scipy build), scipy.linalg's own calls serve.

_INT = ctypes.c_int
"""scipy's OpenBLAS takes 32-bit LAPACK integers (numpy's copy is the ILP64 one)."""


def _np():
    """numpy, scipy.linalg and its lapack, imported on first use: this module is read before them
    (the thread counts are set before OpenBLAS loads)."""
    import numpy
    import scipy.linalg
    from scipy.linalg import lapack

    return numpy, scipy.linalg, lapack


@lru_cache(maxsize=None)
def _lapack(name: str):
    """scipy's OpenBLAS routine ``scipy_<name>_`` (ctypes), or None: not found, or the library
    does not pass :func:`_agrees` (another integer width or calling convention)."""
    fn = _symbol(name)
    return fn if fn is not None and _agrees() else None


def _symbol(name: str):
    for copy, lib, _ in loaded():
        fn = getattr(lib, f"scipy_{name}_", None) if copy == "scipy" else None
        if fn is not None:
            fn.restype = None
            return fn
    return None


@lru_cache(maxsize=1)
def _agrees() -> bool:
    """Whether scipy's dpotrf called through ctypes factors a 3 × 3 matrix as scipy.linalg does
    (the LP64 interface this module assumes; an ILP64 copy names its symbols with a suffix and is
    not found)."""
    np, _, lapack = _np()
    fn = _symbol("dpotrf")
    if fn is None:
        return False
    S = np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.25], [0.5, 0.25, 2.0]], order="F")
    info = _INT(0)
    fn(ctypes.c_char_p(b"L"), _ref(3), _ptr(S), _ref(3), ctypes.byref(info), ctypes.c_size_t(1))
    want, info0 = lapack.dpotrf(np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.25], [0.5, 0.25, 2.0]]), lower=1, clean=0)
    return info.value == info0 == 0 and bool(np.array_equal(np.tril(S), np.tril(want)))


def _ref(value: int):
    return ctypes.byref(_INT(int(value)))


def _ptr(a):
    return ctypes.c_void_p(a.ctypes.data)


def _fortran(A, overwrite: bool):
    """A as a Fortran-ordered float64 array: A itself where ``overwrite`` and it already is one
    (as f2py's ``overwrite_a``), else a copy."""
    np = _np()[0]
    return np.asfortranarray(A, dtype=float) if overwrite else np.array(A, dtype=float, order="F")


def potrf(A, clean: bool = True, overwrite: bool = False) -> tuple:
    """(L, info): ``scipy.linalg.lapack.dpotrf(A, lower=1, clean=clean, overwrite_a=overwrite)``,
    bit for bit, without the GIL (module text)."""
    lapack = _np()[2]
    fn = _lapack("dpotrf")
    if fn is None:
        return lapack.dpotrf(A, lower=1, clean=int(clean), overwrite_a=int(overwrite))
    a = _fortran(A, overwrite)
    n, info = a.shape[0], _INT(0)
    if n:
        fn(ctypes.c_char_p(b"L"), _ref(n), _ptr(a), _ref(n), ctypes.byref(info), ctypes.c_size_t(1))
    if clean:  # f2py's clean: the strict upper triangle zeroed (column by column: contiguous)
        for j in range(1, n):
            a[:j, j] = 0.0
    return a, int(info.value)


def cholesky_lower(A, overwrite: bool = False, clean: bool = True):
    """``scipy.linalg.cholesky(A, lower=True, overwrite_a=overwrite, check_finite=False)``, bit for
    bit, without the GIL; LinAlgError where A is not positive definite. ``clean`` False:
    ``cho_factor``'s factor (the strict upper triangle as it was)."""
    np = _np()[0]
    L, info = potrf(A, clean, overwrite)
    if info > 0:
        raise np.linalg.LinAlgError(f"{info}-th leading minor of the array is not positive definite")
    return L


def potrs(c, b):
    """``scipy.linalg.cho_solve((c, True), b, check_finite=False)`` (c a lower factor, b a vector or
    a matrix), bit for bit, without the GIL."""
    np, sla, _ = _np()
    fn = _lapack("dpotrs")
    b = np.asarray(b)
    if fn is None or b.size == 0 or b.dtype != float:
        return sla.cho_solve((c, True), b, check_finite=False)
    a, x = _column_major(c), np.array(b, dtype=float, order="F")
    n, nrhs, info = a.shape[0], (1 if x.ndim == 1 else x.shape[1]), _INT(0)
    fn(ctypes.c_char_p(b"L"), _ref(n), _ref(nrhs), _ptr(a), _ref(n), _ptr(x), _ref(n), ctypes.byref(info),
       ctypes.c_size_t(1))
    if info.value != 0:
        raise ValueError(f"illegal value in {-info.value}th argument of internal potrs")
    return x


def lauum(K, overwrite: bool = False) -> tuple:
    """(C, info): ``scipy.linalg.lapack.dlauum(K, lower=1, overwrite_c=overwrite)``, bit for bit,
    without the GIL: Kᵀ K of a lower triangular K in C's lower triangle."""
    lapack = _np()[2]
    fn = _lapack("dlauum")
    if fn is None:
        return lapack.dlauum(K, lower=1, overwrite_c=int(overwrite))
    c = _fortran(K, overwrite)
    n, info = c.shape[0], _INT(0)
    if n:
        fn(ctypes.c_char_p(b"L"), _ref(n), _ptr(c), _ref(n), ctypes.byref(info), ctypes.c_size_t(1))
    return c, int(info.value)


def _geqrf(W, overwrite: bool):
    """(a, tau): dgeqrf of W (m × n, m >= n > 0) in a's storage, with the workspace it asks for, as
    scipy's ``safecall``; None where the symbol is absent."""
    np = _np()[0]
    fn = _lapack("dgeqrf")
    if fn is None:
        return None
    a = _fortran(np.asarray_chkfinite(W), overwrite)
    m, n = a.shape
    tau = np.empty(n)
    info = _with_workspace(fn, _ref(m), _ref(n), _ptr(a), _ref(m), _ptr(tau))
    if info < 0:
        raise ValueError(f"illegal value in {-info}th argument of internal geqrf")
    return a, tau


def _with_workspace(fn, *args) -> int:
    """``fn(*args, work, lwork, info)`` with the workspace a query (lwork = -1) asks for, as scipy's
    ``safecall`` (the query's value truncated): info."""
    np = _np()[0]
    work, info = np.empty(1), _INT(0)
    fn(*args, _ptr(work), _ref(-1), ctypes.byref(info))
    lwork = int(np.int_(work[0].real))
    work = np.empty(max(lwork, 1))
    fn(*args, _ptr(work), _ref(lwork), ctypes.byref(info))
    return int(info.value)


def qr_r(W, overwrite: bool = False):
    """``np.triu(scipy.linalg.qr(W, mode="r", overwrite_a=overwrite)[0][:n])`` (W m × n, m >= n,
    finite), bit for bit, without the GIL: dgeqrf with the workspace it asks for, as scipy's."""
    np, sla, _ = _np()
    m, n = np.shape(W)
    done = None if m < n or n == 0 else _geqrf(W, overwrite)
    if done is None:
        return np.triu(sla.qr(W, mode="r", overwrite_a=overwrite, check_finite=True)[0][:n])
    return np.triu(done[0][:n])


def qr_q(W, overwrite: bool = False):
    """``scipy.linalg.qr(W, mode="economic", overwrite_a=overwrite)[0]`` (W m × n, m >= n, finite):
    the orthonormal factor, bit for bit, without the GIL: dgeqrf, then dorgqr on its output, each
    with the workspace it asks for, as scipy's."""
    np, sla, _ = _np()
    m, n = np.shape(W)
    fn = _lapack("dorgqr")
    done = None if fn is None or m < n or n == 0 else _geqrf(W, overwrite)
    if done is None:
        return sla.qr(W, mode="economic", overwrite_a=overwrite, check_finite=True)[0]
    a, tau = done
    info = _with_workspace(fn, _ref(m), _ref(n), _ref(n), _ptr(a), _ref(m), _ptr(tau))
    if info < 0:
        raise ValueError(f"illegal value in {-info}th argument of internal gorgqr/gungqr")
    return a


def gesdd(A, compute_uv: bool, overwrite: bool = False, full: bool = False) -> tuple:
    """(s, Vᵀ) of ``scipy.linalg.svd(A, full_matrices=full, compute_uv=True, overwrite_a=overwrite,
    check_finite=False)``, or (s, None) of ``svdvals`` where not ``compute_uv``, bit for bit, without
    the GIL: dgesdd with scipy's workspace (its ``dgesdd_lwork``)."""
    np, sla, lapack = _np()
    fn = _lapack("dgesdd")
    m, n = np.shape(A)
    k = min(m, n)
    full = bool(full and compute_uv)
    if fn is None or k == 0:
        if compute_uv:
            return tuple(sla.svd(A, full_matrices=full, overwrite_a=overwrite, check_finite=False)[1:])
        return sla.svd(A, compute_uv=False, overwrite_a=overwrite, check_finite=False), None
    a = _fortran(A, overwrite)
    work, info = lapack.dgesdd_lwork(m, n, compute_uv=int(compute_uv), full_matrices=int(full or not compute_uv))
    if info:
        raise ValueError(f"Internal work array size computation failed: {info}")
    lwork = int(work.real)
    s, iwork, work, info = np.empty(k), np.empty(8 * k, dtype=np.int32), np.empty(max(lwork, 1)), _INT(0)
    ucols, vrows = (m, n) if full else (k, k)
    u, vt = (np.empty((m, ucols), order="F"), np.empty((vrows, n), order="F")) if compute_uv else (np.empty(1),
                                                                                                   np.empty(1))
    ldu, ldvt = (m, vrows) if compute_uv else (1, 1)
    job = b"A" if full else (b"S" if compute_uv else b"N")
    fn(ctypes.c_char_p(job), _ref(m), _ref(n), _ptr(a), _ref(m), _ptr(s), _ptr(u),
       _ref(ldu), _ptr(vt), _ref(ldvt), _ptr(work), _ref(lwork), _ptr(iwork), ctypes.byref(info), ctypes.c_size_t(1))
    if info.value > 0:
        raise np.linalg.LinAlgError("SVD did not converge")
    if info.value < 0:
        raise ValueError(f"illegal value in {-info.value}th argument of internal gesdd")
    return (s, vt) if compute_uv else (s, None)


# the Lanczos steps' level-2 calls (a few ms each at a face block's order; ctypes adds microseconds)
_CHARS = {False: b"U", True: b"L"}
_TRANS = {0: b"N", 1: b"T"}


def _column_major(A):
    """A's data in Fortran order: A itself where it is one (f2py's rule for an ``intent(in)`` array)."""
    return A if A.flags.f_contiguous and A.dtype == float else _np()[0].asfortranarray(A, dtype=float)


def symv(A, x, lower: bool):
    """``scipy.linalg.blas.dsymv(1.0, A, x, lower=lower)``, bit for bit, without the GIL."""
    np, _, _ = _np()
    fn = _lapack("dsymv")
    if fn is None:
        from scipy.linalg import blas

        return blas.dsymv(1.0, A, x, lower=int(lower))
    a, x = _column_major(A), np.ascontiguousarray(x, dtype=float)
    n, y = a.shape[0], np.zeros(a.shape[0])
    fn(ctypes.c_char_p(_CHARS[lower]), _ref(n), ctypes.byref(ctypes.c_double(1.0)), _ptr(a), _ref(n), _ptr(x),
       _ref(1), ctypes.byref(ctypes.c_double(0.0)), _ptr(y), _ref(1), ctypes.c_size_t(1))
    return y


def trsv(L, x, lower: bool, trans: int):
    """``scipy.linalg.blas.dtrsv(L, x, lower=lower, trans=trans)``, bit for bit, without the GIL."""
    np, _, _ = _np()
    fn = _lapack("dtrsv")
    if fn is None:
        from scipy.linalg import blas

        return blas.dtrsv(L, x, lower=int(lower), trans=int(trans))
    a, x = _column_major(L), np.array(x, dtype=float)
    fn(ctypes.c_char_p(_CHARS[lower]), ctypes.c_char_p(_TRANS[int(trans)]), ctypes.c_char_p(b"N"), _ref(a.shape[0]),
       _ptr(a), _ref(a.shape[0]), _ptr(x), _ref(1), ctypes.c_size_t(1), ctypes.c_size_t(1), ctypes.c_size_t(1))
    return x


def solve_triangular(L, b, lower: bool, trans: int = 0):
    """``scipy.linalg.solve_triangular(L, b, lower=lower, trans=trans, check_finite=False)`` (b a
    vector or a matrix, real), bit for bit, without the GIL: LAPACK trtrs on L, or on Lᵀ with the
    other triangle and transposition where L is C-ordered, as scipy."""
    np, sla, _ = _np()
    fn = _lapack("dtrtrs")
    b = np.asarray(b)
    if fn is None or b.size == 0 or L.dtype != float or b.dtype != float:
        return sla.solve_triangular(L, b, lower=lower, trans=trans, check_finite=False)
    a = L if L.flags.f_contiguous else L.T
    lower, trans = (lower, int(trans)) if L.flags.f_contiguous else (not lower, 1 - int(trans))
    a = _column_major(a)
    x = np.array(b, dtype=float, order="F")
    n, nrhs, info = a.shape[0], (1 if x.ndim == 1 else x.shape[1]), _INT(0)
    fn(ctypes.c_char_p(_CHARS[bool(lower)]), ctypes.c_char_p(_TRANS[trans]), ctypes.c_char_p(b"N"), _ref(n),
       _ref(nrhs), _ptr(a), _ref(n), _ptr(x), _ref(n), ctypes.byref(info), ctypes.c_size_t(1), ctypes.c_size_t(1),
       ctypes.c_size_t(1))
    if info.value > 0:
        raise np.linalg.LinAlgError(f"singular matrix: resolution failed at diagonal {info.value - 1}")
    if info.value < 0:
        raise ValueError(f"illegal value in {-info.value}-th argument of internal trtrs")
    return x
