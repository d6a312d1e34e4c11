"""Multiplier spaces side by side (solvers/side_by_side.py): two at a time give the rows and worst
modes of one space at a time, bit for bit, on the face and on the segment; the shared caches are
filled once; the memory rule says one at a time where two working sets do not fit."""
import contextlib
import os
import signal
import sys
import threading
import time

import numpy as np
import pandas as pd
import pytest

from infsup_contact import progress
from infsup_contact.errors import InputError
from infsup_contact.la import bottom, openblas, threaded
from infsup_contact.models.membranes import MEMBRANES
from infsup_contact.models.membranes3d import MEMBRANES3D
from infsup_contact.solvers import infsup, side_by_side
from infsup_contact.solvers.infsup import beta_table
from infsup_contact.solvers.request import BetaRequest, MeshOptions
from infsup_contact.solvers.side_cache import SideCache

CASE_ROWS = infsup._case_rows_and_modes


@pytest.fixture
def one_blas_thread(monkeypatch):
    """MKL and OpenBLAS on one thread for the test: the rows are those of one space at a time, bit
    for bit, at one BLAS thread (a serial reference on two MKL threads, MKL_NUM_THREADS=2 in the
    environment, rounds otherwise)."""
    mkl_before, blas_before = threaded.threads(), openblas.threads_now()
    monkeypatch.setenv("MKL_NUM_THREADS", str(mkl_before))  # the variable itself restored after the test
    threaded.use_threads(1)
    openblas.set_threads(1)
    yield
    threaded.use_threads(mkl_before)
    openblas.set_threads(max(blas_before.values(), default=1))


def _run(monkeypatch, request, workers, processes=False, log=None):
    """(rows, worst modes, where the cases ran, Gram cache) with ``workers`` spaces at a time, in
    threads (their names) or in worker processes (``processes``: their ids, through the file ``log``)."""
    monkeypatch.setattr(side_by_side, "space_workers", lambda dim, n, available=None: workers)
    seen = set()

    def recording(*args, **kwargs):
        if processes:
            with open(log, "a") as f:
                f.write(f"{os.getpid()}\n")
        seen.add(threading.current_thread().name)
        return CASE_ROWS(*args, **kwargs)

    monkeypatch.setattr(infsup, "_case_rows_and_modes", recording)
    cache, modes = SideCache(), []
    with side_by_side.worker_processes() if processes else contextlib.nullcontext():
        rows = beta_table(request, cache, modes=modes)
    if processes:
        with open(log) as f:
            seen = set(f.read().split())
    return pd.DataFrame(rows), modes, seen, cache.grams


def _assert_bitwise(rows, modes, serial, serial_modes):
    """The rows (timings aside) and worst modes of a route, bit for bit those of one space at a time."""
    cols = [c for c in serial.columns if not c.startswith("t_")]
    pd.testing.assert_frame_equal(rows[cols], serial[cols], check_exact=True)
    assert [m.keys for m in modes] == [m.keys for m in serial_modes]
    for a, b in zip(modes, serial_modes):
        assert a.beta == b.beta and a.in_kernel == b.in_kernel
        np.testing.assert_array_equal(a.vector, b.vector)


@pytest.mark.parametrize("model, k, n, mesh, dense_max", [
    (MEMBRANES3D, 2, 4, MeshOptions(element="hex"), None),
    (MEMBRANES3D, 2, 4, MeshOptions(element="hex"), 20),  # the large route: Lanczos, split, bottom kernel
    (MEMBRANES3D, 1, 3, MeshOptions(element="tet"), None),
    (MEMBRANES, 2, 6, MeshOptions(), None),
])
def test_two_spaces_at_a_time_give_the_rows_and_modes_of_one_at_a_time_bitwise(monkeypatch, one_blas_thread, model,
                                                                                 k, n, mesh, dense_max):
    if dense_max is not None:
        monkeypatch.setattr(bottom, "DENSE_MAX_M", dense_max)
    request = BetaRequest("structured", k, n, n, None, ("omega2", "union"), ((1.0, 1.0), (1.0, 10.0)),
                          ("H", "L2"), "logkernel", model, mesh)
    serial, serial_modes, serial_threads, serial_grams = _run(monkeypatch, request, 1)
    both, both_modes, both_threads, both_grams = _run(monkeypatch, request, 2)
    assert serial_threads == {threading.main_thread().name}
    assert any(name.startswith("infsup-concurrent") for name in both_threads)  # the route under test ran
    _assert_bitwise(both, both_modes, serial, serial_modes)
    assert len(both_grams) == len(serial_grams) and both_grams.hits == serial_grams.hits  # each Gram once


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="worker processes are forked (Linux)")
@pytest.mark.parametrize("model, k, n, mesh, dense_max", [
    (MEMBRANES3D, 2, 4, MeshOptions(element="hex"), None),
    (MEMBRANES3D, 2, 4, MeshOptions(element="hex"), 20),  # the large route: Lanczos, split, bottom kernel
    (MEMBRANES3D, 1, 3, MeshOptions(element="tet"), None),
])
def test_spaces_in_worker_processes_give_the_rows_and_modes_of_one_at_a_time_bitwise(monkeypatch, one_blas_thread,
                                                                                     tmp_path, model, k, n, mesh,
                                                                                     dense_max):
    if dense_max is not None:
        monkeypatch.setattr(bottom, "DENSE_MAX_M", dense_max)
    request = BetaRequest("structured", k, n, n, None, ("omega2", "union"), ((1.0, 1.0), (1.0, 10.0)),
                          ("H", "L2"), "logkernel", model, mesh)
    serial, serial_modes, _, _ = _run(monkeypatch, request, 1)
    both, both_modes, pids, _ = _run(monkeypatch, request, 2, processes=True, log=tmp_path / "pids")
    assert pids and str(os.getpid()) not in pids  # every space in a worker, none here
    _assert_bitwise(both, both_modes, serial, serial_modes)


def _burn(seconds):
    """Spend ``seconds`` of this process's CPU."""
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="worker processes are forked (Linux)")
def test_worker_processes_return_rows_in_order_raise_errors_whole_and_count_their_cpu(monkeypatch):
    monkeypatch.setattr(side_by_side, "space_workers", lambda dim, n, available=None: 2)

    def rows_of(case):
        if case == "bad":
            raise InputError("case", "a good one", got=case)
        if case == "die":
            os.kill(os.getpid(), signal.SIGKILL)
        _burn(0.2)
        return [case, os.getpid()]

    with side_by_side.worker_processes(), progress.timing() as phases:
        rows = side_by_side.rows_by_case(["a", "b", "c", "d"], rows_of, 10, python_bound=True)
    assert [r[0] for r in rows] == ["a", "b", "c", "d"]
    assert os.getpid() not in {r[1] for r in rows}  # every space in a worker, none alone first
    assert phases[side_by_side.PHASE][1] >= 4 * 0.2 * 0.9  # the workers' CPU counted in the phase
    with side_by_side.worker_processes(), pytest.raises(InputError, match="invalid case") as err:
        side_by_side.rows_by_case(["a", "bad", "b"], rows_of, 10, python_bound=True)
    assert err.value.key == "case" and err.value.got == "bad"  # the worker's error, whole
    with side_by_side.worker_processes(), pytest.raises(RuntimeError, match="worker process .* died"):
        side_by_side.rows_by_case(["a", "b", "die", "c"], rows_of, 10, python_bound=True)
    with side_by_side.worker_processes():  # the segment's cheap spaces, large spaces: threads
        assert not side_by_side.processes_allowed(10, python_bound=False)
        assert not side_by_side.processes_allowed(side_by_side.PROCESSES_MAX_DIM + 1, python_bound=True)
        assert side_by_side.processes_allowed(side_by_side.PROCESSES_MAX_DIM, python_bound=True)
    monkeypatch.setenv("INFSUP_SPACE_PROCESSES", "0")
    with side_by_side.worker_processes():
        assert not side_by_side.processes_allowed(10, python_bound=True)
        assert {r[1] for r in side_by_side.rows_by_case(["a", "b", "c"], rows_of, 10, python_bound=True)} == {os.getpid()}
    monkeypatch.delenv("INFSUP_SPACE_PROCESSES")
    assert not side_by_side.processes_allowed(10, python_bound=True)  # outside the block: threads


def test_spaces_run_one_at_a_time_where_two_working_sets_do_not_fit(monkeypatch):
    monkeypatch.setattr(threaded, "threads", lambda: 2)
    monkeypatch.setattr(side_by_side, "threads", lambda: 2)
    dim = 9025  # dim(W1 + W2) at k = 2, N = 48 on the face
    two = 2 * side_by_side.working_set(dim)
    assert side_by_side.space_workers(dim, 11, available=two / side_by_side.MEMORY_SHARE) == 2
    assert side_by_side.space_workers(dim, 11, available=0.99 * two / side_by_side.MEMORY_SHARE) == 1
    assert side_by_side.space_workers(dim, 1, available=1e15) == 1  # one space: nothing beside it
    monkeypatch.setattr(side_by_side, "threads", lambda: 1)
    assert side_by_side.space_workers(dim, 11, available=1e15) == 1  # one thread asked: one space


def test_a_failing_space_raises_after_the_others_ran(monkeypatch):
    monkeypatch.setattr(side_by_side, "space_workers", lambda dim, n, available=None: 2)
    done = []

    def rows_of(case):
        if case == "bad":
            raise ValueError("bad space")
        done.append(case)
        return [case]

    with pytest.raises(ValueError, match="bad space"):
        side_by_side.rows_by_case(["a", "bad", "b", "c"], rows_of, 10)
    assert sorted(done) == ["a", "b", "c"]
    assert side_by_side.rows_by_case(["a", "b", "c"], lambda c: [c], 10) == [["a"], ["b"], ["c"]]


def test_spaces_sharing_a_series_form_one_task_longest_first():
    series = {"a": None, "q9": "Q9", "b": None, "q9-all": "Q9", "pw": "P1", "t-q9": "Q9", "x": "X", "x2": "X"}
    cases = list(series)
    tasks = side_by_side.chains(cases, series.get)
    assert tasks == [[1, 3, 5], [6, 7], [0], [2], [4]]  # the shared ones first, longest first; then alone
    assert sorted(i for t in tasks for i in t) == list(range(len(cases)))  # every case once
    assert side_by_side.chains(cases) == [[i] for i in range(len(cases))]  # no keys: each case alone


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="worker processes are forked (Linux)")
def test_a_series_runs_in_one_worker_and_a_failure_in_it_raises_in_the_cases_order(monkeypatch):
    monkeypatch.setattr(side_by_side, "space_workers", lambda dim, n, available=None: 2)

    def rows_of(case):
        if case.startswith("bad"):
            raise InputError("case", "a good one", got=case)
        _burn(0.05)
        return [case, os.getpid()]

    series = {"a": None, "s1": "S", "b": None, "s2": "S", "c": None, "s3": "S"}
    with side_by_side.worker_processes():
        rows = side_by_side.rows_by_case(list(series), rows_of, 10, python_bound=True, series=series.get)
    assert [r[0] for r in rows] == list(series)  # the cases' order
    assert len({r[1] for r in rows if series[r[0]]}) == 1 and os.getpid() not in {r[1] for r in rows}
    bad = {"a": None, "s1": "S", "bad-s2": "S", "bad-b": None, "s3": "S"}
    with side_by_side.worker_processes(), pytest.raises(InputError, match="bad-s2") as err:
        side_by_side.rows_by_case(list(bad), rows_of, 10, python_bound=True, series=bad.get)
    assert err.value.key == "case"  # the first failing case in the cases' order, whole
