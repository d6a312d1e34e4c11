"""Speed measured as ratios in one run on one machine (never asserted in unit tests).

Every timing is repeated and reported as median, min and max; the routes of one size
are run interleaved (repeat 1 of every route, then repeat 2, ...) so that a change in
machine load hits all of them alike. ``ratio_to_ours`` = route seconds / ``ours``
seconds; β tables add ``ratio_to_ours_core`` (/ ``ours_core``), contact tables
``ratio_to_limit`` (/ ``limit``: how close a route comes to the unavoidable
factorization). All ratios are of medians.
The workflow's rules run one BLAS thread (``OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1``); with no
thread count in the environment a run takes the idle cores (:func:`~infsup_contact.la.threaded.decide_threads`),
and ``machine.json`` records the counts.

The routes: :mod:`.beta_bench` (β_h of any model), :mod:`.contact_routes` (contact, with the peers of
:mod:`.peers`); :mod:`.speed_accuracy` relates time to error.
"""
from __future__ import annotations

import importlib.metadata as _md
import json
import os
import platform
import sys
import time

import numpy as np

from ..discretization.segment.logkernel import clear_partition_cache


PEER_LIBRARIES = ("osqp", "clarabel", "qpsolvers", "scikit-sparse")

ROUTE_BUDGET = 10.0
"""Default seconds after which a route is not repeated (:func:`run_interleaved`): a route
slower than this runs once, its spread being small next to its time."""



def _log(msg: str) -> None:
    """A benchmark's line: through the request's progress reporter where one is installed
    (``infsup-contact bench``; ``--quiet`` silences it), else on stderr as it is."""
    from .. import progress

    if progress.active():
        progress.note(msg.strip())
        return
    print(f"[bench {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


# ------------------------------------------------------------------------ timing
def run_interleaved(routes: dict, repeats: int, budget: float = np.inf, max_repeats: dict | None = None,
                    self_timed=()):
    """Time several routes round-robin: repeat r of every route before repeat r + 1.

    Parameters
    ----------
    routes : {name: callable}
    repeats : int
        Wanted repetitions per route.
    budget : float
        A route is not repeated once its accumulated time exceeds ``budget`` seconds
        (it always runs once).
    max_repeats : {name: int}, optional
        Per-route cap on the repetitions (slow routes).
    self_timed : names of routes that return their own time in seconds (the wall time
        of the call, which would include their untimed set-up, is then not used).

    Every call starts with the library's per-partition caches empty, as a single call in a
    fresh process would: a repeat must time the work, not a cache lookup.

    Returns
    -------
    {name: (last result, [seconds, ...])}
    """
    max_repeats = max_repeats or {}
    out = {name: (None, []) for name in routes}
    for r in range(repeats):
        for name, fn in routes.items():
            res, times = out[name]
            if r >= max_repeats.get(name, repeats) or (times and sum(times) > budget):
                continue
            clear_partition_cache()
            t = time.perf_counter()
            res = fn()
            times.append(float(res) if name in self_timed else time.perf_counter() - t)
            out[name] = (res, times)
    return out


def _stats(times):
    return float(np.median(times)), float(np.min(times)), float(np.max(times))


def _row(what, route, k, n, times, ref_ours, ref_other, other="ratio_to_ours_core", **extra):
    """One table row; ``other`` names the second ratio column (route / ``ref_other``)."""
    med, lo, hi = _stats(times)
    return {"what": what, "route": route, "k": k, "N": n, "seconds_median": med,
            "seconds_min": lo, "seconds_max": hi, "ratio_to_ours": med / ref_ours,
            other: med / ref_other if ref_other else np.nan, "repeats": len(times), **extra}


# ------------------------------------------------------------------ machine info
def library_versions() -> dict:
    """Versions of the libraries the numbers depend on (provenance + the peers)."""
    from ..provenance import versions

    out = versions()
    for name in PEER_LIBRARIES:
        try:
            out[name] = _md.version(name)
        except _md.PackageNotFoundError:
            out[name] = "not installed"
    try:
        import numpy as _np
        cfg = _np.show_config(mode="dicts")
        blas = cfg.get("Build Dependencies", {}).get("blas", {})
        out["numpy_blas"] = f"{blas.get('name', '?')} {blas.get('version', '')}".strip()
    except Exception:  # noqa: BLE001 - purely informational
        pass
    return out


def machine_info() -> dict:
    """CPU model, cores, load, BLAS thread setting and library versions of this run."""
    model = platform.processor()
    try:
        with open("/proc/cpuinfo") as fh:
            model = next((ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")), model)
    except OSError:
        pass
    try:
        load = list(os.getloadavg())
    except OSError:
        load = None
    try:
        affinity = len(os.sched_getaffinity(0))
    except AttributeError:
        affinity = None
    return dict(cpu_model=model, cores=os.cpu_count(), cores_available=affinity,
                load_average_1_5_15=load, platform=platform.platform(),
                openblas_threads=os.environ.get("OPENBLAS_NUM_THREADS", "unset"),
                omp_threads=os.environ.get("OMP_NUM_THREADS", "unset"),
                mkl_threads=os.environ.get("MKL_NUM_THREADS", "unset"),
                versions=library_versions(),
                date=time.strftime("%Y-%m-%dT%H:%M:%S%z"))


def write_machine_info(path) -> None:
    """Write :func:`machine_info` as JSON, atomically."""
    from ..io import write_atomic

    write_atomic(path, json.dumps(machine_info(), indent=2) + "\n")
