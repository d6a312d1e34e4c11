"""Dense-result products that scipy and numpy run on one core, split over the BLAS threads.

scipy's sparse × dense product (``csr_matvecs``) and numpy's element-wise passes are
single-threaded. On the large face route (k = 2, N = 32) they held about a fifth of a
β_h request while the second core waited: the sandwiches B X Bᵀ of the interface operator
(:mod:`infsup_contact.la.schur`) and R S_P Rᵀ of the cellwise H Grams
(:mod:`infsup_contact.discretization.face.norms.cellwise`), and the reordering of the face
series (:mod:`infsup_contact.discretization.face.norms.tensor`). Both release the GIL, so threads
over disjoint row blocks of the result use every core. Each row of a result is computed by
the same kernel, in the same order, as the one-thread product: the results are bit-identical
(tests/la/test_la_threaded.py).

A second cost was hidden in scipy's ``A @ Y.T``: a C-contiguous copy of the transposed
operand, a strided pass over memory (the largest single cost of a 9,216² product). :func:`symmetric_sandwich`
never transposes a large operand: X Aᵀ is formed row block by row block from small copies.

The number of threads is the BLAS's (MKL_NUM_THREADS, else OPENBLAS_NUM_THREADS, else 1, as
:mod:`infsup_contact.la.pardiso` reads it): a run asked to use one core uses one.

Here too the decisions on threads for a whole request (:func:`decide_threads`: what the
environment asks, else every idle core; :func:`use_threads`) and the helper that runs independent
non-BLAS work side by side (:func:`run_concurrently`: the two sides, a body's parity parts) with
the BLAS of each task on one thread, so that tasks × threads never exceed the cores.
"""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor, wait
from contextlib import contextmanager

import numpy as np
import scipy.sparse as sp

from .openblas import fitted_threads, set_threads, threads_now

MIN_ROWS = 256
"""Fewest result rows of a sparse product per thread worth a thread (below it one call does all)."""
MIN_ENTRIES = 2 ** 20
"""Fewest entries of :func:`symmetric_pairs`' result worth threads."""
BLOCK = 32
"""Rows of X per block of :func:`times_transpose`: the product's (m × BLOCK) result is written
transposed, a pass that stays in cache at this width (one thread: R S_P Rᵀ at dim 9,216 and
B X Bᵀ at n_Γ = 3,969 take about half the time of BLOCK = 256)."""


THREAD_VARIABLES = ("MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")
"""The variables that fix the BLAS threads, in the order they are read (:func:`asked_threads`)."""

_worker = threading.local()
"""``inside`` is True in a thread of :func:`run_concurrently`: its BLAS has one thread."""
LOCAL_THREADS_HOOKS: list = []
"""Callables ``hook(n)`` setting the calling thread's own BLAS thread count (0: the process's
again); :mod:`.mkl` registers ``MKL_Set_Num_Threads_Local`` once it loads MKL."""
GLOBAL_THREADS_HOOKS: list = []
"""Callables ``hook(n)`` setting a loaded library's process-wide thread count (:mod:`.mkl`'s)."""


def threads() -> int:
    """Threads for the products here: MKL_NUM_THREADS, else OPENBLAS_NUM_THREADS, else 1 (1 inside
    a :func:`run_concurrently` task: the tasks hold the cores)."""
    if getattr(_worker, "inside", False):
        return 1
    value = os.environ.get("MKL_NUM_THREADS") or os.environ.get("OPENBLAS_NUM_THREADS") or "1"
    try:
        return max(int(value), 1)
    except ValueError:
        return 1


def asked_threads(environ=None) -> int | None:
    """The thread count the environment fixes: the first of :data:`THREAD_VARIABLES` that is set
    (an unreadable value counts as 1, as :func:`threads` reads it); None where none is set (nobody
    chose: :func:`decide_threads` takes the idle cores)."""
    environ = os.environ if environ is None else environ
    for var in THREAD_VARIABLES:
        value = environ.get(var)
        if value:
            try:
                return max(int(value), 1)
            except ValueError:
                return 1
    return None


def decide_threads(asked: int | None, cpus: int, idle: float | None) -> int:
    """Threads of one request (:func:`use_threads`): the count asked for, else ``cpus``, fitted
    to the idle cores either way (:func:`~.openblas.fitted_threads`: a core counts when 3/4 idle;
    processes side by side, e.g. Snakemake's jobs, each fix their own count and so never sum to
    more than the machine; a request alone on an idle machine gets every core)."""
    return fitted_threads(max(cpus, 1) if asked is None else asked, idle)


def use_threads(n: int) -> None:
    """Give a request ``n`` threads: MKL (PARDISO, its BLAS), the products here and
    :func:`run_concurrently`'s tasks (MKL_NUM_THREADS, which :func:`threads` and MKL read; MKL
    itself if already loaded). OpenBLAS keeps the count it started with (one, the CLI's default):
    its threads wait for work by spinning, and a second OpenBLAS thread on a core another process
    takes made the same request 11× slower (N = 8, k = 2, ``--case all``, load 8 on 2 cores: 86.7 s
    against 7.6 s wall), where MKL's second thread and two tasks cost nothing (8.3 s)."""
    n = max(int(n), 1)
    os.environ["MKL_NUM_THREADS"] = str(n)
    for hook in GLOBAL_THREADS_HOOKS:
        hook(n)


@contextmanager
def as_task():
    """The calling thread as one of :func:`run_concurrently`'s tasks for the duration: one BLAS thread
    of its own (MKL's local count), :func:`threads` 1, its concurrent calls in turn — beside work
    that holds the cores (a body's factorization in another thread)."""
    _worker.inside = True
    for hook in LOCAL_THREADS_HOOKS:
        hook(1)
    try:
        yield
    finally:
        for hook in LOCAL_THREADS_HOOKS:
            hook(0)
        _worker.inside = False


def run_concurrently(tasks, workers: int | None = None) -> list:
    """[task() for task in tasks], the tasks (callables without arguments, independent of each
    other) run side by side on ``workers`` threads (default :func:`threads`, at most one per task).

    For work that releases the GIL and is not BLAS: PARDISO's factorizations (ctypes releases the
    GIL), NGSolve's assembly, numpy's kernels and scipy's sparse products. scipy.linalg's LAPACK and
    BLAS wrappers hold the GIL for the whole call (tasks of them run one after the other): the
    tasks call them through :mod:`.openblas` (the same routines by ctypes). No oversubscription: inside the tasks the
    BLAS runs one thread per task (OpenBLAS set to 1 for the duration, MKL per thread, the products
    of this module serial), so tasks × BLAS threads ≤ the threads asked for. One worker, one task,
    or a call from inside a task (nested): the tasks run in turn in the calling thread. The results
    come in the tasks' order; every task runs to its end, then the first failure (in the tasks'
    order) is raised."""
    tasks = list(tasks)
    n = min(len(tasks), threads() if workers is None else max(int(workers), 1))
    if n <= 1 or getattr(_worker, "inside", False):
        return [task() for task in tasks]
    before = threads_now()

    def inside(task):
        def run():
            with as_task():
                return task()
        return run

    set_threads(1)
    try:
        with ThreadPoolExecutor(n, thread_name_prefix="infsup-concurrent") as pool:
            futures = [pool.submit(inside(t)) for t in tasks]
            wait(futures)
    finally:
        if before:
            set_threads(max(before.values()))
    for f in futures:  # the first failure in the tasks' order, after all ran
        if f.exception() is not None:
            raise f.exception()
    return [f.result() for f in futures]


def concurrent_map(fn, items) -> list:
    """[fn(x) for x in items] by :func:`run_concurrently` (a ``map`` for callers that take one:
    a body's parity parts, :meth:`~infsup_contact.la.body_parity.ParityParts.factorize`)."""
    return run_concurrently([lambda x=x: fn(x) for x in items])


def _row_blocks(n_rows: int, weights: np.ndarray | None = None, min_rows: int = MIN_ROWS) -> list[slice]:
    """At most :func:`threads` contiguous row ranges of at least ``min_rows`` rows, balanced by
    ``weights`` (cumulative work per row boundary, length n_rows + 1, e.g. a CSR indptr), else
    by rows."""
    n = min(threads(), max(n_rows // min_rows, 1))
    if n == 1:
        return [slice(0, n_rows)]
    if weights is None:
        cuts = np.linspace(0, n_rows, n + 1).round().astype(int)
    else:
        cuts = np.searchsorted(weights, np.linspace(weights[0], weights[-1], n + 1))
        cuts[0], cuts[-1] = 0, n_rows
    return [slice(a, b) for a, b in zip(cuts[:-1], cuts[1:]) if b > a]


_pools: dict = {}
"""One pool per thread count, kept for the process: a pool made per call started two threads
each time (2,400 thread starts in a k = 2, N = 32 request)."""


os.register_at_fork(after_in_child=_pools.clear)  # a forked child has none of the threads


def _pool(n: int) -> ThreadPoolExecutor:
    if n not in _pools:
        _pools[n] = ThreadPoolExecutor(n, thread_name_prefix="infsup-threaded")
    return _pools[n]


def _run(tasks) -> None:
    """Call each task (no arguments); in the pool's threads when there is more than one (the
    tasks are leaves: numpy and scipy calls that release the GIL, never :func:`_run` again)."""
    tasks = list(tasks)
    if len(tasks) == 1:
        tasks[0]()
        return
    pool = _pool(len(tasks))
    for f in [pool.submit(t) for t in tasks]:
        f.result()


def sparse_times_dense(A, X: np.ndarray) -> np.ndarray:
    """A X for a sparse A (CSR) and a dense X, C-contiguous (m × columns of X), row blocks of A
    balanced by their nonzeros over the threads; bit-identical to ``A @ X``."""
    A = sp.csr_matrix(A)
    X = np.ascontiguousarray(X, dtype=float)
    out = np.empty((A.shape[0], X.shape[1]))

    def block(rows):
        def task():
            out[rows] = A[rows] @ X
        return task

    _run(block(r) for r in _row_blocks(A.shape[0], A.indptr))
    return out


def times_transpose(A, X: np.ndarray, symmetric: bool = False) -> np.ndarray:
    """X Aᵀ = (A Xᵀ)ᵀ for a sparse A (m × n) and a dense X (p × n), C-contiguous (p × m).

    Row block by row block of X: each block is transposed into a small contiguous copy and
    multiplied by A (``csr_matvecs``), so no transpose of the whole X is ever formed. Entry
    (l, i) is Σ_j A_ij X_lj, summed in the order of A's row i: for a symmetric X the rows of
    ``A @ X``, transposed, bit for bit. ``symmetric``: X is exactly symmetric, and its column
    blocks stand for the transposed row blocks (:func:`symmetric_sandwich`)."""
    A = sp.csr_matrix(A)
    p = X.shape[0]
    out = np.empty((p, A.shape[0]))
    starts = list(range(0, p, BLOCK))
    parts = _row_blocks(len(starts), min_rows=1)

    def chunk(ids):
        def task():
            for s in starts[ids]:
                e = min(s + BLOCK, p)
                block = X[:, s:e] if symmetric else X[s:e].T
                out[s:e] = (A @ np.ascontiguousarray(block)).T
        return task

    _run(chunk(r) for r in parts)
    return out


def symmetric_sandwich(A, X: np.ndarray) -> np.ndarray:
    """A X Aᵀ for a sparse A (CSR, m × n) and a dense exactly symmetric X (n × n), C-contiguous.

    Z = X Aᵀ as :func:`times_transpose` forms it, with the column block X[:, s:e] for the
    transposed row block X[s:e]ᵀ (equal for a symmetric X; a gather of contiguous row pieces
    where the transpose is a strided copy), then A Z by :func:`sparse_times_dense`. Bit for bit
    ``A @ (A @ X).T`` (the former route: Z equals (A X)ᵀ entry by entry), at every thread
    count. The result is symmetric only to round-off."""
    return sparse_times_dense(A, times_transpose(A, X, symmetric=True))


def symmetric_pairs(flat: np.ndarray, dx: int, dy: int) -> np.ndarray:
    """G[(a, b), (a', b')] = ½ (F[a, a', b, b'] + F[a', a, b', b]) for F = ``flat`` indexed
    ((a, a'), (b, b')): the reordering and the symmetrisation ½ (G + Gᵀ) of a separable face
    series in one pass, one a at a time (whole-array transposes walk memory with stride dim²,
    ~3× slower at dim 9,216; the slab F[:, a] is first copied with its dy × dy blocks
    transposed, in cache, so both operands are read along b'), the a's split over the threads. Bit for bit ½ G + ½ Gᵀ: halving
    is exact and addition commutes."""
    F = flat.reshape(dx, dx, dy, dy)
    G = np.empty((dx, dy, dx, dy))

    def chunk(ids):
        def task():
            for a in range(ids.start, ids.stop):
                T = np.ascontiguousarray(F[:, a].transpose(0, 2, 1))   # T[a', b, b'] = F[a', a, b', b]
                np.add(F[a].transpose(1, 0, 2), T.transpose(1, 0, 2), out=G[a])
                G[a] *= 0.5
        return task

    _run(chunk(b) for b in _row_blocks(dx, min_rows=1 if G.size >= MIN_ENTRIES else dx))
    return G.reshape(dx * dy, dx * dy)


def symmetric_part(A: np.ndarray) -> np.ndarray:
    """½ (A + Aᵀ) of a square dense A, C-contiguous, row blocks over the threads: bit for bit
    ``0.5 * (A + A.T)``."""
    A = np.asarray(A, dtype=float)
    out = np.empty(A.shape)

    def block(rows):
        def task():
            np.add(A[rows], A[:, rows].T, out=out[rows])
            out[rows] *= 0.5
        return task

    _run(block(r) for r in _row_blocks(A.shape[0]))
    return out


def elementwise(f, *arrays: np.ndarray) -> np.ndarray:
    """f(*arrays) for an element-wise f of equally shaped dense arrays (numpy arithmetic),
    C-contiguous, row blocks over the threads: bit for bit ``f(*arrays)`` (each entry is the
    same operations on the same operands). For the Richardson steps of the large Gram series
    (:func:`~infsup_contact.la.richardson.extrapolate`: R = S₂ + (S₂ − S₁)/(2^p − 1) and
    R(2n) − R(n) on 4,225² matrices, single-threaded passes in numpy)."""
    arrays = [np.asarray(a, dtype=float) for a in arrays]
    out = np.empty(arrays[0].shape)

    def block(rows):
        def task():
            out[rows] = f(*(a[rows] for a in arrays))
        return task

    _run(block(r) for r in _row_blocks(out.shape[0]))
    return out


GATHER_CHUNK = 1 << 20
"""Entries per pass of :func:`signed_gather_sum` (a few MB of temporaries instead of m² per block)."""


def signed_gather_sum(blocks, index, sign) -> np.ndarray:
    """G[i, j] = Σ_c D_c[index_c[i], index_c[j]] (sign_c[i] sign_c[j]) for dense symmetric D_c
    (``blocks``), integer maps ``index`` and weights ``sign`` (0 where row i has no entry in
    block c): Σ_c Q_c D_c Q_cᵀ for bases Q_c with at most one nonzero per row (the reflections'
    isotypic bases), as gathers of row blocks over the threads. Each term multiplies D by the
    product sign_c[i] sign_c[j], which commutes, and the terms are added in the order of c: the
    result is exactly symmetric."""
    m = len(index[0])
    out = np.empty((m, m))
    chunk = max(1, GATHER_CHUNK // max(m, 1))  # rows per pass: the temporaries stay small (cache, memory)

    def block(rows):
        def task():
            for start in range(rows.start, rows.stop, chunk):
                r = slice(start, min(start + chunk, rows.stop))
                acc = out[r]
                for c, (D, idx, w) in enumerate(zip(blocks, index, sign)):
                    part = D[idx[r]][:, idx]
                    part *= w[r, None] * w[None, :]  # the product first: G stays exactly symmetric
                    if c == 0:
                        acc[...] = part
                    else:
                        acc += part
        return task

    _run(block(r) for r in _row_blocks(m))
    return out

