"""The elastic face stage of the DAG (config ``models.elastic3d``, rules/models.smk with plans/elastic3d.py): its config
checks, the claim builder (study/face_elastic_claims.py: predictions from structure, verdicts from
the table) and the generated subsection (report/sections/elastic3d.py), on fabricated tables — the
numbers themselves are computed by the DAG, and the elastic model is tested in test_elastic3d.py."""
from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.criteria.claims import FAIL, INCONCLUSIVE, PASS
from infsup_contact.study.claims.membranes3d import matching_kernel
from infsup_contact.study.face.elastic3d import nu_pairs
from infsup_contact.study.claims.elastic3d import FINDING, claim_id, face_elastic_claims, nu_slope
from infsup_contact.study.claims.membranes3d_studies import face_contains_constants

ROOT = Path(__file__).resolve().parents[2]
CLAIMS_CFG = {"slope_tolerance": 0.15, "beta_floor": 1e-3, "confidence": 0.95, "fit_window": 5}
FE = {"model": "elastic3d", "elements": ["hex"], "k": [2], "N": [4, 6], "nonmatching": [[4, 5]],
      "cases": ["T3", "R5.2", "T4", "DUAL"], "nu": 0.3,
      "nu_sweep": {"nu": [0.3, 0.49, 0.499, 0.4999], "N": [4], "fit_nu_min": 0.49, "slope_tolerance": 0.05},
      "patch": {"elements": ["hex"], "pairs": [[4, 5]], "k": [2]}}
FACES = {"hex": SQUARE}


def _rows(case, k=2, exponent=0.5, kernel=None, decision="clear", membranes_kernel=None):
    """Fabricated elastic rows: the kernel is the dimension count on matching meshes (or
    ``kernel(n1, n2, count)``), β_H = (1 − 2ν)^exponent without kernel; also the membranes'
    face_beta rows on the non-matching pairs (their kernel ``membranes_kernel`` or 0)."""
    spec, out, mem = SPACES[case], [], []
    for nu, pairs in nu_pairs(FE):
        for n1, n2 in pairs:
            count = matching_kernel(spec, k, n2, SQUARE) if n1 == n2 else 0
            dim = count if kernel is None else kernel(n1, n2, count)
            out.append(dict(model="elastic3d", element="hex", case=case, k=k, family="structured", N1=n1, N2=n2,
                            multiplier_mesh="omega2", norm="H", nu=nu, beta=0.0 if dim else (1 - 2 * nu) ** exponent,
                            kernel_dim=dim, structural_kernel_dim=count, kernel_decision=decision,
                            kernel_margin_decades=5.0, smallest_nonzero=0.5))
            if n1 != n2 and np.isclose(nu, FE["nu"]):
                mem.append(dict(out[-1], model="membranes3d", kernel_dim=membranes_kernel or 0))
    return pd.DataFrame(out), pd.DataFrame(mem)


def _claims(frames, patch=None):
    beta = pd.concat([f[0] for f in frames], ignore_index=True)
    mem = pd.concat([f[1] for f in frames], ignore_index=True)
    return face_elastic_claims(beta, patch, CLAIMS_CFG, FE, FACES, mem).set_index("claim_id")


def test_nu_pairs_compute_each_nu_and_pair_once():
    got = nu_pairs(FE)
    assert got[0] == (0.3, [(4, 4), (6, 6), (4, 5)])
    assert [nu for nu, _ in got] == [0.3, 0.49, 0.499, 0.4999]  # 0.3 of the sweep is the table's ν
    assert all(pairs == [(4, 4)] for _, pairs in got[1:])


def test_kernel_differing_from_the_proof_fails_although_predicted_pass():
    ok = _claims([_rows("R5.2")])
    bad = _claims([_rows("R5.2", kernel=lambda n1, n2, c: c - 1 if n1 == n2 == 6 else c)])
    cid = claim_id("kernel", "R5.2", 2, "hex")
    assert ok.loc[cid, "verdict"] == PASS and bad.loc[cid, "verdict"] == FAIL
    assert ok.loc[cid, "predicted"] == bad.loc[cid, "predicted"] == PASS  # from the structure, not the table


def test_non_matching_kernel_is_compared_with_the_membranes():
    cid = claim_id("kernel", "T3", 2, "hex")
    assert _claims([_rows("T3")]).loc[cid, "verdict"] == PASS
    assert _claims([_rows("T3", membranes_kernel=3)]).loc[cid, "verdict"] == FAIL
    assert _claims([_rows("T3", decision="close")]).loc[cid, "verdict"] == INCONCLUSIVE


def test_nu_slope_claims_predict_from_spans_constants():
    claims = _claims([_rows("T3"), _rows("DUAL"), _rows("T4", exponent=1.0), _rows("R5.2")])
    for case in ("T3", "DUAL", "T4"):
        expected = PASS if face_contains_constants(SPACES[case], 2, SQUARE) else FINDING
        assert claims.loc[claim_id("nu", case, 2, "hex", 4), "predicted"] == expected
    assert claims.loc[claim_id("nu", "T3", 2, "hex", 4), "predicted"] == FINDING  # T3 vanishes on ∂Γ
    assert claims.loc[claim_id("nu", "DUAL", 2, "hex", 4), "verdict"] == PASS
    assert claims.loc[claim_id("nu", "T4", 2, "hex", 4), "verdict"] == FAIL  # slope 1, not 1/2
    assert claim_id("nu", "R5.2", 2, "hex", 4) not in claims.index  # a kernel: β_H = 0 at every ν
    assert claim_id("bounded", "R5.2", 2, "hex") not in claims.index  # not marked stable


def test_every_character_of_the_claims_has_a_latex_form():
    """The ledger is typeset (paper_macros): statements and evidence use only mapped characters."""
    from infsup_contact.report.texformat import UNICODE_LATEX

    patch = pd.DataFrame([dict(element="hex", case="DUAL", k=2, N1=4, N2=5, E1=1.0, E2=1.0, nu=0.3,
                               lambda_max_rel_error=1e-14, u_max_rel_error=1e-14, kernel_dim=0, passes=True)])
    claims = _claims([_rows("T3"), _rows("DUAL"), _rows("R5.2")], patch)
    text = "".join(claims.statement) + "".join(claims.evidence)
    assert {ch for ch in text if ord(ch) > 127 and ch not in UNICODE_LATEX} == set()


def test_slope_fit_is_exact_on_a_power_law():
    rows = pd.DataFrame({"nu": [0.3, 0.49, 0.499, 0.4999], "beta": [(1 - 2 * v) ** 0.37 for v in (0.3, 0.49, 0.499, 0.4999)]})
    slope, n = nu_slope(rows, 0.49)
    assert n == 3 and slope == pytest.approx(0.37, abs=1e-12)


def test_bounded_fails_below_the_floor():
    beta, mem = _rows("T4")
    beta.loc[(beta.N1 == 4) & (beta.N2 == 5), "beta"] = 1e-6
    claims = face_elastic_claims(beta, None, CLAIMS_CFG, FE, FACES, mem).set_index("claim_id")
    assert claims.loc[claim_id("bounded", "T4", 2, "hex"), "verdict"] == FAIL


def test_patch_claims_predict_pass_iff_the_space_spans_constants():
    patch = pd.DataFrame([dict(element="hex", case=c, k=2, N1=4, N2=5, E1=1.0, E2=1.0, nu=0.3,
                               lambda_max_rel_error=e, u_max_rel_error=e, kernel_dim=0, passes=e < 1e-8)
                          for c, e in (("T3", 1.0), ("DUAL", 1e-14), ("T4", 1e-14))])
    claims = _claims([_rows("T3")], patch)
    for case in ("T3", "DUAL", "T4"):
        row = claims.loc[claim_id("patch", case, 2, "hex")]
        assert row.predicted == (PASS if face_contains_constants(SPACES[case], 2, SQUARE) else FAIL)
        assert row.verdict == row.predicted


def test_subsection_renders_the_table():
    from infsup_contact.report.sections.elastic3d import elastic3d_tex

    frames = [_rows("T3"), _rows("R5.2"), _rows("DUAL")]
    beta = pd.concat([f[0] for f in frames], ignore_index=True)
    claims = _claims(frames).reset_index()
    tex = elastic3d_tex(beta, None, claims, FE)
    assert r"\label{tab:elastic3d}" in tex and tex.count(r"hex & 2 &") == 3
    assert "48 (48)" in tex  # R5.2, k = 2, N = 6: 4Nk on matching meshes


# ------------------------------------------------------------------ config checks

pytestmark = pytest.mark.usefixtures("registry_as_found")  # tests/conftest.py


def _ci():
    return yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())


@pytest.mark.parametrize("mutate, key", [
    (lambda f: f.update(model="membranes3d"), "studies.elastic3d.model"),
    (lambda f: f.update(elements=["hex", "prism"]), "studies.elastic3d.elements[1]"),
    (lambda f: f["patch"].update(elements=["prism"]), "studies.elastic3d.patch.elements[0]"),
    (lambda f: f.update(nu=0.5), "studies.elastic3d.nu"),
    (lambda f: f["nu_sweep"].update(nu=[0.3, 0.49, 0.5]), "studies.elastic3d.nu_sweep.nu[2]"),
    (lambda f: f["nu_sweep"].update(fit_nu_min=0.4999), "studies.elastic3d.nu_sweep.fit_nu_min"),
    (lambda f: f["nu_sweep"].update(N=[5]), "studies.elastic3d.nu_sweep.N[0]"),
    (lambda f: f.update(nonmatching=[[5, 5]]), "studies.elastic3d.nonmatching[0]"),
    (lambda f: f["patch"].update(pairs=[[4, 4]]), "studies.elastic3d.patch.pairs[0]"),
    (lambda f: f.update(cases=["T3", "NOPE"]), "studies.elastic3d.cases[1]"),
    (lambda f: f.update(k=[1], cases=["T4"]), "studies.elastic3d.cases[0]"),
    (lambda f: f["nu_sweep"].update(slope_tolerance=0), "studies.elastic3d.nu_sweep.slope_tolerance"),
    (lambda f: f.update(surprise=1), "studies.elastic3d"),
])
def test_bad_elastic3d_key_is_named(mutate, key):
    from infsup_contact.config.checks import ConfigError, check_config

    cfg = copy.deepcopy(_ci())
    mutate(cfg["studies"]["elastic3d"])
    with pytest.raises(ConfigError) as err:
        check_config(cfg, ROOT / "workflow" / "schemas" / "config.schema.yaml")
    assert f"config key {key}" in str(err.value)


@pytest.mark.parametrize("name", ["ci.yaml", "config.yaml"])
def test_shipped_configs_pass_and_the_study_is_optional(name):
    from infsup_contact.config.checks import check_config

    cfg = yaml.safe_load((ROOT / "config" / name).read_text())
    check_config(cfg, ROOT / "workflow" / "schemas" / "config.schema.yaml")
    del cfg["studies"]["elastic3d"]
    check_config(cfg, ROOT / "workflow" / "schemas" / "config.schema.yaml")
