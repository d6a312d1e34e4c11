"""The section templates (report/sections/templates.py, blocks.py) and the section tables declared
through them (report/sections/elastic.py, face.py, elastic3d.py, model_section.py): every row of a generated
tabular has the tabular's column count, blocks and rows come in the paper's order, the cells
say what the rows hold, and the claim counts add up under any ledger."""
import re

import numpy as np
import pandas as pd
import pytest

from infsup_contact.report.sections.blocks import claim_count_macros, n_as_predicted, outcome, predicted, verdict_macros
from infsup_contact.report.sections.templates import (NORM_TITLES, Group, at, beta_by_mesh_table, beta_cell,
                                                      case_blocks, case_table, kernel_cell, pairs_tex, tabular,
                                                      verdict_cell)
from infsup_contact.report.texformat import case_order, fmt_fixed
from infsup_contact.report.texnames import macro_name

TABULAR = re.compile(r"\\begin\{tabular\}\{((?:[^{}]|\{[^{}]*\})*)\}(.*?)\\end\{tabular\}", re.S)


def _columns(spec: str) -> int:
    """Columns of a tabular specification (``@{..}``, ``>{..}`` and rules take none)."""
    spec = re.sub(r"[@>]\{[^{}]*\}", "", spec)
    spec = re.sub(r"p\{[^{}]*\}", "p", spec)
    return sum(spec.count(c) for c in "lcrp")


def _cells(line: str) -> int:
    """Columns a row spans: its unescaped ``&`` + 1, a ``\\multicolumn{n}`` n columns."""
    spans = [int(n) for n in re.findall(r"\\multicolumn\{(\d+)\}", line)]
    return len(re.findall(r"(?<!\\)&", line)) + 1 + sum(n - 1 for n in spans)


def _rows_that_misfit(text: str) -> list[str]:
    found = TABULAR.findall(text)
    assert found, "no tabular"
    return [f"{_columns(spec)} columns: {line}" for spec, body in found for line in body.splitlines()
            if line.rstrip().endswith("\\\\") and _cells(line) != _columns(spec)]


# ----------------------------------------------------------------------------- small section inputs

def _elastic3d_beta(cases=("T3", "R5.2"), nus=(0.3, 0.49, 0.499, 0.4999), exponent=0.5) -> pd.DataFrame:
    """Elastic face rows: N = 4, 6 at ν = 0.3 and N = 4 at every ν; β_H = (1 − 2ν)^exponent, a
    kernel of dimension 3 (count 3) for R5.2."""
    out = []
    for case in cases:
        kernel = 3 if case == "R5.2" else 0
        for n, nu in [(6, 0.3)] + [(4, v) for v in nus]:
            out.append(dict(element="hex", case=case, k=2, N1=n, N2=n, norm="H", nu=nu,
                            beta=0.0 if kernel else (1 - 2 * nu) ** exponent, kernel_dim=kernel,
                            structural_kernel_dim=kernel))
    return pd.DataFrame(out)


def _elastic_files(which: str) -> dict:
    from helpers.elastic_tables import small_elastic_tables

    from infsup_contact.report.sections.elastic import elastic_paper_files

    t = dict(small_elastic_tables())
    if which == "matching, no modeling":
        t["beta"] = t["beta"][t["beta"].N1 == t["beta"].N2]
        t["hertz"] = t["hertz"][t["hertz"].study == "discretization"]
    return elastic_paper_files(**t)


def _face_files(which: str) -> dict:
    from helpers.face_tables import small_face_tables

    from infsup_contact.report.sections.face import face_paper_files

    t = small_face_tables()
    if which == "matching, no studies":
        return face_paper_files(t["beta"][t["beta"].N1 == t["beta"].N2], t["claims"])
    return face_paper_files(**t)


def _elastic3d_table(which: str) -> dict:
    from infsup_contact.report.sections.elastic3d import elastic3d_table

    nus = (0.3, 0.49, 0.499, 0.4999) if which == "sweep" else (0.3,)
    return {"elastic3d table": elastic3d_table(_elastic3d_beta(nus=nus), 0.49, 0.3, 4)}


def _model_section(which: str) -> dict:
    from helpers.face_tables import small_face_tables

    from infsup_contact.report.sections.model_section import model_section_tex

    t = small_face_tables()
    beta = t["beta"].assign(model="orthotropic")
    return {"model section": model_section_tex("ortho", {}, beta if which == "both norms" else beta[beta.norm == "H"],
                                               t["claims"])}


@pytest.mark.parametrize("files, which", [(_elastic_files, "as run"), (_elastic_files, "matching, no modeling"),
                                          (_face_files, "as run"), (_face_files, "matching, no studies"),
                                          (_elastic3d_table, "sweep"), (_elastic3d_table, "no other nu"),
                                          (_model_section, "both norms"), (_model_section, "H only")])
def test_every_row_fills_its_tabular(files, which):
    """A row with more or fewer cells than the tabular's columns is a LaTeX error or a shifted
    column; the head rows, the spanning titles and the notes count too."""
    tables = {name: text for name, text in files(which).items() if "macros" not in name}
    assert tables
    for name, text in tables.items():
        assert _rows_that_misfit(text) == [], name


def test_elastic3d_slope_of_a_square_root_law_is_one_half():
    """β_H = (1 − 2ν)^{1/2}: the fitted slope of log β_H against log(1 − 2ν) is 1/2 up to
    round-off (the cell's 3 decimals), each ν cell is β_H there, a space with a kernel shows 0
    and no slope."""
    from infsup_contact.report.sections.elastic3d import elastic3d_table

    text = elastic3d_table(_elastic3d_beta(), 0.49, 0.3, 4)
    rows = {line.split(" & ")[2]: line.removesuffix(r" \\").split(" & ") for line in text.splitlines()
            if line.startswith("hex & ")}
    assert rows["T3"][-1] == "0.500"
    assert rows["T3"][5:-1] == [fmt_fixed((1 - 2 * nu) ** 0.5, 4) for nu in (0.49, 0.499, 0.4999)]
    assert rows["R5.2"][3:5] == ["0", "3 (3)"] and rows["R5.2"][-1] == "--"


# ----------------------------------------------------------------------------- the templates


def test_tabular_puts_a_midrule_before_each_block_even_an_empty_one():
    text = tabular("ll", ["a & b \\\\"], [["1 & 2 \\\\"], [], ["3 & 4 \\\\"]], after=["% note"])
    lines = text.splitlines()
    assert lines[:3] == [r"\begin{tabular}{ll}", r"\toprule", "a & b \\\\"]
    assert lines[3:] == [r"\midrule", "1 & 2 \\\\", r"\midrule", r"\midrule", "3 & 4 \\\\", r"\bottomrule",
                         r"\end{tabular}", "% note"]
    assert text.endswith("\n")


def test_case_blocks_follow_the_groups_and_the_paper_order():
    frame = pd.DataFrame(dict(element=["tet", "hex", "hex", "tet", "hex"], case=["R5.2", "DUAL", "T3", "T3", "R5.2"]))
    sorted_blocks = case_blocks(frame, "element")
    assert [b[0][0] for b in sorted_blocks] == ["hex", "tet"]
    for block in sorted_blocks:
        assert [case for _, case in block] == case_order(frame[frame.element == block[0][0]].case)
    given = case_blocks(frame, "element", order=["tet", "quad", "hex"])
    assert [len(b) for b in given] == [2, 0, 3]  # a value without rows: an empty block, kept


def test_case_table_titles_span_their_groups():
    groups = [Group(("x", "y"), lambda key: ["1", "2"], "$k=1$"), Group(("z",), lambda key: ["3"])]
    text = case_table("lrrr", ("case",), lambda key: [key[0]], groups, [[("T3",)]])
    assert r" & \multicolumn{2}{c}{$k=1$} &  \\" in text  # an untitled group: blank in the title row
    assert "case & x & y & z \\\\" in text and "T3 & 1 & 2 & 3 \\\\" in text
    assert _rows_that_misfit(text) == []


def test_beta_by_mesh_table_has_a_block_per_norm_and_marks_a_mesh_not_run():
    """H before L², each under its title; a (k, case) without a row on some N shows ``--`` there."""
    rows = [dict(norm=norm, k=1, case=case, N2=n, beta=0.5) for norm in ("L2", "H") for case in ("R5.2", "T3")
            for n in (4, 8) if not (case == "R5.2" and n == 8)]
    text = beta_by_mesh_table(pd.DataFrame(rows), [4, 8], ("k",), ("$k$", "case"), lambda key: [str(key[0]), key[1]])
    assert text.index(NORM_TITLES["H"]) < text.index(NORM_TITLES["L2"])
    assert text.count("1 & T3 & 0.5000 & 0.5000 \\\\") == 2 and text.count("1 & R5.2 & 0.5000 & -- \\\\") == 2
    assert text.index("1 & T3") < text.index("1 & R5.2")  # the paper's order of the cases
    assert _rows_that_misfit(text) == []


def test_cells_say_what_the_rows_hold():
    rows = pd.DataFrame(dict(beta=[0.25, 0.0], kernel_dim=[0, 2], structural_kernel_dim=[0, 2], nu=[0.3, 0.49]))
    assert beta_cell(rows.iloc[:1]) == "0.2500" and beta_cell(rows.iloc[1:]) == "0"
    assert beta_cell(rows.iloc[1:], kernel_note=True) == "0 [2]" and beta_cell(rows.iloc[:0]) == "--"
    assert kernel_cell(rows.iloc[1:]) == "2 (2)" and kernel_cell(rows.iloc[:0]) == "--"
    assert len(at(rows, "nu", 0.49 + 1e-12)) == 1 and at(rows, "nu", 0.49 + 1e-12, rtol=0, atol=1e-14).empty
    claims = pd.DataFrame(dict(claim_id=["a", "b"], verdict=["PASS", "FAIL"], predicted=["PASS", "finding"]))
    assert [verdict_cell(claims, i) for i in ("a", "b", "c")] == ["P", "F*", "--"]
    assert pairs_tex([5, 4, 5], [4, 3, 4]) == "$4{:}3$, $5{:}4$"


# ----------------------------------------------------------------------------- the macro blocks

def _value(macros, name):
    return next(m.tex for m in macros if m.name == name)


@pytest.mark.parametrize("how", ["as is", "swapped", "all INCONCLUSIVE"])
def test_claim_counts_add_up_under_any_ledger(how):
    """Predicted + findings = all; as predicted <= predicted; swapping PASS and FAIL turns every
    predicted claim with a definite verdict from as predicted to not, and back."""
    from helpers.face_tables import small_face_tables

    claims = small_face_tables()["claims"]
    swap = {"PASS": "FAIL", "FAIL": "PASS", "INCONCLUSIVE": "INCONCLUSIVE"}
    flipped = claims.assign(verdict={"as is": claims.verdict, "swapped": claims.verdict.map(swap),
                                     "all INCONCLUSIVE": "INCONCLUSIVE"}[how])
    name = lambda *labels: macro_name("test", *labels)  # noqa: E731
    m = claim_count_macros(flipped, name, "claims.csv")
    n, pred, found = (int(_value(m, f"test{x}")) for x in ("NClaims", "NPredicted", "NFindings"))
    assert pred + found == n == len(claims) and int(_value(m, "testNAsPredicted")) <= pred
    definite = predicted(claims)[predicted(claims).verdict != "INCONCLUSIVE"]
    if how == "swapped":
        assert n_as_predicted(flipped) == len(definite) - n_as_predicted(claims)
    if how == "all INCONCLUSIVE":
        assert n_as_predicted(flipped) == 0
    assert len(claim_count_macros(flipped, name, "claims.csv", findings=False)) == 3


@pytest.mark.parametrize("verdicts, word", [(["PASS", "PASS"], "PASS"), (["FAIL"], "FAIL"),
                                            (["PASS", "FAIL"], "INCONCLUSIVE"), ([], "INCONCLUSIVE")])
def test_verdict_macros_count_every_claim_once(verdicts, word):
    rows = pd.DataFrame(dict(verdict=verdicts, claim_id=[f"x{i}" for i in range(len(verdicts))]), dtype=object)
    name = lambda *labels: macro_name("test", *labels)  # noqa: E731
    m = {mac.name: mac for mac in verdict_macros(rows, name, "kind", "t.csv: kind claims")}
    assert m["testOutcomeKind"].tex == word == outcome(verdicts)
    assert sum(int(m[f"testNKind{v}"].tex) for v in ("Pass", "Fail", "Inconclusive")) == int(m["testNKind"].tex)
    assert m["testNKindPass"].source == "t.csv: kind claims with verdict PASS"
    assert np.all([mac.source.startswith("t.csv: kind claims") for mac in m.values()])
