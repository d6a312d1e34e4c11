"""The multiplier spaces of a β_h request side by side: two spaces at a time on two cores.

After the sides, a request's time goes into its spaces, one after the other (k = 2, N = 36 on
the face: 11 of 12 spaces, 85 of 118 CPU-s), and inside a space into the Gram series, the kernel
decision, the sandwiches B X Bᵀ and the eigensolves: LAPACK, numpy and scipy kernels that
release the GIL but run on one core (OpenBLAS on one thread, the products split over rows only
where no space runs beside them). Two spaces at a time, each on one core
(:func:`~infsup_contact.la.threaded.run_concurrently`: one BLAS thread per task), use both.

What the spaces share is made safe for two threads where it lives: the Grams of a sweep are
computed one at a time (:class:`~.side_cache.GramCache`, whose lock also guards the series the
spaces of one G_h share), the sides' trace basis values once per point set
(:meth:`~infsup_contact.discretization.gamma.trace.GammaTrace.cached_basis`). In threads the
first space runs alone: it makes what the others then only read (each side's explicit X_i, the
trace basis at the common quadrature points). Every space computes what it computed alone, from
the same operands: the rows are those of one space at a time (tested bit for bit at one BLAS thread).

In worker processes where the command line asks (:func:`worker_processes`: ``beta`` and ``bench``, a
request of one mesh pair, on Linux): two forked processes take every space, each space as one task
(one BLAS thread; the spaces sharing a Gram series one after the other in one worker,
:func:`chains`), and send back their rows. No space runs alone first: a worker's caches are its
own anyway (each makes the trace values it needs), and a first space alone left a core idle (cold
caches, k = 2 on the face, ours paired, every space in the workers against the first alone:
0.94–0.97× at N = 16, 0.95–1.02× at N = 20; 0.77–0.96× at N = 24, where threads ran before).
Threads share Python's GIL, and a space holds it for much of its time (ARPACK's
reverse-communication loops, scipy's sparse wrappers, the trace basis; about 3.6 of 8 s at k = 2,
N = 24), so two threads run at about 1.4× one; two processes do not wait for each other (ours
0.80× at N = 16, 0.87× at N = 20; spaces up to :data:`PROCESSES_MAX_DIM`). Fork shares the
sides without a copy. The rows are those of one space at a time on one BLAS thread, bit for bit
(tested); what a worker caches (its Grams, trace values) stays in it, so the route is for a
request whose spaces ask each Gram once — a sweep of pairs sharing G_h keeps threads and its Gram
cache. A worker that dies (killed, out of memory) fails the request with a message saying so.
``INFSUP_SPACE_PROCESSES=0`` keeps threads.

Memory bounds it: a space holds a few dense m × m matrices at its peak (:data:`DENSE_COPIES`,
m about dim(W1 + W2)), and two spaces run at once only where both working sets fit in
:data:`MEMORY_SHARE` of the memory available when the spaces start (k = 2 on the face, 24 GB:
N = 36, 2 × 1.6 GB, two at a time; N = 48, 2 × 5.7 GB against about 17 GB available after the sides,
one at a time: the peak stays the serial one). Where the request's progress is timed by phase
(:func:`~infsup_contact.progress.timing`, the benchmark's breakdown), the concurrent spaces'
phases count as one, :data:`PHASE`. Where the command line keeps freed memory within a stage
only, each space's end is a stage's end (:func:`~infsup_contact.memory.release_freed_memory`).
"""
from __future__ import annotations

import contextlib
import multiprocessing
import os
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool

from .. import progress
from ..la.openblas import set_threads
from ..la.threaded import as_task, run_concurrently, threads
from ..memory import available_bytes, release_freed_memory

DENSE_COPIES = 8.0
"""Dense m × m float64 matrices one space holds at its peak (measured at k = 2 on the face,
N = 32 and 36: the interface terms raised the resident memory by 7–8 m² doubles)."""
MEMORY_SHARE = 0.5
"""Share of the available memory two spaces' working sets may take together."""
PHASE = "spaces side by side"
"""The phase (:func:`~infsup_contact.progress.phase`) the concurrent spaces count in."""


_PROCESSES = {"on": False}
"""Whether :func:`rows_by_case` may run the spaces in worker processes (:func:`worker_processes`)."""
_WORK: dict = {}
"""What the forked workers read: the spaces' function and cases, set before the workers fork."""


@contextlib.contextmanager
def worker_processes():
    """Inside: :func:`rows_by_case` may run the spaces in two forked worker processes (module
    text). The command line's ``beta`` and ``bench`` run in it; a library caller keeps threads
    unless it asks."""
    before = _PROCESSES["on"]
    _PROCESSES["on"] = True
    try:
        yield
    finally:
        _PROCESSES["on"] = before


PROCESSES_MAX_DIM = 2500
"""Largest dim (about dim(W1 + W2)) whose spaces run in worker processes. Above it a space's work
is mostly BLAS and sparse kernels that release the GIL, and the workers' fresh pages and unshared
caches cost as much as the GIL did, or more (k = 2 on the face, ours paired with threads in one
process, the first space alone: 0.72× at N = 8, 0.73× N = 12, 0.80× N = 16, 0.87× N = 20
(dim 1,521); 0.95–0.97× at N = 24 (dim 2,209) for half again the CPU, and 0.77–0.96× with every
space in the workers; 1.06× at N = 32 (dim 4,225), whose summed peak PSS also rose 2.8 → 3.8 GB)."""


def processes_allowed(dim: int, python_bound: bool) -> bool:
    """Whether spaces of dimension about ``dim`` run in worker processes: asked
    (:func:`worker_processes`), their work ``python_bound`` (a face's spaces: the GIL bounds two
    threads; the segment's are cheap and gain nothing), ``dim`` ≤ :data:`PROCESSES_MAX_DIM`, not
    refused by ``INFSUP_SPACE_PROCESSES=0``, on Linux where ``fork`` is available."""
    return (_PROCESSES["on"] and python_bound and dim <= PROCESSES_MAX_DIM
            and os.environ.get("INFSUP_SPACE_PROCESSES", "1") != "0"
            and sys.platform.startswith("linux") and "fork" in multiprocessing.get_all_start_methods())


def working_set(dim: int) -> float:
    """Bytes one space of dimension about ``dim`` holds at its peak (:data:`DENSE_COPIES`)."""
    return DENSE_COPIES * 8.0 * float(dim) ** 2


def space_workers(dim: int, n_spaces: int, available: float | None = None) -> int:
    """How many spaces run at once: two where the request has two threads or more
    (:func:`~infsup_contact.la.threaded.threads`), there are two spaces to run and two working
    sets of dimension ``dim`` fit in :data:`MEMORY_SHARE` of ``available`` bytes (default: the
    memory available now, :func:`~infsup_contact.memory.available_bytes`); else one."""
    if threads() < 2 or n_spaces < 2:
        return 1
    if available is None:
        available = available_bytes()
    if available is None or 2 * working_set(dim) > MEMORY_SHARE * available:
        return 1
    return 2


def rows_by_case(cases, rows_of, dim: int, label=str, python_bound: bool = False, series=None) -> list:
    """[rows_of(case) for case in cases], in the cases' order: where :func:`space_workers` allows
    two at a time, every case in two worker processes where :func:`processes_allowed`
    (``python_bound``: their work holds the GIL much, as a face's does), else the first case alone
    (it makes what the spaces share) and the others in two threads, each on one BLAS thread; else
    one after the other.
    ``dim``: about the spaces' dimension (their working set, :func:`working_set`); ``label``: a
    case's name in the progress; ``series``: a case's Gram series key, or None (:func:`chains`)."""
    cases = list(cases)
    release_freed_memory()  # the sides' factorizations are done: what they freed goes back

    def released(case):
        out = rows_of(case)
        release_freed_memory()
        return out

    if processes_allowed(dim, python_bound) and space_workers(dim, len(cases)) == 2:
        with progress.phase(PHASE):  # every space in a worker: each makes its own shared values
            progress.note(f"{len(cases)} spaces, 2 worker processes")
            return _in_processes(cases, released, 2, label, chains(cases, series))
    workers = space_workers(dim, len(cases) - 1)
    if workers < 2:
        return [released(case) for case in progress.steps(cases, "space", label)]
    first = [released(case) for case in progress.steps(cases[:1], "space", label)]
    with progress.phase(PHASE):
        progress.note(f"{len(cases) - 1} spaces, {workers} at a time")
        rest = run_concurrently([lambda case=case: released(case) for case in cases[1:]], workers=workers)
    return first + rest


def chains(cases, series=None) -> list:
    """The worker processes' tasks: lists of case indices, each run in one worker in its order.
    Cases whose Grams share a series (equal ``series(case)``, not None: a face's cellwise spaces on
    one piece space, :attr:`~infsup_contact.discretization.face.spaces.cellwise.CellwiseFaceSpace.series_key`)
    form one task, so that the series' partial sums are made once, as one space at a time makes
    them (k = 2, N = 24: DUAL-Q9 and DUAL-Q9-ALL in two workers at once took 1.6 and 2.2 s against
    1.1 and 1.3 s one after the other); those tasks first, longest first (the others even out the
    end), then every other case alone, in the cases' order."""
    keys = [None if series is None else series(case) for case in cases]
    groups: dict = {}
    for i, key in enumerate(keys):
        if key is not None:
            groups.setdefault(key, []).append(i)
    shared = sorted((g for g in groups.values() if len(g) > 1), key=len, reverse=True)
    grouped = {i for g in shared for i in g}
    return shared + [[i] for i in range(len(cases)) if i not in grouped]


def _in_processes(cases: list, rows_of, workers: int, label, tasks: list) -> list:
    """[rows_of(case) for case in cases] in ``workers`` forked processes, the ``tasks`` (lists of
    case indices, :func:`chains`) each one :func:`_task`, the results in the cases' order; every
    task runs to its end, then the first failure in the cases' order is raised (as
    :func:`~infsup_contact.la.threaded.run_concurrently`)."""
    _WORK.update(rows_of=rows_of, cases=cases, tasks=tasks)
    release_freed_memory(always=True)  # the parent waits: the memory it kept for reuse is the workers'
    try:
        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork")) as pool:
            futures = [pool.submit(_task, t) for t in range(len(tasks))]
            task_of, done = {future: task for future, task in zip(futures, tasks)}, 0
            for future in as_completed(futures):
                for i in task_of[future]:  # a task's spaces said one by one, as it ends
                    done += 1
                    progress.note(f"space {label(cases[i])} {'done' if future.exception() is None else 'failed'} "
                                  f"({done} of {len(cases)})")
    finally:
        _WORK.clear()
    by_case = {i: (t, j) for t, task in enumerate(tasks) for j, i in enumerate(task)}
    for i, case in enumerate(cases):
        error = futures[by_case[i][0]].exception()
        if isinstance(error, _CaseFailed):  # the task's own case failed, or another of its cases did
            error = error.error if error.index == i else None
        if isinstance(error, BrokenProcessPool):
            raise RuntimeError(f"a worker process running the multiplier spaces died (killed, or out of memory) "
                               f"before space {label(case)} was done; INFSUP_SPACE_PROCESSES=0 runs them in "
                               "threads") from error
        if error is not None:
            raise error
    return [futures[t].result()[j] for t, j in (by_case[i] for i in range(len(cases)))]


class _CaseFailed(Exception):
    """A task's case ``index`` raised ``error`` (the cases after it in the task did not run)."""

    def __init__(self, index: int, error: BaseException):
        super().__init__(index, error)
        self.index, self.error = index, error


def _task(t: int):
    """Task ``t`` of :data:`_WORK` (its cases one after the other) in a forked worker, each case
    as one task of the threads' route (one BLAS thread: the same bits), its progress not reported
    (the parent says what finished)."""
    progress.detach()
    set_threads(1)
    out = []
    for i in _WORK["tasks"][t]:
        with as_task():
            try:
                out.append(_WORK["rows_of"](_WORK["cases"][i]))
            except Exception as error:  # noqa: BLE001 - raised in the parent, in the cases' order
                raise _CaseFailed(i, error) from None
    return out
