"""A producer that is not installed (issue 50, item 1): the config's predicted claims stay in the
ledger with the verdict NOT RUN and the install command as evidence; the gate accepts them,
lists them and judges the rest as before; the paper counts them apart.

The producers section is config/config.yaml's own (Kratos, DOLFINx, GetFEM), each interpreter
pointed at a path that does not exist: the state of a fresh machine, without a subprocess.
"""
from __future__ import annotations

import os

import pandas as pd
import pytest
import yaml

from infsup_contact.io import read_table, write_csv_atomic
from infsup_contact.report.macros import claims_macros
from infsup_contact.report.tables import claims_table
from infsup_contact.study.claims.gate import GateError, gate
from infsup_contact.study.producers import producers_claims, producers_table
from test_producers_stage import CRITERION, ROOT


def _nothing_installed(tmp_path) -> dict:
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["producers"]
    for spec in cfg["codes"].values():
        spec["python"] = str(tmp_path / "no-such-python")
    return dict(cfg, criterion=CRITERION)


def _producer_claims(tmp_path):
    cfg = _nothing_installed(tmp_path)
    return cfg, producers_claims(producers_table(cfg, tmp_path / "work"), cfg)


def test_every_predicted_claim_is_kept_not_run(tmp_path):
    cfg, claims = _producer_claims(tmp_path)
    expected = [f"producer-{name}-{space}" for name, spec in cfg["codes"].items() for space in spec["predictions"]]
    assert list(claims.claim_id) == expected and set(claims.verdict) == {"NOT RUN"}
    assert set(claims.predicted) == {"PASS"}  # the prediction stays what the config says
    for c in claims.itertuples():
        name, space = c.claim_id.split("-", 2)[1:]
        spec = cfg["codes"][name]
        assert spec["install"] in c.evidence  # which command would run it
        assert all(f"{norm} {v}" in c.statement for norm, v in spec["predictions"][space]["verdicts"].items())
    path = tmp_path / "producers_claims.csv"  # what rule producers writes: a table with rows, as the ledger reads it
    write_csv_atomic(path, claims)
    assert len(read_table(path, "claims")) == len(expected)


def _ledger(tmp_path, rows, producers: pd.DataFrame):
    """The producers' claims table and a ledger of ``rows`` (id, verdict, predicted) plus them,
    written in that order (the gate refuses a ledger older than its tables)."""
    table, ledger = tmp_path / "producers_claims.csv", tmp_path / "claims.csv"
    own = pd.DataFrame([dict(claim_id=c, paper_ref="Thm 3", statement="s", evidence="e", verdict=v, predicted=p)
                        for c, v, p in rows])
    write_csv_atomic(table, producers)
    write_csv_atomic(ledger, pd.concat([own, producers], ignore_index=True))
    for i, path in enumerate((table, ledger)):
        os.utime(path, ns=(10**18 + i * 10**9, 10**18 + i * 10**9))
    return ledger, [(str(ledger), {str(table): "claims"})]


def test_the_gate_lists_not_run_claims_unjudged(tmp_path):
    _, producers = _producer_claims(tmp_path)
    ledger, stages = _ledger(tmp_path, [("a", "PASS", "PASS"), ("b", "FAIL", "FAIL"), ("c", "FAIL", "finding")],
                             producers)
    frame, summary = gate(ledger, stages)
    assert summary.startswith("verify-claims: 2 claims as predicted, 1 findings listed")
    assert f"{len(producers)} NOT RUN" in summary and all(c in summary for c in producers.claim_id)


@pytest.mark.parametrize("rows, needle", [
    ([("a", "PASS", "PASS"), ("b", "PASS", "FAIL")], "b (PASS, predicted FAIL)"),  # a wrong verdict still fails
    ([("a", "INCONCLUSIVE", "PASS")], "a (INCONCLUSIVE, predicted PASS)"),
    ([("c", "FAIL", "finding")], "nothing to verify"),  # NOT RUN is not checked: nothing checked is no pass
])
def test_the_gate_still_judges_what_ran(tmp_path, rows, needle):
    _, producers = _producer_claims(tmp_path)
    ledger, stages = _ledger(tmp_path, rows, producers)
    with pytest.raises(GateError) as err:
        gate(ledger, stages)
    assert needle in str(err.value) and "producer-" not in str(err.value), err.value


def test_the_paper_counts_not_run_apart(tmp_path):
    _, producers = _producer_claims(tmp_path)
    ran = pd.DataFrame([dict(claim_id="wohlmuth-dual", paper_ref="beyond the paper (Wohlmuth 2000)", statement="s",
                             evidence="e", verdict="PASS", predicted="PASS"),
                        dict(claim_id="thm3", paper_ref="Thm 3", statement="s", evidence="e", verdict="PASS",
                             predicted="PASS")])
    macros = {m.name: m.tex for m in claims_macros(pd.concat([ran, producers], ignore_index=True))}
    assert macros["nClaimsNotRun"] == str(len(producers))
    assert macros["nBeyondClaims"] == "1" and macros["nBeyondAsPredicted"] == "1"  # of those that ran
    assert macros["nClaimsChecked"] == "1" and macros["nClaimsAsPredicted"] == "1"
    assert macros["refVerdictBeyondThePaperCertifyingProductionCodes"] == r"\verdictfmt{NOT RUN}"
    assert macros["refOutcomeBeyondThePaperCertifyingProductionCodes"] == "INCONCLUSIVE"  # \byverdict: undecided
    assert r"\verdictfmt{NOT RUN}" in claims_table(producers)


def test_a_config_without_predictions_has_an_empty_claims_table_the_gate_accepts(tmp_path):
    """Predictions are optional per code: then the producers' claims table has no rows, which the
    ledger (workflow/scripts/claims.py) and the gate (kind ``claims?``, rules/claims.smk) accept;
    any other ledger table with no rows is still refused."""
    from infsup_contact.io import TableError

    cfg = _nothing_installed(tmp_path)
    for spec in cfg["codes"].values():
        spec.pop("predictions")
    empty = producers_claims(producers_table(cfg, tmp_path / "work"), cfg)
    assert empty.empty
    ledger, stages = _ledger(tmp_path, [("a", "PASS", "PASS")], empty)
    (product, sources), = stages
    frame, summary = gate(ledger, [(product, {path: "claims?" for path in sources})])
    assert len(frame) == 1 and "NOT RUN" not in summary
    with pytest.raises(TableError, match="no data rows"):
        gate(ledger, stages)
