"""Hints on the ``--system`` path where the numbers suggest a mistake in the export or in the
levels (systems/hints.py): a mesh-dependent scale factor on B or G, a transposed B, a kernel
only on the coarse levels, levels too coarse or too few for the verdict. A hint goes to the
verdict row's ``hints`` column and to stderr; it changes no verdict."""
from __future__ import annotations

import csv
import io
import re

import numpy as np
import pytest

from infsup_contact.cli import main
from infsup_contact.study.verdict import verdict_rows
from infsup_contact.systems.export import suite_system, write_system
from infsup_contact.systems.hints import MIN_PER_DIRECTION, coarse_levels_hint
from infsup_contact.systems.levels import system_verdict
from infsup_contact.systems.manifest import load_manifest

CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
FINE = (8, 16, 32)  # T3, k = 2: STABLE on these (15, 31, 63 multipliers)


def _manifest(tmp_path, case, k, ns, offset=0, scale_b=None, scale_g=None, transpose=False, fmt="mtx"):
    levels = []
    for n in ns:
        A, B, G = suite_system(case, k, n + offset, n)
        h = 1.0 / n
        B = B * scale_b(h) if scale_b else B
        G = G * scale_g(h) if scale_g else G
        levels.append((h, A, B.T.tocsr() if transpose else B, G))
    return load_manifest(write_system(tmp_path, levels, fmt, f"{case}-k{k}"))


def _verdict(manifest):
    notes = io.StringIO()
    out, _ = system_verdict(manifest, **CRITERION, notes=notes)
    return out, notes.getvalue()


def test_stable_fine_levels_get_no_hint(tmp_path):
    out, err = _verdict(_manifest(tmp_path, "T3", 2, FINE))
    assert out["verdict"] == "STABLE" and out["hints"] == "" and "hint" not in err


@pytest.mark.parametrize("scale, power", [("B", -1.0), ("G", -0.5)])
def test_mesh_dependent_scale_gets_the_scale_hint(tmp_path, scale, power):
    """B·(1/h) scales every β_h by 1/h, G·h by h^(-1/2): the slope of log β_h shifts by exactly
    −1 or −1/2 (checked against the unscaled export to 1e-9), and the hint names the factor."""
    plain, _ = _verdict(_manifest(tmp_path / "plain", "T3", 2, FINE))
    kw = {"scale_b": lambda h: 1.0 / h} if scale == "B" else {"scale_g": lambda h: h}
    out, err = _verdict(_manifest(tmp_path / "scaled", "T3", 2, FINE, **kw))
    assert abs(out["slope"] - (plain["slope"] + power)) <= 1e-9
    assert out["verdict"] == "UNSTABLE"  # the criterion is not changed by a hint
    assert "scaled by a mesh-dependent factor (E/h, say)?" in out["hints"]
    assert f"slope {out['slope']:.2f} of log β_h vs log h ≈ {power:g}" in out["hints"]
    assert f"infsup-contact: hint: β_h grows under refinement (slope {out['slope']:.2f}" in err


def test_scale_hint_through_the_cli(tmp_path, capfd):
    _manifest(tmp_path, "T3", 2, FINE, scale_b=lambda h: 1.0 / h)
    assert main(["verdict", "--system", str(tmp_path / "levels.yaml"), "--expect", "stable"]) == 1
    captured = capfd.readouterr()
    row, = csv.DictReader(io.StringIO(captured.out))
    assert "mesh-dependent factor" in row["hints"]
    assert re.search(r"^infsup-contact: hint: β_h grows under refinement \(slope -0\.9\d", captured.err, re.M)


@pytest.mark.parametrize("fmt", ["mtx", "npz"])
@pytest.mark.parametrize("dry_run", [False, True])
def test_transposed_b_gets_the_transposition_hint(tmp_path, capsys, fmt, dry_run):
    _manifest(tmp_path, "T3", 2, (4, 8, 16), transpose=True, fmt=fmt)
    code = main(["verdict", "--system", str(tmp_path / "levels.yaml")] + (["--dry-run"] if dry_run else []))
    captured = capsys.readouterr()
    assert code == 2 and captured.out == "" and len(captured.err.strip().splitlines()) == 1
    n = suite_system("T3", 2, 4, 4)[0].shape[0]  # level 0: n dofs, m = 2N − 1 = 7 multipliers
    assert f"B is {n} x 7" in captured.err
    assert f"hint: B appears transposed: give B as m x n (7 x {n}" in captured.err


def test_a_b_that_fits_in_no_orientation_gets_no_transposition_hint(tmp_path, capsys):
    levels = [(1.0 / n, A, B[:, :-1], G) for n in (4, 8, 16) for A, B, G in [suite_system("T3", 2, n, n)]]
    write_system(tmp_path, levels, "mtx", "cut")  # B a column short on every level
    code = main(["verdict", "--system", str(tmp_path / "levels.yaml")])
    err = capsys.readouterr().err
    n = levels[0][1].shape[0]
    assert code == 2 and f"B is 7 x {n - 1}" in err and "transposed" not in err


def test_kernel_only_on_the_coarse_levels_gets_the_vanishing_kernel_hint(tmp_path):
    """R5.2, k = 1, N1 = N − 1 on N = 2, 3, 4: a kernel of dims [2, 1, 0] (m − dim W of the
    pair), UNSTABLE by the criterion, and a hint that the fine level has none."""
    out, err = _verdict(_manifest(tmp_path, "R5.2", 1, (2, 3, 4), offset=-1))
    assert out["verdict"] == "UNSTABLE"
    assert "the kernel of B^T shrinks under refinement (dims [2, 1, 0] over 1/h = 2, 3, 4)" in out["hints"]
    assert "gone from h = 0.25 on" in err
    assert "drop them and add at least 2 level(s) finer than h = 0.25" in out["hints"]  # 3 without a kernel


def test_coarse_non_matching_levels_get_the_coarse_levels_hint(tmp_path):
    """T3, k = 1, N1 = N + 1 on N = 2, 3, 4 (stable: STABLE on N = 16 … 128, below): the coarse
    pairs give a slope of 0.32 and UNSTABLE; the hint names the levels and the h from which
    there are MIN_PER_DIRECTION multipliers per direction: m = N − 1 = 3 at h = 1/4, so
    h = (1/4)·3/8 = 0.09375."""
    out, err = _verdict(_manifest(tmp_path / "coarse", "T3", 1, (2, 3, 4), offset=1))
    assert out["verdict"] == "UNSTABLE" and out["kernel_dim"] == 0
    assert "the levels h = [0.5, 0.333333, 0.25] have about [1, 2, 3] multipliers per direction" in out["hints"]
    assert f"fewer than {MIN_PER_DIRECTION}" in out["hints"]
    assert "give at least 3 levels at or below h = 0.0938" in out["hints"]
    fine = verdict_rows("T3", 1, "structured", (16, 32, 64, 128), "H", n1_offset=1, **CRITERION)
    assert fine["verdict"] == "STABLE"  # the levels the hint asks for decide the other way


def test_inconclusive_on_fine_levels_counts_the_levels_to_add():
    """Synthetic: three fine levels (16, 32, 64 multipliers per direction, none coarse) and a
    scattered slope: the hint asks for a number of further levels, more for more scatter."""
    h = np.array([1 / 16, 1 / 32, 1 / 64])
    m = 1 / h
    counts = []
    for wobble in (0.02, 0.05):
        y = np.exp(np.array([0.0, wobble, -wobble]) + 0.05 * np.log(h))
        slope = np.polyfit(np.log(h), np.log(y), 1)[0]
        out = dict(verdict="INCONCLUSIVE", slope=slope, slope_lo=-1.0, slope_hi=1.0)
        text = coarse_levels_hint(h, m, y, out, 0.15, 0.95)
        assert "multipliers per direction" not in text
        counts.append(int(re.search(r"add about (\d+) level\(s\) finer than h = 0.015625", text).group(1)))
    assert 1 <= counts[0] < counts[1]
