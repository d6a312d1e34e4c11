"""examples/producers/contract.py: the command line and writers every producer shares (run here
by the suite's interpreter; each producer's own tests run it under that code's interpreter)."""
from __future__ import annotations

import io
import sys
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "examples" / "producers"))
import contract  # noqa: E402

from infsup_contact.systems.levels import system_rows  # noqa: E402
from infsup_contact.systems.manifest import load_manifest  # noqa: E402

SPACES = {"P1": (1, "continuous P1")}


def _run(argv, export=lambda args: None, **limits):
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = contract.run(argv, SPACES, export, **limits)
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("argv, names", [
    ([], "--out"), (["--out", "d", "--space", "P1"], "--N"), (["--out", "d", "--space", "Q9", "--N", "4"], "--space"),
    (["--out", "d", "--space", "P1", "--N", "8", "4"], "--N"), (["--out", "d", "--space", "P1", "--N", "0"], "--N"),
    (["--out", "d", "--space", "P1", "--N", "4", "--offset", "-4"], "--N"), (["--out", "d", "--space", "P1", "--N", "x"], "--N"),
    (["--out", "d", "--space", "P1", "--N", "100000"], "--N"), (["--bogus"], "--bogus"),
])
def test_a_bad_command_line_is_one_line_naming_the_flag(tmp_path, argv, names):
    argv = [str(tmp_path / a) if a == "d" else a for a in argv]
    code, out, err = _run(argv)
    assert code == 2 and out == "" and len(err.splitlines()) == 1 and names in err, err


def test_offsets_a_producer_cannot_mesh_are_refused_with_its_reason(tmp_path):
    code, _, err = _run(["--out", str(tmp_path / "d"), "--space", "P1", "--N", "4", "--offset", "1"],
                        offsets=(0,), offset_reason="matching meshes only")
    assert code == 2 and "--offset 1: matching meshes only" in err


def test_another_system_is_not_overwritten(tmp_path):
    (tmp_path / "levels.yaml").write_text("levels: []\n")
    code, _, err = _run(["--out", str(tmp_path), "--space", "P1", "--N", "4"])
    assert code == 2 and "holds a system already" in err and (tmp_path / "levels.yaml").read_text() == "levels: []\n"


def test_list_spaces_is_the_only_stdout():
    code, out, err = _run(["--list-spaces"], describe=lambda spec: spec[1])
    assert code == 0 and out == "P1\tcontinuous P1\n" and err == ""


def test_the_writers_give_a_manifest_the_certifier_reads(tmp_path):
    """Three levels of a P1 multiplier on the segment (A = 2I, B = [I 0], G = the P1 mass as
    described): the manifest written is read and checked by the certifier's own loader."""
    def export(args):
        levels = []
        for n in args.N:
            m = n + 1
            A, B = 2.0 * sp.identity(2 * m), sp.hstack([sp.identity(m), sp.csr_matrix((m, m))])
            h = 1.0 / n
            G = sp.diags([h / 6 * np.ones(m - 1), np.r_[h / 3, 2 * h / 3 * np.ones(m - 2), h / 3], h / 6 * np.ones(m - 1)],
                         [-1, 0, 1])
            desc = {"basis": "lagrange", "degree": 1, "breakpoints": np.linspace(0, 1, n + 1).tolist(), "ends": "keep"}
            levels.append(contract.level_entry(args.out, n, A, B, G, desc))
        return contract.write_manifest(args.out, "fake P1", levels)

    code, out, err = _run(["--out", str(tmp_path / "sys"), "--space", "P1", "--N", "4", "8", "16"], export)
    assert code == 0 and out == "", err
    m = load_manifest(tmp_path / "sys" / "levels.yaml")
    assert m.norm == "H" and [lv.h for lv in m.levels] == [0.25, 0.125, 0.0625]
    assert not list((tmp_path / "sys").glob(".*tmp*"))  # atomic writes leave no temporary files
    rows = system_rows(m, notes=io.StringIO())  # G against the description's L2 mass: the rows' order
    assert [r["m"] for r in rows] == [5, 9, 17] and all(r["beta"] > 0 for r in rows)
