"""The face stage's claims (study/face_claims.py), macros (report/sections/face.py) and config checks
(config/membranes3d.py) on synthetic tables: verdicts follow the data by the ledger's criteria, the
predictions follow registry properties (not ids), a bad ``face:`` key is named."""
from __future__ import annotations

import copy
import dataclasses
import re
from pathlib import Path

import pandas as pd
import pytest
import yaml

from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.errors import InputError
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.criteria.claims import FAIL, INCONCLUSIVE, PASS
from infsup_contact.study.claims.membranes3d import (face_claims, face_dimension, face_predictions, kernel_formula,
                                              planar_kernel, tensor_kernel_bound)

ROOT = Path(__file__).resolve().parents[2]
from helpers.face_tables import CLAIMS_CFG, NS, face_rows as _rows  # noqa: E402


def _verdicts(frame, tensor=("hex",)):
    claims = face_claims(frame, CLAIMS_CFG, {e: SQUARE if e in tensor else SQUARE_TRIG for e in set(frame.element)})
    return dict(zip(claims.claim_id, zip(claims.verdict, claims.predicted)))


def test_stable_space_claims_pass_on_bounded_data_and_fail_on_decay():
    ok = _verdicts(_rows("T3", 1))
    assert ok["face-kernel-Thm3-k1-hex"] == (PASS, PASS)
    assert ok["face-Thm3-k1-hex"] == (PASS, PASS)
    assert ok["face-Rem3.1-Thm3-k1-hex"] == (PASS, PASS)
    assert ok["face-nonmatching-kernel-Thm3-k1-hex"] == (PASS, PASS)
    bad = _verdicts(_rows("T3", 1, beta_h=lambda n: 1.0 / n, beta_l2=lambda n: 1.0 / n))
    assert bad["face-Thm3-k1-hex"][0] == FAIL  # slope 1 vs 0 ± τ
    assert bad["face-Rem3.1-Thm3-k1-hex"][0] == FAIL  # slope 1 vs 1/2 ± τ


def test_kernel_claims_follow_the_count_and_close_decisions_are_inconclusive():
    v = _verdicts(_rows("R5.2", 1))
    assert v["face-kernel-Rem5.2-k1-hex"] == (PASS, PASS)
    off = _verdicts(_rows("R5.2", 1, kernel=lambda n1, n2, c: c + 1))
    assert off["face-kernel-Rem5.2-k1-hex"][0] == FAIL
    frame = _rows("R5.2", 1)
    frame.loc[frame.index[0], "kernel_decision"] = "close"
    assert _verdicts(frame)["face-kernel-Rem5.2-k1-hex"][0] == INCONCLUSIVE
    # non-matching: above the planar count = FAIL of "kernel equals the count"
    above = _verdicts(_rows("R5.2", 1, kernel=lambda n1, n2, c: c if n1 == n2 else c + 8))
    assert above["face-nonmatching-kernel-Rem5.2-k1-hex"][0] == FAIL


@pytest.mark.parametrize("k", [1, 2, 3])
def test_kernel_formula_is_the_dimension_count(k):
    """dim M − dim W on the face: R5.2's (Nk + 1)² − (Nk − 1)² = 4Nk; every case's formula
    string evaluates to the count (read back by substituting N)."""
    assert kernel_formula(SPACES["R5.2"], k) == f"{4 * k}N"
    for spec in SPACES.values():
        if spec.dimension is None or not spec.valid_for(k):
            continue
        try:
            formula = kernel_formula(spec, k)
        except InputError:  # a space the face refuses to build (DUAL-Q8: weights <= 0; tested apart)
            continue
        for n in (3, 7):
            assert _evaluate(formula, n) == face_dimension(spec, k, n) - SQUARE.trace_dimension(k, n)


def _evaluate(formula: str, n: int) -> int:
    """Value of a ``kernel_formula`` text (``−3N² + 4N − 1``) at N = n."""
    total = 0
    for sign, coef, power in re.findall(r"([+−-]?)\s*(\d*)(N²|N)?", formula.replace(" ", "")):
        if not coef and not power:
            continue
        c = int(coef) if coef else 1
        total += (-1 if sign in "−-" and sign else 1) * c * {"N²": n * n, "N": n, "": 1}[power]
    return total


def test_tensor_bound_is_a_bound_of_one_direction_product():
    """2 a1 a2 − min(a1, a2)² >= a1 a2 (the dimension of K1ˣ ⊗ K2ʸ alone) and = 0 when Ω2's
    1D count a2 is 0 (every stable tensor-product space of the registry on N:N+1; a face-only
    space's count is two-dimensional)."""
    for spec in SPACES.values():
        if spec.dimension is None or not spec.defined_on(1):
            continue
        for k in (1, 2):
            if not spec.valid_for(k):
                continue
            d = spec.dimension(k, 7)
            a1, a2 = max(d - (6 * k - 1), 0), max(d - (7 * k - 1), 0)
            assert tensor_kernel_bound(spec, k, 6, 7) >= a1 * a2
            if spec.stable:
                assert tensor_kernel_bound(spec, k, 6, 7) == 0 and planar_kernel(spec, k, 6, 7) == 0


def test_predictions_come_from_properties_not_ids():
    for spec in SPACES.values():
        if spec.dimension is None:
            continue
        alias = dataclasses.replace(spec, id="ZZ", claim_tag="ZZ", paper_ref="nowhere")
        for k in (1, 2):
            if spec.valid_for(k):
                for tensor in (True, False):
                    assert face_predictions(alias, k, [(4, 5)], tensor) == face_predictions(spec, k, [(4, 5)], tensor)
    assert face_predictions(SPACES["R5.4"], 1, [(6, 7)], True)["nonmatching"] == FAIL  # bound 3 > count 0
    assert face_predictions(SPACES["R5.4"], 1, [(6, 7)], False)["nonmatching"] == "finding"


def test_face_macros_count_the_claims():
    from infsup_contact.report.sections.face import check_face_tex, face_paper_files

    beta = pd.concat([_rows("T3", 1), _rows("R5.2", 1), _rows("T3", 1, element="tet")], ignore_index=True)
    claims = face_claims(beta, CLAIMS_CFG, {"hex": SQUARE, "tet": SQUARE_TRIG})
    from helpers.face_tables import small_study_tables

    files = face_paper_files(beta, claims, **small_study_tables())  # paper/face.tex also shows the studies
    check_face_tex((ROOT / "paper" / "face.tex").read_text(), files)
    macros = dict(re.findall(r"\\newcommand\{\\([A-Za-z]+)\}\{([^}]*)\}", files["face_macros.tex"]))
    assert int(macros["faceNClaims"]) == len(claims)
    assert int(macros["faceFinestN"]) == max(NS)
    assert "48 (48)" in files["face_beta_table.tex"]  # R5.2, k = 1, N = 12: 4Nk


# ------------------------------------------------------------------ config checks

pytestmark = pytest.mark.usefixtures("registry_as_found")  # tests/conftest.py


def _ci():
    return yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())


@pytest.mark.parametrize("mutate, key", [
    (lambda f: f.update(cases=["T3", "NOPE"]), "studies.membranes3d.cases[1]"),
    (lambda f: f.update(elements=["hex", "prism"]), "studies.membranes3d.elements[1]"),
    (lambda f: f.update(nonmatching=[[5, 5]]), "studies.membranes3d.nonmatching[0]"),
    (lambda f: f.update(model="membranes"), "studies.membranes3d.model"),
    (lambda f: f.update(norms=["H", "H1"]), "studies.membranes3d.norms"),
    (lambda f: f.update(max_N={"prism": 8}), "studies.membranes3d.max_N.prism"),
    (lambda f: f.update(max_N={"hex": 4}), "studies.membranes3d.max_N.hex"),
    (lambda f: f.update(l2_max_N={"hex": 12}), "studies.membranes3d.l2_max_N.hex"),                 # no max_N to exceed
    (lambda f: f.update(max_N={"hex": 8}, l2_max_N={"hex": 6}), "studies.membranes3d.l2_max_N.hex"),  # below max_N
    (lambda f: f.update(max_N={"hex": 8}, l2_max_N={"hex": 10}, norms=["H"]), "studies.membranes3d.l2_max_N.hex"),
])
def test_bad_face_key_is_named(mutate, key):
    from infsup_contact.config.checks import ConfigError, check_config

    cfg = copy.deepcopy(_ci())
    mutate(cfg["studies"]["membranes3d"])
    with pytest.raises(ConfigError) as err:
        check_config(cfg, ROOT / "workflow" / "schemas" / "config.schema.yaml")
    assert f"config key {key}" in str(err.value)


def test_config_without_face_study_is_valid():
    from infsup_contact.config.checks import check_config

    cfg = _ci()
    del cfg["studies"]["membranes3d"]
    check_config(cfg, ROOT / "workflow" / "schemas" / "config.schema.yaml")


@pytest.mark.parametrize("verdict", ["PASS", "FAIL", "INCONCLUSIVE"])
def test_face_section_renders_under_any_verdict(verdict):
    """paper/face.tex states outcomes only through \\byverdict on its generated outcome macros:
    it renders (every macro expanded, every branch resolved) whatever the ledger says."""
    from infsup_contact.report.consistency import render
    from infsup_contact.report.sections.face import face_macros
    from infsup_contact.report.sections.face import study_files

    from helpers.face_tables import small_face_tables

    t = small_face_tables()
    macros = face_macros(t["beta"], t["claims"].assign(verdict=verdict))
    macros += study_files(t["patch"], t["alpha"], t["edge"], t["study_claims"].assign(verdict=verdict))[0]
    text = render((ROOT / "paper" / "face.tex").read_text(), macros)
    assert "\\byverdict" not in text and "\\faceOutcome" not in text


def test_max_n_trims_the_pairs_of_its_element_only():
    from infsup_contact.config.membranes3d import face_pairs

    fc = {"N": [4, 5, 6, 8, 12], "nonmatching": [[4, 5], [8, 9]], "max_N": {"tet": 6}}
    assert face_pairs(fc, "tet") == [(4, 4), (5, 5), (6, 6), (4, 5)]
    assert face_pairs(fc, "hex") == [(4, 4), (5, 5), (6, 6), (8, 8), (12, 12), (4, 5), (8, 9)]


def test_l2_max_n_adds_the_matching_meshes_above_max_n_of_its_element_only():
    from infsup_contact.config.membranes3d import face_pairs, l2_only_sizes

    fc = {"N": [4, 5, 6, 7, 8, 10, 12], "nonmatching": [[4, 5], [8, 9]], "max_N": {"tet": 6},
          "l2_max_N": {"tet": 10}}
    assert l2_only_sizes(fc, "tet") == [7, 8, 10]
    assert l2_only_sizes(fc, "hex") == []
    assert not set((n, n) for n in l2_only_sizes(fc, "tet")) & set(face_pairs(fc, "tet"))  # no row twice


def test_quadrilateral_element_spaces_are_not_built_on_triangles():
    """The QUAD9-element multipliers pair with rectangle faces only (``SpaceSpec.face_cells``)."""
    quad_only = [s for s in SPACES.values() if s.face_cells == ("quad",)]
    assert quad_only and all(SQUARE.builds(s) and not SQUARE_TRIG.builds(s) for s in quad_only)
    x = __import__("numpy").linspace(0.0, 1.0, 3)
    from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition

    with pytest.raises(InputError, match="faces"):
        SQUARE_TRIG.space(quad_only[0], 2, TensorPartition(x, x))


def test_kuhn_faces_predict_fail_where_the_triangle_bound_exceeds_the_count():
    """On tetrahedra (Kuhn triangles) the non-matching claim is predicted from
    triangle_kernel_bound: FAIL where it exceeds the planar count on a config pair (R5.2 at
    k = 2, 4:5: corner modes), FINDING where it does not (R5.2 at k = 1, 4:5), PASS for a
    stable space; never from the data."""
    from infsup_contact.study.claims.membranes3d import FINDING, face_predictions, triangle_kernel_bound
    r52 = SPACES["R5.2"]
    assert triangle_kernel_bound(r52, 2, 4, 5) > planar_kernel(r52, 2, 4, 5, SQUARE_TRIG)
    assert face_predictions(r52, 2, [(4, 5)], False, SQUARE_TRIG)["nonmatching"] == FAIL
    assert triangle_kernel_bound(r52, 1, 4, 5) == planar_kernel(r52, 1, 4, 5, SQUARE_TRIG)
    assert face_predictions(r52, 1, [(4, 5)], False, SQUARE_TRIG)["nonmatching"] == FINDING
    assert face_predictions(r52, 1, [(4, 5), (6, 7)], False, SQUARE_TRIG)["nonmatching"] == FAIL
    assert face_predictions(SPACES["T3"], 1, [(4, 5)], False, SQUARE_TRIG)["nonmatching"] == PASS


@pytest.mark.parametrize("patch, refused", [(["hex"], True), (["hex", "tet"], False)])
def test_face_case_no_configured_element_carries_is_refused(patch, refused):
    """Issue 39, item 5.3: PWLIN-T6 (a triangle-face space) listed for the face while only
    hexahedra are configured was accepted and silently never computed. Refused, naming the key,
    the elements and the spaces their faces build; computed (accepted) where the patch test's
    tetrahedra carry it."""
    from infsup_contact.config.checks import ConfigError, check_config

    cfg = copy.deepcopy(_ci())
    face = cfg["studies"]["membranes3d"]
    face["cases"] = [*face["cases"], "PWLIN-T6"]
    face["patch"]["elements"] = patch
    schema = ROOT / "workflow" / "schemas" / "config.schema.yaml"
    if not refused:
        check_config(cfg, schema)
        return
    with pytest.raises(ConfigError) as err:
        check_config(cfg, schema)
    line = str(err.value)
    assert line.startswith(f"config key studies.membranes3d.cases[{len(face['cases']) - 1}]: PWLIN-T6 is built by the face "
                           "of none of the elements hex") and "allowed T3, R5.2" in line and "PWLIN-Q9" in line, line
