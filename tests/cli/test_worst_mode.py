"""``beta --worst-mode FILE``: the table it writes (segment and face), a foreign system's mode equal to
the model's it was exported from, and hostile input refused in one line naming the flag."""
import os

import numpy as np
import pandas as pd
import pytest

from tests.helpers.cli import run_in_process

BETA = ["beta", "--case", "R5.4", "--k", "1", "--N1", "4", "--N2", "4"]


def refused(argv):
    code, out, err = run_in_process(argv)
    assert code == 2 and out == "" and len(err.splitlines()) == 1 and "Traceback" not in err, (code, out, err)
    assert "--worst-mode" in err, err
    return err


def test_segment_table(tmp_path):
    path = tmp_path / "modes.csv"
    code, out, err = run_in_process([*BETA, "--case", "all", "--worst-mode", str(path)])
    assert code == 0, err
    rows = pd.read_csv(__import__("io").StringIO(out))
    modes = pd.read_csv(path)
    assert list(modes.columns) == ["case", "multiplier_mesh", "c1", "c2", "norm", "beta", "x", "mu"]
    keys = ["case", "multiplier_mesh", "c1", "c2", "norm"]
    # one mode per row of the β table, with the row's β
    joined = modes.groupby(keys, sort=False).beta.first().reset_index().merge(rows, on=keys, suffixes=("", "_row"))
    assert len(joined) == len(rows) and np.array_equal(joined.beta, joined.beta_row)
    for _, g in modes.groupby(keys):
        assert g.x.min() == 0.0 and g.x.max() == 1.0 and np.all(np.diff(g.x) > 0)  # Γ sampled, in order
        assert np.max(np.abs(g.mu)) == pytest.approx(1.0) and g.mu.max() == pytest.approx(1.0)
    assert not [p for p in tmp_path.iterdir() if p.name != "modes.csv"]  # no temporary file left


def test_face_table_has_y(tmp_path):
    path = tmp_path / "face.csv"
    code, _, err = run_in_process(["beta", "--model", "membranes3d", "--element", "tet", "--case", "T4", "--k", "2",
                                   "--N1", "2", "--N2", "2", "--norm", "L2", "--worst-mode", str(path)])
    assert code == 0, err
    modes = pd.read_csv(path)
    assert list(modes.columns) == ["case", "multiplier_mesh", "c1", "c2", "norm", "beta", "x", "y", "mu"]
    assert len(modes) == 13 ** 2 and set(np.round(modes.mu, 9)) == {-1.0, 1.0}  # the ±1 checkerboard


def test_foreign_system_mode_is_the_models(tmp_path):
    """A system exported with its multipliers described (export --norm H) gives, level by level,
    the mode of the model it came from (the same pencil, the basis from the description)."""
    out_dir = tmp_path / "export"
    for case, k in (("T3", 2), ("R5.4", 1)):
        code, _, err = run_in_process(["export", "--case", case, "--k", str(k), "--N", "4", "--norm", "H",
                                       "--out", str(out_dir), "--force"])
        assert code == 0, err
        code, _, err = run_in_process(["beta", "--system", str(out_dir / "levels.yaml"),
                                       "--worst-mode", str(tmp_path / "system.csv"), "--force"])  # the loop's own
        assert code == 0, err
        code, _, err = run_in_process(["beta", "--case", case, "--k", str(k), "--N1", "4", "--N2", "4", "--norm", "H",
                                       "--worst-mode", str(tmp_path / "model.csv"), "--force"])
        assert code == 0, err
        system, model = pd.read_csv(tmp_path / "system.csv"), pd.read_csv(tmp_path / "model.csv")
        assert list(system.columns) == ["system", "level", "h", "norm", "beta", "x", "mu"]
        assert np.array_equal(system.x, model.x)
        assert np.max(np.abs(system.mu - model.mu)) < 1e-10, case


def test_foreign_system_without_description_is_refused(tmp_path):
    out_dir = tmp_path / "export"
    code, _, err = run_in_process(["export", "--case", "T3", "--k", "1", "--N", "4", "--norm", "L2",
                                   "--out", str(out_dir)])
    assert code == 0, err
    err = refused(["beta", "--system", str(out_dir / "levels.yaml"), "--worst-mode", str(tmp_path / "m.csv")])
    assert "export --norm H" in err and "multipliers" in err
    assert not (tmp_path / "m.csv").exists()


def test_hostile_paths(tmp_path):
    refused([*BETA, "--worst-mode", str(tmp_path)])                       # a directory
    refused([*BETA, "--worst-mode", ""])                                  # empty
    blocker = tmp_path / "file"
    blocker.write_text("x")
    refused([*BETA, "--worst-mode", str(blocker / "modes.csv")])          # under a file
    manifest = tmp_path / "levels.yaml"
    code, _, err = run_in_process(["export", "--case", "T3", "--k", "1", "--N", "4", "--norm", "H",
                                   "--out", str(tmp_path / "e")])
    assert code == 0, err
    refused(["beta", "--system", str(tmp_path / "e" / "levels.yaml"),    # an input of the request
             "--worst-mode", str(tmp_path / "e" / "levels.yaml")])
    assert not manifest.exists()


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into any directory")
def test_unwritable_directory(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    refused([*BETA, "--worst-mode", str(locked / "modes.csv")])


def test_dry_run_writes_nothing(tmp_path):
    path = tmp_path / "modes.csv"
    code, out, err = run_in_process([*BETA, "--worst-mode", str(path), "--dry-run"])
    assert code == 0 and out.startswith("dry run: valid request") and not err
    assert not path.exists()
    refused([*BETA, "--worst-mode", str(tmp_path), "--dry-run"])           # still checked
