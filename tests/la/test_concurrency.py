"""Threads of a request (la/threaded.py): the decision from the environment and the idle cores,
and run_concurrently (the same results as serial, failures raised, no oversubscription)."""
import threading

import numpy as np
import pytest

from infsup_contact.cli import _fit_blas_threads, _threads_default
from infsup_contact import memory
from infsup_contact.la import openblas, threaded


@pytest.mark.parametrize("environ,asked", [({}, None), ({"MKL_NUM_THREADS": "3"}, 3),
                                           ({"OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "4"}, 2),
                                           ({"OMP_NUM_THREADS": "4"}, 4), ({"MKL_NUM_THREADS": "junk"}, 1),
                                           ({"MKL_NUM_THREADS": "", "OPENBLAS_NUM_THREADS": "1"}, 1),
                                           ({"MKL_NUM_THREADS": "0"}, 1)])
def test_the_environment_fixes_the_count_or_leaves_it_open(environ, asked):
    assert threaded.asked_threads(environ) == asked


@pytest.mark.parametrize("asked,cpus,idle,used", [
    (None, 2, 2.0, 2), (None, 2, 1.0, 1), (None, 2, None, 2), (None, 8, 3.7, 3),   # nobody chose: the idle cores
    (1, 2, 2.0, 1), (2, 2, 0.5, 1), (4, 2, None, 4), (None, 1, 1.0, 1)])          # asked: never more (the guard)
def test_threads_of_a_request(asked, cpus, idle, used):
    assert threaded.decide_threads(asked, cpus, idle) == used


def _with_cli_threads(monkeypatch, environ, idle):
    """The CLI's two steps (before numpy, after the checks) under ``environ``; the threads after."""
    for var in threaded.THREAD_VARIABLES:
        monkeypatch.delenv(var, raising=False)
    for var, value in environ.items():
        monkeypatch.setenv(var, value)
    monkeypatch.setattr(openblas, "idle_cores", lambda *a, **k: idle)
    monkeypatch.setattr(openblas.os, "sched_getaffinity", lambda pid: {0, 1})
    before = openblas.threads_now()
    openblas.set_threads(1)  # as OpenBLAS starts after _threads_default: one thread
    try:
        _threads_default()
        _fit_blas_threads()
        return threaded.threads(), openblas.threads_now()
    finally:
        openblas.set_threads(max(before.values()))


def test_a_request_alone_gets_both_cores_side_by_side_one(monkeypatch):
    """MKL, the threaded products and the tasks take the idle cores; OpenBLAS keeps its one thread
    (it spins: threaded.use_threads); a count in the environment is kept (a Snakemake job's 1)."""
    assert _with_cli_threads(monkeypatch, {}, 2.0) == (2, {"numpy": 1, "scipy": 1})
    assert _with_cli_threads(monkeypatch, {}, 0.9) == (1, {"numpy": 1, "scipy": 1})      # a busy core
    assert _with_cli_threads(monkeypatch, {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}, 2.0) == \
        (1, {"numpy": 1, "scipy": 1})
    monkeypatch.setenv("INFSUP_BLAS_FIT", "0")                                          # the cores, not fitted
    assert _with_cli_threads(monkeypatch, {}, 0.0) == (2, {"numpy": 1, "scipy": 1})


def test_freed_memory_is_reused_unless_malloc_is_configured(monkeypatch):
    monkeypatch.setenv("MALLOC_ARENA_MAX", "2")
    assert memory.reuse_freed_memory() is False
    monkeypatch.delenv("MALLOC_ARENA_MAX")
    for var in [v for v in memory.os.environ if v.startswith("MALLOC_")]:
        monkeypatch.delenv(var)
    assert memory.reuse_freed_memory() is True                                        # glibc (Linux)


def test_concurrent_results_are_the_serial_ones_in_order():
    rng = np.random.default_rng(0)
    mats = [rng.standard_normal((120, 120)) for _ in range(5)]
    tasks = [lambda M=M: np.linalg.eigvalsh(M + M.T) for M in mats]
    serial = [t() for t in tasks]
    got = threaded.run_concurrently(tasks, workers=2)
    assert all(np.array_equal(a, b) for a, b in zip(got, serial))
    assert threaded.run_concurrently([], workers=2) == []
    assert threaded.concurrent_map(lambda x: x * x, range(5)) == [0, 1, 4, 9, 16]


def test_tasks_run_side_by_side_with_one_blas_thread_each(monkeypatch):
    """Two tasks that wait for each other finish only if they run at the same time; inside them
    the products of la.threaded and OpenBLAS run one thread, and the count is back after."""
    monkeypatch.setenv("MKL_NUM_THREADS", "2")
    before = openblas.threads_now()
    openblas.set_threads(2)
    barrier = threading.Barrier(2, timeout=10)
    try:
        def task():
            barrier.wait()
            return threaded.threads(), set(openblas.threads_now().values())
        assert threaded.run_concurrently([task, task]) == [(1, {1}), (1, {1})]
        assert set(openblas.threads_now().values()) == {2} and threaded.threads() == 2
    finally:
        openblas.set_threads(max(before.values()))


def test_nested_calls_run_in_turn_and_one_worker_is_serial():
    seen = []

    def outer():
        return threaded.run_concurrently([lambda: threading.current_thread().name, lambda: 2], workers=2)
    inner = threaded.run_concurrently([outer, outer], workers=2)
    assert all(r[1] == 2 and r[0].startswith("infsup-concurrent") for r in inner)  # not a third thread
    threaded.run_concurrently([lambda: seen.append(threading.current_thread().name)], workers=4)
    assert seen == [threading.current_thread().name]


def test_every_task_runs_then_the_first_failure_is_raised():
    done = []

    def fail(msg):
        def task():
            done.append(msg)
            raise ValueError(msg)
        return task
    with pytest.raises(ValueError, match="first"):
        threaded.run_concurrently([lambda: done.append("ok"), fail("first"), fail("second")], workers=2)
    assert sorted(done) == ["first", "ok", "second"]


def test_pardiso_schur_complements_side_by_side_are_the_serial_ones(monkeypatch):
    """PARDISO releases the GIL and keeps its state per handle: two bodies' Schur complements
    computed side by side (one MKL thread each) are bit for bit those computed in turn."""
    import scipy.sparse as sp

    from infsup_contact.la import pardiso

    if not pardiso.available():
        pytest.skip("MKL (PARDISO) not loaded")
    monkeypatch.setenv("MKL_NUM_THREADS", "2")

    def body(n, shift):
        T = sp.diags([-1.0, 2.0 + shift, -1.0], [-1, 0, 1], shape=(n, n))
        return sp.csr_matrix(sp.kronsum(T, T))
    bodies = [(body(40, 0.0), 40), (body(36, 0.1), 36)]
    tasks = [lambda A=A, g=g: pardiso.gamma_schur(A, g) for A, g in bodies]
    serial = [t() for t in tasks]
    together = threaded.run_concurrently(tasks)
    assert all(np.array_equal(a, b) for a, b in zip(together, serial))


@pytest.mark.parametrize("estimate_gb, available_gb, bounded", [(1, 8, False), (4, 8, False), (5, 8, True),
                                                                (23, 16, True)])
def test_freed_memory_is_kept_for_the_whole_request_only_where_memory_is_plentiful(monkeypatch, estimate_gb,
                                                                                   available_gb, bounded):
    """The command line keeps freed memory for reuse (a higher peak) for the whole request when the
    estimated peak is at most half the available memory, else within a stage only (bounded)."""
    from infsup_contact import cli, resources

    calls = []
    monkeypatch.setattr(memory, "reuse_freed_memory", lambda bounded=False: calls.append(bounded) or True)
    monkeypatch.setattr(resources, "available_bytes", lambda *a: available_gb * 1e9)
    cli._reuse_freed_memory(resources.Estimate(estimate_gb * 1e9, 1.0))
    assert calls == [bounded]


def test_bounded_reuse_gives_freed_memory_back_at_a_stages_end(monkeypatch):
    for var in [v for v in memory.os.environ if v.startswith("MALLOC_")]:
        monkeypatch.delenv(var)
    monkeypatch.setattr(memory, "_bounded_reuse", False)
    released = []
    libc = type("Libc", (), {"malloc_trim": staticmethod(released.append), "mallopt": staticmethod(lambda p, v: 1)})
    monkeypatch.setattr("ctypes.CDLL", lambda name: libc())      # glibc's calls recorded, not made
    memory.release_freed_memory()
    assert released == []                                         # glibc's default or unbounded reuse: nothing
    assert memory.reuse_freed_memory(bounded=True) is True
    memory.release_freed_memory()
    assert released == [0]
