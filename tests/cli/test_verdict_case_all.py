"""``verdict --case`` and ``export`` take every registered space a model builds (the segment's
and, on a 3D model, the face-only spaces of its element), non-matching series (``--N1-offset``),
and name the model, element and offset in the verdict row; an impossible combination is one
line naming the key and the values allowed for that model, element and k."""
from __future__ import annotations

import csv
import io

import numpy as np
import pytest

from infsup_contact.cli import main
from infsup_contact.discretization.spaces.registry import common_ids, ids_built_on, SPACES
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.models import MODELS
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.request import MeshOptions
from infsup_contact.systems.levels import system_verdict
from infsup_contact.systems.manifest import load_manifest

CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
GRID = TensorPartition(np.linspace(0, 1, 3), np.linspace(0, 1, 3))


def _face_only(element, k):
    """The face-only registered ids the element's face builds at degree k (an entry refusing its
    construction, e.g. a dual basis with a weight <= 0, left out): from the registry, not a list."""
    gamma = SQUARE if element == "hex" else SQUARE_TRIG
    return {c for c in ids_built_on(k, gamma, GRID) if not SPACES[c].defined_on(1)}


def _run(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def _row(out):
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == 1
    return rows[0]


def test_acceptance_face_only_space_on_hexahedra(capsys):
    code, out, err = _run(capsys, ["verdict", "--model", "membranes3d", "--element", "hex", "--case", "DUAL-Q9",
                                   "--k", "2", "--N", "2", "3", "4"])
    assert code == 0, err
    row = _row(out)
    assert (row["space"], row["model"], row["element"], row["N1_offset"]) == ("DUAL-Q9", "membranes3d", "hex", "0")
    assert row["kernel_dim"] == "0" and float(row["beta_min"]) > 0.5  # a stable space: no kernel, β_h ~ 1
    assert row["verdict"] in ("STABLE", "INCONCLUSIVE")  # three coarse meshes: the CI may be wide


def _expected_ids(model, element, k):
    segment = set(common_ids(k))
    return segment if model.dim == 2 else segment | _face_only(element, k)


SETTINGS = [(name, el) for name, m in MODELS.items() for el in (("hex", "tet") if m.dim == 3 else (None,))]


@pytest.mark.parametrize("model_name, element", SETTINGS, ids=[f"{m}-{e or '2d'}" for m, e in SETTINGS])
def test_every_registered_id_accepted_or_refused_in_one_line(tmp_path, capsys, model_name, element):
    """Every registered id × k = 1, 2 on each model and element: ``verdict --dry-run`` and
    ``export --dry-run`` accept exactly the spaces the model builds; the rest exit 2 with one
    line naming --case (listing the allowed ids) or --k."""
    model = MODELS[model_name]
    flags = ["--model", model_name] + (["--element", element] if element else [])
    for k, case, command in ((k, c, cmd) for k in (1, 2) for c in SPACES for cmd in ("verdict", "export")):
        allowed = _expected_ids(model, element, k)
        out_dir = ["--out", str(tmp_path / "out")] if command == "export" else []
        code, out, err = _run(capsys, [command, *flags, "--case", case, "--k", str(k), "--N", "3", "4", "5",
                                       "--dry-run", *out_dir])
        if case in allowed:
            assert code == 0, (command, case, k, err)
            continue
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, (command, case, k, err)
        if not SPACES[case].valid_for(k):
            assert "invalid --k" in err and f"case {case}" in err, err
        else:
            assert f"invalid --case (got '{case}')" in err, err
            listed = err.split(f"with k = {k}: ")[1].split(" (")[0].split(", ")
            assert set(listed) == allowed, (command, case, k, err)
    assert not (tmp_path / "out").exists()  # a dry run writes nothing


@pytest.mark.parametrize("argv, key", [
    (["--model", "membranes", "--case", "DUAL-Q9", "--k", "2"], "--case"),
    (["--model", "membranes3d", "--element", "tet", "--case", "TDUAL-Q8", "--k", "2"], "--case"),
    (["--model", "elastic3d", "--element", "hex", "--case", "PWLIN-T6", "--k", "2"], "--case"),
    (["--model", "membranes3d", "--element", "hex", "--case", "DUAL-Q8", "--k", "2"], "--case"),
    (["--model", "membranes3d", "--element", "tet", "--family", "unstructured", "--case", "TDUAL-T6", "--k", "2"],
     "--case"),
    (["--model", "membranes3d", "--element", "hex", "--case", "DUAL-Q9", "--k", "1"], "--k"),
    (["--case", "T3", "--k", "5"], "--k"),
    (["--case", "T3", "--k", "1", "--N1-offset", "-3"], "--N1-offset"),
    (["--case", "T3", "--k", "1", "--N1-offset", "100000"], "--N1-offset"),
])
@pytest.mark.parametrize("command", ["verdict", "export"])
def test_impossible_combinations_one_line(tmp_path, capsys, command, argv, key):
    tail = ["--N", "3", "4", "5"] + (["--out", str(tmp_path / "x")] if command == "export" else [])
    code, out, err = _run(capsys, [command, *argv, *tail])
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert f"invalid {key}" in err, err
    assert not (tmp_path / "x").exists()  # nothing written


def test_offset_refused_with_system(tmp_path, capsys):
    assert main(["export", "--case", "T3", "--k", "1", "--N", "2", "3", "4", "--out", str(tmp_path)]) == 0
    manifest = capsys.readouterr().out.strip()
    code, out, err = _run(capsys, ["verdict", "--system", manifest, "--N1-offset", "1"])
    assert code == 2 and "invalid --N1-offset" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("flags, case, k, offset", [
    ([], "R5.2", 1, -1),           # kernel dims [2, 1, 0]: UNSTABLE from the coarse pairs
    ([], "T3", 1, 1),
    (["--model", "elastic"], "R5.4", 2, 1),
    (["--model", "membranes3d", "--element", "hex"], "DUAL-Q9", 2, -1),
])
def test_non_matching_verdict_case_equals_export_then_system(tmp_path, capsys, flags, case, k, offset):
    """Two routes to one non-matching verdict: ``verdict --case --N1-offset`` (the built-in β_h)
    and ``export --N1-offset`` then the foreign-system engine on the files. Same verdict and
    kernel; β_min of the per-pair ``beta`` rows; the same slope (its fit of the same β_h)."""
    ns = ["2", "3", "4"]
    common = [*flags, "--case", case, "--k", str(k), "--N", *ns, "--N1-offset", str(offset)]
    code, out, err = _run(capsys, ["verdict", *common])
    assert code == 0, err
    row = _row(out)
    assert row["N1_offset"] == str(offset) and row["model"] == (flags[1] if flags else "membranes")
    assert _run(capsys, ["export", *common, "--out", str(tmp_path)])[0] == 0
    system, _ = system_verdict(load_manifest(tmp_path / "levels.yaml"), **CRITERION, notes=io.StringIO())
    assert system["verdict"] == row["verdict"] and system["kernel_dim"] == int(row["kernel_dim"])
    model = MODELS[flags[1] if flags else "membranes"]
    mesh = MeshOptions(element=flags[3]) if len(flags) > 2 else MeshOptions()
    refs = [r for n in map(int, ns) for r in beta_rows("structured", k, n + offset, n, [case], norms=("H",),
                                                        model=model, mesh=mesh)]
    assert [int(r["N1"]) for r in refs] == [int(n) + offset for n in ns]
    beta_min = min(r["beta"] for r in refs)
    for value in (float(row["beta_min"]), system["beta_min"]):  # CSV: 6 digits
        assert abs(value - beta_min) <= 1e-5 * max(beta_min, 1e-12) + 1e-12
    assert abs(float(row["slope"]) - system["slope"]) <= 1e-5 * max(1.0, abs(system["slope"]))
