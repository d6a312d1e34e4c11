"""The machine's memory as the kernel reports it (/proc/meminfo): what a request may still take.

One reading for every decision that depends on it: the ``--dry-run`` refusal and the command
line's reuse of freed memory (:mod:`.resources`, :mod:`.cli`), the foreign systems' readers, and
whether two multiplier spaces run side by side (:mod:`.solvers.side_by_side`). MemAvailable, not
MemFree: the page cache a request's files filled is given back on demand, and after a workflow
has run it can hold most of the machine (MemFree then says "full" of a machine that is not).
"""
from __future__ import annotations


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
