"""The curved segment's study (plans/arc.py, study/beta/arc.py, study/claims/arc.py): a small entry's
claims come out as predicted, its paper subsection is generated, and every bad entry is one line
naming its key."""
from __future__ import annotations

import math

import pandas as pd
import pytest

from infsup_contact.config.models import check_models
from infsup_contact.config.schema import ConfigError
from infsup_contact.plans import study_of
from infsup_contact.study.beta.arc import PAPER, arc_verdicts, curvature, radius_of

ENTRY = {"study": "arc", "k": [1], "radii": [2], "couplings": ["exact", "projection"],
         "series": {"matching": [[4, 4], [6, 6], [8, 8]], "plus1": [[4, 5], [6, 7], [8, 9]]},
         "cases": ["T3", "R5.2", "R5.4"]}
CLAIMS = {"slope_tolerance": 0.15, "beta_floor": 1e-3, "confidence": 0.95, "fit_window": 3}


@pytest.fixture(scope="module")
def run():
    config = {"studies": {"arc": ENTRY}, "claims": CLAIMS}
    check_models(config)
    study = study_of(config, "arc")
    beta = pd.concat([job.run() for job in study.jobs().values()], ignore_index=True)
    claims = study.claims({"beta": beta}, CLAIMS)
    return study, beta, claims


def test_the_table_has_every_radius_coupling_and_the_papers_rows(run):
    _, beta, _ = run
    runs = set(zip(beta.curvature, beta.coupling))
    assert runs == {(0.5, "exact"), (0.5, "projection"), (0.0, "exact"), (0.0, "projection"), (0.0, PAPER)}
    per_run = beta.groupby(["curvature", "coupling"]).size()
    assert (per_run == 3 * 2 * 6).all()  # cases × norms × (pairs in series)


def test_the_predicted_claims_come_out_as_predicted(run):
    _, _, claims = run
    checked = claims[claims.predicted != "finding"]
    assert len(checked) >= 5 and (checked.verdict == checked.predicted).all(), checked[["claim_id", "verdict", "evidence"]]


def test_the_verdicts_have_one_row_per_series(run):
    _, beta, _ = run
    verdicts = arc_verdicts(beta, 0.15, 1e-3, 0.95)
    assert len(verdicts) == 5 * 2 * 3 * 2  # runs × series × cases × norms
    t3 = verdicts[(verdicts.case == "T3") & (verdicts.norm == "H")]  # L2: Remark 3.1, stable looks like h^(1/2)
    assert (t3.verdict != "UNSTABLE").all() and (t3.verdict == "STABLE").any()  # stable; short series may be undecided


def test_the_paper_subsection_is_generated(run):
    study, beta, claims = run
    files = study.paper_files({"beta": beta, "claims": claims}, {"claims": CLAIMS})
    tex = files["arc.tex"]
    assert r"\subsection{The curved segment \texttt{arc}}" in tex and tex.count(r"\begin{tabular}") == 2
    assert r"$R=\infty$" in tex and "$R=2$" in tex


def test_curvature_names_a_radius_both_ways():
    assert curvature(math.inf) == 0.0 and radius_of(0.0) == math.inf and radius_of(curvature(4.0)) == 4.0


@pytest.mark.parametrize("change, key", [
    ({"radii": None}, "studies.arc.radii"),
    ({"model": "membranes"}, "studies.arc.model"),
    ({"series": {"short": [[4, 4], [6, 6]]}}, "studies.arc.series.short"),
    ({"series": {"dup": [[4, 4], [4, 4], [6, 6]]}}, "studies.arc.series.dup"),
    ({"cases": ["T3", "Q8"]}, "studies.arc.cases[1]"),
    ({"cases": ["NOPE"]}, "studies.arc.cases[0]"),
])
def test_a_bad_entry_is_one_line_naming_its_key(change, key):
    entry = {k: v for k, v in dict(ENTRY, **change).items() if v is not None}
    with pytest.raises(ConfigError) as err:
        check_models({"studies": {"arc": entry}})
    text = str(err.value)
    assert key in text and "\n" not in text


CYLINDER = {"study": "cylinder", "k": [1], "radii": [2], "couplings": ["exact", "projection"],
            "series": {"matching": [[2, 2], [3, 3], [4, 4]], "plus1": [[2, 3], [3, 4], [4, 5]]},
            "cases": ["T3", "R5.2", "DUAL-ALL"]}


def test_the_cylinder_study_runs_and_its_predictions_hold():
    """The same study on the 3D membranes (hexahedra, Γ a part of the cylinder): the flat face is
    reproduced bit for bit, the exact coupling keeps every kernel, no verdict flips."""
    config = {"studies": {"cyl": CYLINDER}, "claims": CLAIMS}
    check_models(config)
    study = study_of(config, "cyl")
    beta = pd.concat([job.run() for job in study.jobs().values()], ignore_index=True)
    claims = study.claims({"beta": beta}, CLAIMS)
    checked = claims[claims.predicted != "finding"]
    assert len(checked) >= 5 and (checked.verdict == checked.predicted).all(), checked[["claim_id", "evidence"]]
    tex = study.paper_files({"beta": beta, "claims": claims}, {"claims": CLAIMS})["cyl.tex"]
    assert r"\subsection{The curved face \texttt{cyl}}" in tex


@pytest.mark.parametrize("change, key", [({"patch": {"k": [1], "pairs": [[3, 2], [6, 4]], "c": [1, 1]}}, "studies.cyl.patch"),
                                         ({"cases": ["T3", "Q8"]}, "studies.cyl.cases[1]")])
def test_a_bad_cylinder_entry_is_one_line_naming_its_key(change, key):
    with pytest.raises(ConfigError) as err:
        check_models({"studies": {"cyl": dict(CYLINDER, **change)}})
    assert key in str(err.value) and "\n" not in str(err.value)
