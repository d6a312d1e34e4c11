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
(:meth:`~infsup_contact.discretization.gamma.trace.GammaTrace.cached_basis`). The first space
runs alone: it makes what the others then only read (each side's explicit X_i, the trace basis
at the common quadrature points). Every space computes what it computed alone, from the same
operands: the rows are those of one space at a time (tested bit for bit at one BLAS thread).

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

from .. import progress
from ..la.threaded import run_concurrently, threads
from ..memory import available_bytes, release_freed_memory

DENSE_COPIES = 8.0
"""Dense m × m float64 matrices one space holds at its peak (measured at k = 2 on the face,
N = 32 and 36: the interface terms raised the resident memory by 7–8 m² doubles)."""
MEMORY_SHARE = 0.5
"""Share of the available memory two spaces' working sets may take together."""
PHASE = "spaces side by side"
"""The phase (:func:`~infsup_contact.progress.phase`) the concurrent spaces count in."""


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


def rows_by_case(cases, rows_of, dim: int, label=str) -> list:
    """[rows_of(case) for case in cases], in the cases' order: the first case alone (it makes
    what the spaces share), the others two at a time where :func:`space_workers` allows,
    each on one BLAS thread; else one after the other. ``dim``: about the spaces' dimension
    (their working set, :func:`working_set`); ``label``: a case's name in the progress."""
    cases = list(cases)
    release_freed_memory()  # the sides' factorizations are done: what they freed goes back

    def released(case):
        out = rows_of(case)
        release_freed_memory()
        return out

    workers = space_workers(dim, len(cases) - 1)
    if workers < 2:
        return [released(case) for case in progress.steps(cases, "space", label)]
    first = [released(case) for case in progress.steps(cases[:1], "space", label)]
    progress.note(f"{len(cases) - 1} spaces, {workers} at a time")
    with progress.phase(PHASE):
        rest = run_concurrently([lambda case=case: released(case) for case in cases[1:]], workers=workers)
    return first + rest
