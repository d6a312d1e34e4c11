"""The face studies in the DAG: the model job script (rule model_job) of the face study
on tiny inputs, the claims of study/face_study_claims.py (predictions from properties; verdicts
that flip when the data flips) and the three paper tables (report/sections/face.py)."""
import copy
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from helpers.face_tables import (CLAIMS_CFG, FIT_THETA_MAX, THETAS, alpha_rows, edge_rows, patch_rows,
                          small_face_tables)

from infsup_contact.discretization.face.spaces.dual_bases import ZERO_WEIGHT_RTOL, weight_fractions
from infsup_contact.discretization.spaces.registry import common_ids, ids_valid_for, SPACES
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.io import read_table
from infsup_contact.study.claims import membranes3d_studies as fsc

ROOT = Path(__file__).resolve().parents[2]
ENV = {"PYTHONPATH": str(ROOT / "src"), "OPENBLAS_NUM_THREADS": "1", "PATH": str(Path(sys.executable).parent)}

JOB = """
import runpy, sys, types
snakemake = types.SimpleNamespace(output=[sys.out], log=[sys.log], threads=1,
                                  config={"spaces": [], "studies": {"membranes3d": {"study": "membranes3d", **sys.fc}}},
                                  wildcards=types.SimpleNamespace(model="membranes3d", job=sys.study))
runpy.run_path("workflow/scripts/model_job.py", init_globals={"snakemake": snakemake})
"""
TINY = {"model": "membranes3d", "cases": ["T3", "R5.2", "T4", "T5"], "norms": ["L2"],
        "patch": {"elements": ["hex", "tet"], "pairs": [[2, 3]], "k": [1]},
        "alpha": {"elements": ["QUAD8"], "alphas": [0.1, 0.125, 0.2], "N": [2]},
        "edge_dropping": {"k": [2], "N": [2], "n2_factor": 1, "theta": [1.0, 0.5, 0.25],
                          "fit_theta_max": 1.0}}


pytestmark = pytest.mark.usefixtures("registry_as_found")  # tests/conftest.py


def run_job(tmp_path, study, fc=TINY):
    out, log = tmp_path / f"{study}.csv", tmp_path / f"{study}.log"
    setup = f"import sys; sys.out = {str(out)!r}; sys.log = {str(log)!r}; sys.study = {study!r}; sys.fc = {fc!r}\n"
    proc = subprocess.run([sys.executable, "-c", setup + JOB], cwd=ROOT, env=ENV, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr + log.read_text() if log.exists() else proc.stderr
    return out


# ------------------------------------------------------------------ the job script on tiny inputs

def test_patch_job_passes_iff_the_face_space_holds_the_constants(tmp_path):
    table = read_table(run_job(tmp_path, "patch"), "face_patch")
    gammas = {"hex": SQUARE, "tet": SQUARE_TRIG}
    expected = {(e, c) for e in gammas for c in ids_valid_for(1, TINY["cases"])}
    assert set(zip(table.element, table.case)) == expected and (table.N1 == 2).all() and (table.N2 == 3).all()
    for r in table.itertuples():
        holds = fsc.face_contains_constants(SPACES[r.case], r.k, gammas[r.element])
        assert r.passes == holds, r
        assert (r.lambda_max_rel_error < fsc.PATCH_RTOL) if holds else (r.lambda_max_rel_error > fsc.PATCH_FAIL_RTOL)
    assert {"package_version", "git_commit", "config_hash"} <= set(table.columns)  # provenance


def test_alpha_job_accepts_exactly_the_positive_weights(tmp_path):
    table = read_table(run_job(tmp_path, "alpha"), "face_alpha")
    assert sorted(set(table.alpha)) == TINY["alpha"]["alphas"] and set(table.norm) == {"L2"}
    for r in table.itertuples():
        exact = float(weight_fractions(r.element, r.alpha).min())
        assert r.min_weight == pytest.approx(exact, abs=1e-11) and r.min_weight_gauss == pytest.approx(exact, abs=1e-11)
        assert r.accepted == (exact > 1e-12) and (math.isnan(r.beta) != r.accepted)
    assert table.accepted.any() and not table.accepted.all()


def test_edge_job_writes_both_beta_routes_and_the_fit_window(tmp_path):
    table = read_table(run_job(tmp_path, "edge_dropping"), "face_edge")
    cases = set(table.case)
    assert cases and cases <= set(TINY["cases"]) and sorted(set(table.theta)) == [0.25, 0.5, 1.0]
    assert (table.fit_theta_max == 1.0).all() and (table.N2 == table.N).all()
    both = table[table.beta_L2_resolved & table.beta_L2_kappa_resolved]
    assert len(both) and np.allclose(both.beta_L2_kappa, both.beta_L2, rtol=1e-8)


# ------------------------------------------------------------------ predictions from properties

def test_face_constants_agree_with_the_registry_on_rectangles():
    """Two routes: the face build's least-squares check against the registry's 1D one, on
    tensor products (1 ∈ M ⊗ M iff 1 ∈ M)."""
    for k in (1, 2):
        for case in common_ids(k):
            assert fsc.face_contains_constants(SPACES[case], k, SQUARE) == SPACES[case].contains_constants(k), case


def test_alpha_interval_is_where_the_weights_change_sign():
    for element in ("QUAD8", "QUAD9"):
        lo, hi = fsc.alpha_interval(element)
        assert 0.0 <= lo < hi <= 0.5
        inside = np.linspace(lo, hi, 9)[1:-1]
        assert all(weight_fractions(element, a).min() > 0 for a in inside)
        if lo > 0:  # the threshold is a zero of the smallest weight (to the dual basis' own zero test:
            # lo and the weight at it carry round-off), negative below it
            assert abs(weight_fractions(element, lo).min()) <= ZERO_WEIGHT_RTOL
            assert weight_fractions(element, lo / 2).min() < 0


def test_natural_kernel_count_is_zero_for_nodal_spaces_on_the_finer_trace():
    """A continuous space on G_h = trace of Ω2 of degree <= k is a subspace of W2 (no count)."""
    for case in ("R5.2", "T5"):
        for k in (2, 3):
            assert fsc.natural_kernel_count(SPACES[case], k, 4, 5, SQUARE) == 0


# ------------------------------------------------------------------ verdicts flip with the data

def _verdicts(frame):
    return dict(zip(frame.claim_id, zip(frame.verdict, frame.predicted)))


def test_patch_claims_flip_when_the_errors_flip():
    def claims(holding_err, lacking_err):
        t = pd.concat([patch_rows("R5.2", 1, err=lambda p: holding_err),
                       patch_rows("T3", 1, passes=False, err=lambda p: lacking_err)])
        return _verdicts(fsc.face_study_claims(t, None, None, CLAIMS_CFG, {"hex": SQUARE}, FIT_THETA_MAX))

    good, hold, lack = claims(1e-13, 1.0), fsc.patch_claim_id("R5.2", 1, "hex"), fsc.patch_claim_id("T3", 1, "hex")
    assert good[hold] == ("PASS", "PASS") and good[lack] == ("FAIL", "FAIL")
    flipped = claims(1.0, 1e-13)
    assert flipped[hold] == ("FAIL", "PASS") and flipped[lack] == ("PASS", "FAIL")
    assert claims(10 * fsc.PATCH_RTOL, 1.0)[hold][0] == "INCONCLUSIVE"   # between round-off and failure


def test_alpha_claim_fails_when_a_negative_weight_is_accepted():
    table = alpha_rows()
    ok = _verdicts(fsc.face_study_claims(None, table, None, CLAIMS_CFG, {}, FIT_THETA_MAX))
    assert ok["face-alpha-accept-QUAD8"] == ("PASS", "PASS")
    bad = table.copy()
    bad.loc[bad.alpha == 0.1, "accepted"] = True           # the construction ignored a negative weight
    assert _verdicts(fsc.face_study_claims(None, bad, None, CLAIMS_CFG, {}, FIT_THETA_MAX))[
        "face-alpha-accept-QUAD8"][0] == "FAIL"
    bad = table.copy()
    bad.loc[bad.alpha == 0.3, "min_weight_gauss"] = -0.01  # the second quadrature disagrees
    assert _verdicts(fsc.face_study_claims(None, bad, None, CLAIMS_CFG, {}, FIT_THETA_MAX))[
        "face-alpha-accept-QUAD8"][0] == "FAIL"


@pytest.mark.parametrize("doctor, kind, case, k, verdict", [
    (dict(), "decay", "R5.2", 1, "PASS"),
    (dict(beta_h=lambda t: 0.5), "decay", "R5.2", 1, "FAIL"),            # bounded instead of ~θ
    (dict(beta_h=lambda t: 1.0), "bounded", "T4", 2, "PASS"),
    (dict(beta_h=lambda t: t), "bounded", "T4", 2, "FAIL"),               # decays instead
    (dict(beta_h=lambda t: 1.0), "kappa-cond", "T4", 2, "PASS"),
    (dict(beta_h=lambda t: 1.0, cond=lambda t: 10 / t), "kappa-cond", "T4", 2, "FAIL"),
    (dict(), "kappa-beta", "R5.2", 1, "PASS"),
    (dict(kappa_rel=1e-2), "kappa-beta", "R5.2", 1, "FAIL"),
    (dict(kappa_rel=1e-5), "kappa-beta", "R5.2", 1, "INCONCLUSIVE"),
])
def test_edge_claims_flip_when_the_data_flips(doctor, kind, case, k, verdict):
    table = edge_rows(case, k, **doctor)
    got = _verdicts(fsc.face_study_claims(None, None, table, CLAIMS_CFG, {}, FIT_THETA_MAX))
    assert got[fsc.edge_claim_id(kind, case, k, 4)] == (verdict, "PASS")


def test_edge_predictions_follow_degree_and_stability():
    """Decay predicted for the full-order spaces at k = 1 only; bounded and κ-conditioning for
    the stable lower-order ones; the rest are findings."""
    rows = pd.concat([edge_rows(c, k) for k in (1, 2) for c in ("R5.2", "R5.4", "T4", "T5") if SPACES[c].valid_for(k)])
    claims = fsc.face_study_claims(None, None, rows, CLAIMS_CFG, {}, FIT_THETA_MAX)
    for r in claims.itertuples():
        if "-decay-" in r.claim_id:
            case, k = next((c, k) for c in SPACES for k in (1, 2) if r.claim_id == fsc.edge_claim_id("decay", c, k, 4))
            full = SPACES[case].degree(k) == k
            assert r.predicted == ("PASS" if full and k == 1 else "finding"), r.claim_id
    kinds = {cid.split("-")[2] for cid in claims.claim_id}
    assert kinds == {"decay", "bounded", "kappa"}


# ------------------------------------------------------------------ paper and config

def test_study_tables_cite_every_row_and_verdict():
    from infsup_contact.report.sections.face import face_paper_files

    t = small_face_tables()
    files = face_paper_files(**t)
    for name in ("face_patch_table.tex", "face_alpha_table.tex", "face_edge_table.tex"):
        assert name in files and files[name].rstrip().endswith(r"\end{tabular}")
    assert files["face_patch_table.tex"].count(r"\\") == 2 + t["patch"].case.nunique()
    assert files["face_alpha_table.tex"].count(r"\\") == 2 + t["alpha"].alpha.nunique()
    assert files["face_edge_table.tex"].count(r"\\") == 1 + t["edge"].groupby(["case", "k"]).ngroups
    assert r"\newcommand{\faceOutcomePatchHolding}{PASS}" in files["face_macros.tex"]
    assert r"\newcommand{\faceOutcomePatchLacking}{FAIL}" in files["face_macros.tex"]


@pytest.mark.parametrize("mutate, key", [
    (lambda f: f["patch"].update(elements=["prism"]), "studies.membranes3d.patch.elements[0]"),
    # HEX20: k = 2 only
    (lambda f: f["patch"].update(elements=["hex", "hex20"], k=[1]), "studies.membranes3d.patch.elements[1]"),
    (lambda f: f["patch"].update(pairs=[[4, 4]]), "studies.membranes3d.patch.pairs[0]"),
    (lambda f: f["alpha"].update(elements=["QUAD4"]), "studies.membranes3d.alpha.elements[0]"),
    (lambda f: f["alpha"].update(alphas=[0.5]), "studies.membranes3d.alpha.alphas"),
    (lambda f: f["edge_dropping"].update(theta=[0.0, 0.5, 1.0]), "studies.membranes3d.edge_dropping.theta"),
    (lambda f: f["edge_dropping"].update(fit_theta_max=0.012), "studies.membranes3d.edge_dropping.fit_theta_max"),
    (lambda f: f.pop("patch"), "studies.membranes3d"),
])
def test_bad_study_key_is_named(mutate, key):
    from infsup_contact.config.checks import ConfigError, check_config

    cfg = copy.deepcopy(yaml.safe_load((ROOT / "config" / "ci.yaml").read_text()))
    mutate(cfg["studies"]["membranes3d"])
    with pytest.raises(ConfigError) as err:
        check_config(cfg, ROOT / "workflow" / "schemas" / "config.schema.yaml")
    assert f"config key {key}" in str(err.value)
    assert len(str(err.value).splitlines()) == 1


def test_theta_window_of_the_helper_matches_the_configs():
    """The synthetic tables use the configs' fit window and its θ (the claims' data), and full cover."""
    window = sorted(t for t in THETAS if t <= FIT_THETA_MAX)
    for name in ("config.yaml", "ci.yaml"):
        ed = yaml.safe_load((ROOT / "config" / name).read_text())["studies"]["membranes3d"]["edge_dropping"]
        assert ed["fit_theta_max"] == FIT_THETA_MAX and 1.0 in ed["theta"]
        assert sorted(t for t in ed["theta"] if t <= FIT_THETA_MAX) == window
