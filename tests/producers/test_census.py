"""The census (study/census.py, report/figures/census.py, report/sections/producers.py census_tex) on
synthetic producers tables: no code is run. Each row of the census is one (code, space, offset)
of the producers table, its verdict the H row's; a code not installed has its configured spaces
and offsets as NOT RUN rows with the install command; the fix is the prediction's; the date of a
prediction is the oldest commit holding its verdicts and kernel as they are now."""
from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pandas as pd
import pytest
import yaml

from infsup_contact.io import read_table, write_csv_atomic
from infsup_contact.report.figures.census import plot_census_modes, unstable_panels
from infsup_contact.report.sections.producers import census_tex
from infsup_contact.study.census import (CENSUS_COLUMNS, NONE, NOT_GIVEN, UNCOMMITTED, census_table, matching,
                                         prediction_commits)
from infsup_contact.study.producers import COLUMNS, MODE_COLUMNS


def _row(code, space, offset, norm, verdict, kernels=(0, 0, 0), dims=(7, 15, 31), status="ok", **kw):
    row = dict(producer=code, version="1.2.3", space=space, offset=offset, norm=norm, status=status, verdict=verdict,
               kernel_dim=max(kernels), beta_levels=" ".join("0" if k else "0.5" for k in kernels),
               kernel_levels=" ".join(map(str, kernels)), h_levels="0.125 0.0625 0.03125", slope=0.0, slope_lo=-0.1,
               slope_hi=0.1, evidence="the evidence", seconds=1.0, install="make producers-a", system=f"{code} {space}",
               dim_M_levels=" ".join(map(str, dims)))
    row.update(kw)
    return row


def _frames():
    """Code a: space bad (kernel 2 in H, fix given), good (STABLE), nofix (UNSTABLE, no fix), at
    offsets 0 and 1 in H and L2; code b not installed (two spaces, offsets [0, 1] from the section)."""
    rows = []
    for offset in (0, 1):
        for norm in ("L2", "H"):  # H second: the census picks it by name, not position
            rows += [_row("a", "bad", offset, norm, "UNSTABLE", kernels=(2, 2, 2)),
                     _row("a", "good", offset, norm, "STABLE" if norm == "H" else "UNSTABLE"),
                     _row("a", "nofix", offset, norm, "UNSTABLE")]
    rows.append(dict(producer="b", version="", space="-", offset=0, norm="-", status="not installed", verdict="",
                     evidence="b not importable: run `make producers-b`", install="make producers-b"))
    table = pd.DataFrame(rows).reindex(columns=list(COLUMNS))
    stable = {"H": "STABLE", "L2": "UNSTABLE"}
    cfg = {"N": [8, 16, 32], "offsets": [0, 1], "norms": ["H", "L2"], "codes": {
        "a": {"spaces": ["bad", "good", "nofix"], "install": "make producers-a", "predictions": {
            "bad": {"verdicts": {"H": "UNSTABLE", "L2": "UNSTABLE"}, "kernel": 2, "why": "w", "fix": "good: drop two"},
            "good": {"verdicts": stable, "kernel": 0, "why": "w"},
            "nofix": {"verdicts": {"H": "UNSTABLE", "L2": "UNSTABLE"}, "why": "w"}}},
        "b": {"spaces": ["x", "y"], "install": "make producers-b", "predictions": {
            "x": {"verdicts": {"H": "UNSTABLE", "L2": "UNSTABLE"}, "why": "w", "fix": "x-fixed"},
            "y": {"verdicts": stable, "why": "w"}}}}}
    claims = pd.DataFrame({"claim_id": ["producer-a-bad", "producer-a-good", "producer-a-nofix", "producer-b-x",
                                        "producer-b-y"],
                           "verdict": ["PASS", "PASS", "FAIL", "NOT RUN", "NOT RUN"]})
    return table, claims, cfg


def test_census_rows_one_per_code_space_offset_with_the_h_verdict_and_the_fix(tmp_path):
    table, claims, cfg = _frames()
    census = census_table(table, claims, cfg, {("a", "bad"): "abc1234 2026-01-01"})
    assert list(census.columns) == list(CENSUS_COLUMNS)
    keys = list(zip(census.code, census.space, census.offset))
    assert len(keys) == len(set(keys)) == 3 * 2 + 2 * 2
    a = census[census.code == "a"].set_index(["space", "offset"])
    assert (a.norm == "H").all() and (a.matching == [matching(k) for _, k in a.index]).all()
    assert set(a.matching) == {"matching", "non-matching"}
    assert a.loc[("good", 0), "verdict"] == "STABLE" and a.loc[("good", 0), "other_norms"] == "L2 UNSTABLE"
    assert a.loc[("bad", 1), "kernel_vs_dim"] == "2/7 2/15 2/31"
    assert a.loc[("bad", 0), "fix"] == "good: drop two"
    assert a.loc[("good", 0), "fix"] == NONE  # nothing to fix
    assert a.loc[("nofix", 0), "fix"] == NOT_GIVEN  # UNSTABLE, the prediction names no fix
    assert a.loc[("nofix", 0), "claim"] == "FAIL"
    assert a.loc[("bad", 0), "predicted_in"] == "abc1234 2026-01-01" and a.loc[("good", 0), "predicted_in"] == NONE
    b = census[census.code == "b"].set_index(["space", "offset"])
    assert sorted(b.index) == [("x", 0), ("x", 1), ("y", 0), ("y", 1)]
    assert (b.verdict == "NOT RUN").all() and (b.claim == "NOT RUN").all()
    assert b.evidence.str.contains("make producers-b", regex=False).all()
    assert b.loc[("x", 0), "fix"] == "x-fixed" and b.loc[("y", 0), "fix"] == NONE
    assert list(b.predicted) == ["UNSTABLE", "UNSTABLE", "STABLE", "STABLE"]
    path = tmp_path / "census.csv"  # what the rule writes, the schema the paper reads it by
    write_csv_atomic(path, census)
    assert len(read_table(path, "census")) == len(census)


def test_census_refused_row_and_a_space_without_prediction():
    table, claims, cfg = _frames()
    extra = pd.DataFrame([_row("a", "new", 0, "H", "", status="refused: levels.yaml: bad key"),
                          _row("a", "new", 0, "L2", "STABLE")]).reindex(columns=list(COLUMNS))
    census = census_table(pd.concat([table, extra], ignore_index=True), claims, cfg)
    new = census[census.space == "new"].iloc[0]
    assert new.verdict == "refused" and new.status.startswith("refused: ") and new.other_norms == "L2 STABLE"
    assert new.predicted == new.claim == new.predicted_in == NONE


def _git(root, *args):
    subprocess.run(["git", "-C", str(root), *args], check=True, capture_output=True,
                   env={"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t",
                        "GIT_COMMITTER_EMAIL": "t@t", "PATH": "/usr/bin:/bin", "HOME": str(root)})


def _commit(root, codes, message):
    path = root / "config" / "config.yaml"
    path.parent.mkdir(exist_ok=True)
    path.write_text("other: 1\n" + yaml.safe_dump({"producers": {"N": [8, 16, 32], "codes": codes}}) + "figures: {}\n")
    _git(root, "add", "config/config.yaml")
    _git(root, "commit", "-q", "-m", message)
    return subprocess.run(["git", "-C", str(root), "log", "-1", "--format=%h"], capture_output=True,
                          text=True).stdout.strip()


@pytest.mark.skipif(shutil.which("git") is None, reason="git not installed")
def test_prediction_commits_date_the_verdict_not_the_words(tmp_path):
    pred = {"verdicts": {"H": "UNSTABLE"}, "kernel": 2, "why": "first words"}
    _git(tmp_path, "init", "-q")
    first = _commit(tmp_path, {"c": {"predictions": {"s": pred}}}, "prediction")
    _commit(tmp_path, {"c": {"predictions": {"s": dict(pred, why="other words", fix="f")}}}, "words")
    flipped = dict(pred, verdicts={"H": "STABLE"})
    now = {"c": {"predictions": {"s": flipped, "t": pred}}}
    assert prediction_commits(now, tmp_path)[("c", "s")] == UNCOMMITTED  # a verdict no commit holds
    assert prediction_commits({"c": {"predictions": {"s": pred}}}, tmp_path)[("c", "s")].split()[0] == first
    third = _commit(tmp_path, now, "verdict changed")
    dated = prediction_commits(now, tmp_path)
    assert dated[("c", "s")].split()[0] == third and dated[("c", "t")].split()[0] == third


def test_prediction_commits_without_a_repository_say_none(tmp_path):
    codes = {"c": {"predictions": {"s": {"verdicts": {"H": "STABLE"}, "why": "w"}}}}
    assert prediction_commits(codes, tmp_path / "not-a-repo") == {("c", "s"): NONE}


def _modes(census):
    """A mode per (code, space, offset) of the census that ran: a sine on [0, 1], max 1."""
    x = np.linspace(0.0, 1.0, 25)
    parts = [pd.DataFrame(dict(producer=r.code, space=r.space, offset=r.offset, level=2, h=1 / 32, beta=0.0,
                               in_kernel=True, x=x, mu=np.sin(np.pi * x)))
             for r in census[census.status == "ok"].itertuples()]
    return pd.concat(parts, ignore_index=True)[list(MODE_COLUMNS)]


def test_mode_figure_draws_the_unstable_spaces_only(tmp_path):
    table, claims, cfg = _frames()
    census = census_table(table, claims, cfg)
    modes = _modes(census)
    pdf, png = tmp_path / "m.pdf", tmp_path / "m.png"
    panels = plot_census_modes(census, modes, pdf, png)
    assert panels == [("a", "bad"), ("a", "nofix")]  # not good (STABLE), not b (NOT RUN: no mode)
    assert pdf.stat().st_size > 0 and png.stat().st_size > 0
    tex = census_tex(census, panels)
    assert r"\includegraphics" in tex and tex.count(r" \\" + "\n") == len(census) + 1  # the header and a line per row
    stable = census[census.space == "good"]
    assert plot_census_modes(stable, modes, tmp_path / "s.pdf", tmp_path / "s.png") == []
    assert r"\includegraphics" not in census_tex(stable, [])
    assert unstable_panels(census, modes.iloc[:0]) == []  # no mode written: no panel


def test_a_stabilised_systems_class_is_carried_to_the_census_and_the_paper():
    table, claims, cfg = _frames()
    table["stabilisation"] = np.where((table.space == "bad") & (table.norm == "H"), "regularised", "")
    census = census_table(table, claims, cfg)
    assert set(census[census.space == "bad"].stabilisation) == {"regularised"}
    assert set(census[census.space != "bad"].stabilisation) == {NONE}  # no C block, or not run
    tex = census_tex(census, [])
    assert tex.count("UNSTABLE; regularised") == 2  # offsets 0 and 1


def test_a_manifest_not_described_in_H_leads_with_the_next_norm():
    """A `norm: given` manifest (FreeFEM's star-shaped skeleton) has no H^{-1/2} certificate: its
    stage row "H" is the pencil as written, so the census leads with the next norm that ran (L2 in
    this frame); a described manifest keeps H."""
    table, claims, cfg = _frames()
    table["norm_as_written"] = np.where(table.space == "good", "given", "H")
    census = census_table(table, claims, cfg)
    good, bad = census[census.space == "good"], census[census.space == "bad"]
    assert set(good.norm) == {"L2"} and set(good.verdict) == {"UNSTABLE"} and set(good.other_norms) == {"H STABLE"}
    assert set(bad.norm) == {"H"}
