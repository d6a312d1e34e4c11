"""OpenBLAS's thread count fitted to the cores that are idle when a request starts.

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
