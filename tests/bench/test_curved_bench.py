"""``bench --what arc`` (bench/curved.py): every route once per pair, ratios against the limit and the
exact coupling, β on the arc close to the flat one; bad flags one line."""
from __future__ import annotations

import io

import numpy as np
import pandas as pd
import pytest

from helpers.cli import run_in_process

from infsup_contact.bench.curved import COLUMNS, curved_rows


def test_every_route_has_its_ratios():
    rows = pd.DataFrame(curved_rows([4], [1], radius=4.0, repeats=1), columns=list(COLUMNS))
    assert list(rows.route) == ["limit", "flat", "exact", "projection", "couplings_exact", "couplings_projection"]
    assert (rows.seconds_median > 0).all() and np.isfinite(rows.ratio_to_limit).all()
    assert rows.set_index("route").ratio_to_limit["limit"] == 1.0
    # R = 4 moves β by O(1/R), not more: the same problem, curved
    diffs = rows.set_index("route").max_abs_diff_to_flat
    assert diffs["flat"] == 0.0 and 0.0 < diffs["exact"] < 0.05 and 0.0 < diffs["projection"] < 0.05


def test_the_command_writes_the_table():
    code, out, err = run_in_process(["bench", "--what", "arc", "--N", "4", "--k", "1", "--repeats", "1"])
    assert code == 0, err
    assert list(pd.read_csv(io.StringIO(out)).columns) == list(COLUMNS)


@pytest.mark.parametrize("argv, flag", [(["--radius", "1"], "--radius"), (["--radius", "inf"], "--radius"),
                                        (["--radius", "nan"], "--radius"), (["--element", "hex"], "--element")])
def test_bad_flags_are_one_line(argv, flag):
    code, out, err = run_in_process(["bench", "--what", "arc", "--N", "4", "--k", "1", *argv])
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and flag in err, err
