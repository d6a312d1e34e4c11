"""The machine's memory as the kernel reports it (/proc/meminfo): what a request may still take.

One reading for every decision that depends on it: the ``--dry-run`` refusal and the command
line's reuse of freed memory (:mod:`.resources`, :mod:`.cli`), the foreign systems' readers, and
whether two multiplier spaces run side by side (:mod:`.solvers.side_by_side`). MemAvailable, not
MemFree: the page cache a request's files filled is given back on demand, and after a workflow
has run it can hold most of the machine (MemFree then says "full" of a machine that is not).

Here too how the process keeps the memory it frees (:func:`reuse_freed_memory`,
:func:`release_freed_memory`): glibc's ``mallopt`` and ``malloc_trim``.
"""
from __future__ import annotations

import os


def _meminfo(field: str, meminfo: str) -> float | None:
    try:
        with open(meminfo) as fh:
            for line in fh:
                if line.startswith(field + ":"):
                    return float(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def available_bytes(meminfo: str = "/proc/meminfo") -> float | None:
    """MemAvailable of /proc/meminfo in bytes (None where the file or the field is missing)."""
    return _meminfo("MemAvailable", meminfo)


def total_bytes(meminfo: str = "/proc/meminfo") -> float | None:
    """MemTotal of /proc/meminfo in bytes (None where unavailable)."""
    return _meminfo("MemTotal", meminfo)


M_TRIM_THRESHOLD, M_MMAP_MAX, M_ARENA_MAX = -1, -4, -8
"""glibc's ``mallopt`` parameters (malloc.h)."""


_bounded_reuse = False
"""Whether :func:`release_freed_memory` gives the kept free memory back (:func:`reuse_freed_memory`
with ``bounded``)."""


def reuse_freed_memory(bounded: bool = False) -> bool:
    """Keep freed memory in the process for the next allocation (glibc ``mallopt``: no ``mmap``
    per large block, no trimming). A request allocates and frees dense blocks of 100 MB and more
    many times over; by default each is a fresh ``mmap`` whose pages fault in zeroed one by one,
    and the request spent 15 % of its CPU in the kernel (k = 2, N = 24: 7.1 s sys of 45.8 s,
    689 k minor faults; with this 1.1 s, 342 k faults; N = 32: 4.9 s sys of 161 s). Transparent
    huge pages are not the cause (``NUMPY_MADVISE_HUGEPAGE=0``: 7.5 s sys, 3.4 M faults): zeroing
    fresh pages is. The price is a higher peak (freed blocks stay resident between reuses: peak RSS
    1.78 GB against 1.68 at N = 24, 5.19 GB against ~4.4 at N = 32), so the command line applies it
    only where memory is plentiful (``cli._reuse_freed_memory``). Left as it is where glibc is
    absent or a ``MALLOC_*`` variable already says how; True if applied.

    A thread other than the main one allocates from an arena of its own, whose heaps are 64 MB:
    a larger block there is an ``mmap`` whatever ``M_MMAP_MAX`` says (k = 2, N = 32, two threads:
    720 k faults and 11 s sys against 118 k and 6 s on one). So every thread allocates from the
    main arena (``M_ARENA_MAX`` = 1): N = 24, two threads, 201 k → 97 k faults, 3.0 → 2.5 s sys,
    peak 1.46 → 1.29 GB, the same user CPU-s (16.7, 17.2; run side by side on a loaded machine).

    ``bounded``: freed memory is kept within a stage of the request only: at the stage's end
    (:func:`release_freed_memory`, after the sides and after each multiplier space) what is free
    goes back to the system, so the peak is the live memory plus one stage's churn at most. For
    requests whose peak is too close to the available memory for unbounded reuse (k = 2, N = 36,
    two threads, one space at a time: 77.9 → 20.1 s sys, 17 M → 0.42 M faults, peak 4.44 → 4.90 GB
    against glibc's default; kept all along: 5.55 GB)."""
    import ctypes

    if any(v.startswith("MALLOC_") for v in os.environ):
        return False
    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    applied = (bool(mallopt(M_MMAP_MAX, 0)) and bool(mallopt(M_TRIM_THRESHOLD, 2 ** 31 - 1))
               and bool(mallopt(M_ARENA_MAX, 1)))
    global _bounded_reuse
    _bounded_reuse = applied and bounded
    return applied


def release_freed_memory(always: bool = False) -> None:
    """Where :func:`reuse_freed_memory` was applied ``bounded`` (or ``always``: before worker
    processes fork, which allocate their own while the parent waits): give the free memory the
    process keeps back to the system (glibc ``malloc_trim``; live blocks stay where they are). Else
    nothing."""
    if _bounded_reuse or always:
        import ctypes

        ctypes.CDLL(None).malloc_trim(0)
