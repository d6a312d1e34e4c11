"""The √2 family on the 3D face (issue 28, item 1): N2 = round(√2·N1), Ω2 the finer side. The config
accepts it per element (face.nonmatching_families), the command line runs the pair, and on it the
numerical kernel is bounded below by the dimension argument and, on rectangles, by the tensor count;
the verdicts the face ledger predicts from registry properties hold."""
import copy
import io
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from infsup_contact.config.checks import ConfigError, check_config
from infsup_contact.config.membranes3d import face_pairs, family_pairs
from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.study.face.families import family_kernels, family_pair
from helpers.cli import run_in_process

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


pytestmark = pytest.mark.usefixtures("registry_as_found")  # tests/conftest.py


def test_sqrt2_pairs_follow_the_rule_and_share_no_interior_line():
    for n1 in (5, 7, 10):
        n1_, n2 = family_pair("sqrt2", n1)
        assert n1_ == n1 and n2 == round(math.sqrt(2) * n1) and n2 > n1
    assert [family_pair("sqrt2", n)[1] for n in (5, 7, 10)] == [7, 10, 14]
    # gcd(5, 7) = 1: the traces' common coarsening is the one cell, W1 ∩ W2 = {0} on rectangles
    u = [TensorPartition(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1)) for n in (5, 7)]
    assert SQUARE.trace_sum_dimension(1, *u) == SQUARE.trace_dimension(1, 5) + SQUARE.trace_dimension(1, 7)


def test_the_config_runs_one_sqrt2_pair_per_element():
    fc = CONFIG["studies"]["membranes3d"]
    check_config(copy.deepcopy(CONFIG), SCHEMA)
    for element in fc["elements"]:
        fam = family_pairs(fc, element)
        assert len(fam) <= 1 and all(n2 == round(math.sqrt(2) * n1) for n1, n2 in fam)
        assert set(fam) <= set(face_pairs(fc, element))       # not capped by face.max_N


@pytest.mark.parametrize("families,key", [
    ({"cube": {"hex": [5]}}, "studies.membranes3d.nonmatching_families.cube"),
    ({"sqrt2": {"prism": [5]}}, "studies.membranes3d.nonmatching_families.sqrt2.prism"),
    ({"sqrt2": {"hex": [1]}}, "studies.membranes3d.nonmatching_families.sqrt2.hex[0]"),
])
def test_bad_families_are_refused_naming_the_key(families, key):
    cfg = copy.deepcopy(CONFIG)
    cfg["studies"]["membranes3d"]["nonmatching_families"] = families
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    assert err.value.key == key and "\n" not in str(err.value)


def test_kernels_on_a_sqrt2_pair_against_the_counts():
    """5:7, k = 1, both elements: kernel ≥ planar count (dimension argument) everywhere, ≥ the tensor
    count on rectangles; 0 for the spaces the registry marks stable; each PASS/FAIL prediction of the
    face ledger (face_predictions) borne out; every kernel decision clear."""
    cases = ["T3", "R5.2", "R5.4", "DUAL", "DUAL-ALL"]
    rows = pd.DataFrame(family_kernels([family_pair("sqrt2", 5)], ks=(1,), cases=cases))
    assert set(rows.element) == {"hex", "tet"} and len(rows) == 2 * len(cases)
    assert (rows.kernel_decision == "clear").all()
    assert (rows.kernel_dim >= rows.planar).all()
    hexes = rows[rows.element == "hex"]
    assert hexes.tensor.notna().all() and (hexes.kernel_dim >= hexes.tensor).all()
    assert (hexes.kernel_dim == hexes.tensor_1d).all()       # 3D pencil = rank of the 1D Kronecker factors
    stable = rows.case.map(lambda c: SPACES[c].stable)
    assert (rows[stable].kernel_dim == 0).all()
    predicted = rows[rows.prediction.isin(["PASS", "FAIL"])]
    assert len(predicted) and predicted.as_predicted.astype(bool).all()


def test_the_command_line_runs_the_pair_and_agrees():
    """Two routes: `infsup-contact beta` on 5:7 (tetrahedra, k = 1) and the family study."""
    code, out, err = run_in_process(["beta", "--model", "membranes3d", "--element", "tet", "--case", "R5.2",
                                     "--k", "1", "--N1", "5", "--N2", "7", "--norm", "L2"])
    assert code in (0, None), err
    cli = pd.read_csv(io.StringIO(out))
    study = pd.DataFrame(family_kernels([(5, 7)], ks=(1,), cases=["R5.2"], elements=["tet"]))
    assert int(cli.kernel_dim.iloc[0]) == int(study.kernel_dim.iloc[0]) >= int(study.planar.iloc[0])


def test_hexahedral_kernels_at_k2_equal_the_1d_tensor_route():
    """5:7, k = 2, hexahedra: the 3D numerical kernel = dim M − rank [A1⊗A1; A2⊗A2] from 1D integrals,
    also where both lower bounds undercount (R5.2, DUAL-ALL: planar 0)."""
    rows = pd.DataFrame(family_kernels([(5, 7)], ks=(2,), cases=["R5.2", "R5.4", "T4", "DUAL-ALL"], elements=["hex"]))
    assert (rows.kernel_dim == rows.tensor_1d).all() and (rows.kernel_decision == "clear").all()
    assert (rows.tensor_1d >= rows.tensor).all() and (rows.tensor_1d >= rows.planar).all()   # both lower bounds
