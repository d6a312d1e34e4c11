"""Multiplier spaces side by side (solvers/side_by_side.py): two at a time give the rows and worst
modes of one space at a time, bit for bit, on the face and on the segment; the shared caches are
filled once; the memory rule says one at a time where two working sets do not fit."""
import threading

import numpy as np
import pandas as pd
import pytest

from infsup_contact.la import bottom, threaded
from infsup_contact.models.membranes import MEMBRANES
from infsup_contact.models.membranes3d import MEMBRANES3D
from infsup_contact.solvers import infsup, side_by_side
from infsup_contact.solvers.infsup import beta_table
from infsup_contact.solvers.request import BetaRequest, MeshOptions
from infsup_contact.solvers.side_cache import SideCache

CASE_ROWS = infsup._case_rows_and_modes


def _run(monkeypatch, request, workers):
    """(rows, worst modes, names of the threads the cases ran in, Gram cache) with ``workers``
    spaces at a time."""
    monkeypatch.setattr(side_by_side, "space_workers", lambda dim, n, available=None: workers)
    seen = set()

    def recording(*args, **kwargs):
        seen.add(threading.current_thread().name)
        return CASE_ROWS(*args, **kwargs)

    monkeypatch.setattr(infsup, "_case_rows_and_modes", recording)
    cache, modes = SideCache(), []
    rows = beta_table(request, cache, modes=modes)
    return pd.DataFrame(rows), modes, seen, cache.grams


@pytest.mark.parametrize("model, k, n, mesh, dense_max", [
    (MEMBRANES3D, 2, 4, MeshOptions(element="hex"), None),
    (MEMBRANES3D, 2, 4, MeshOptions(element="hex"), 20),  # the large route: Lanczos, split, bottom kernel
    (MEMBRANES3D, 1, 3, MeshOptions(element="tet"), None),
    (MEMBRANES, 2, 6, MeshOptions(), None),
])
def test_two_spaces_at_a_time_give_the_rows_and_modes_of_one_at_a_time_bitwise(monkeypatch, model, k, n, mesh,
                                                                                 dense_max):
    if dense_max is not None:
        monkeypatch.setattr(bottom, "DENSE_MAX_M", dense_max)
    request = BetaRequest("structured", k, n, n, None, ("omega2", "union"), ((1.0, 1.0), (1.0, 10.0)),
                          ("H", "L2"), "logkernel", model, mesh)
    serial, serial_modes, serial_threads, serial_grams = _run(monkeypatch, request, 1)
    both, both_modes, both_threads, both_grams = _run(monkeypatch, request, 2)
    assert serial_threads == {threading.main_thread().name}
    assert any(name.startswith("infsup-concurrent") for name in both_threads)  # the route under test ran
    cols = [c for c in serial.columns if not c.startswith("t_")]
    pd.testing.assert_frame_equal(both[cols], serial[cols], check_exact=True)
    assert [m.keys for m in both_modes] == [m.keys for m in serial_modes]
    for a, b in zip(both_modes, serial_modes):
        assert a.beta == b.beta and a.in_kernel == b.in_kernel
        np.testing.assert_array_equal(a.vector, b.vector)
    assert len(both_grams) == len(serial_grams) and both_grams.hits == serial_grams.hits  # each Gram once


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
