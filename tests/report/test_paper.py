"""The paper stage: macros and tables generated from (synthetic) result tables, and paper.tex.

Fast unit tests on synthetic tables shaped like the real ones (the claims ledger is built by
the real ``claims.ledger`` from them, so claim ids are the real ones), plus one end-to-end
LaTeX build when latexmk is installed.
"""
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from infsup_contact import report as pt
from infsup_contact.discretization.spaces.registry import PAPER_CASES
from infsup_contact.study.claims.membranes import REM55_INSTANCES, ledger, nonmatching_claims

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "paper" / "paper.tex"
CFG = yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())
FIGURES = ["fig1_model_problem", "fig2_beta_H", "fig3_beta_L2", "fig4_families",
           "fig5_contact_solutions", "fig6_convergence", "fig7_speed_accuracy", "fig8_dual"]
CASES_K = {1: ["T3", "R5.2", "R5.4", "DUAL", "DUAL-ALL", "P0-2h"],
           2: ["T3", "R5.2", "T4", "R5.4", "T5", "DUAL", "DUAL-ALL"]}
KERNEL = {"R5.2": 2, "R5.4": 1, "DUAL-ALL": 2}
DIM_M = {"T3": lambda n, k: n * k - 1, "R5.2": lambda n, k: n * k + 1, "T4": lambda n, k: n * (k - 1),
         "R5.4": lambda n, k: n * k, "T5": lambda n, k: n * (k - 1) + 1, "DUAL": lambda n, k: n * k - 1,
         "DUAL-ALL": lambda n, k: n * k + 1, "P0-2h": lambda n, k: max(n // 2, 1)}


# ----------------------------------------------------------------------------- synthetic tables

def synth_beta(seed=0):
    """β rows: 3 families, k = 1, 2, even and odd matching N, two multiplier meshes, 3:2 and
    2:1 finer and 3:4 coarser non-matching pairs; values with 6 random decimals."""
    rng = np.random.default_rng(seed)
    series = {"matching": [(n, n) for n in (4, 8, 16, 32, 5, 9, 17)],
              "ratio3-2": [(6, 4), (12, 8), (24, 16)], "ratio2-1": [(16, 8)], "ratio3-4": [(6, 8)],
              "plus1": [(9, 8), (17, 16), (33, 32)], "sqrt2": [(11, 8), (23, 16), (45, 32)]}
    pairs = [(name, p) for name, ps in series.items() for p in ps]
    rows = []
    for fam in ("structured", "perturbed", "unstructured"):
        for k, cases in CASES_K.items():
            for name, (n1, n2) in pairs:
                for mm in ("omega2", "union"):
                    for case in cases:
                        for norm in ("H", "L2"):
                            kern = KERNEL.get(case, 0) if n1 == n2 and mm == "omega2" else 0
                            base = 0.8 + 0.2 * rng.random()
                            val = base * (1.0 if norm == "H" else (1.0 / n2) ** 0.5)
                            beta = 0.0 if kern else round(val, 6)
                            rows.append(dict(case=case, k=k, family=fam, N1=n1, N2=n2, multiplier_mesh=mm,
                                             c1=1.0, c2=1.0, norm=norm, beta=beta, kernel_dim=kern,
                                             structural_kernel_dim=kern, kernel_check="agree", kernel_detected=0,
                                             kernel_margin_decades=round(2 + 12 * rng.random(), 6),
                                             kernel_decision="clear", smallest_nonzero=round(val, 6),
                                             beta_v1_zero=round(0.9 * beta, 6), dim_M=DIM_M[case](n2, k),
                                             dim_W=n2 * k - 1, series=name, seed=0 if fam == "perturbed" else np.nan,
                                             package_version="0.1.0",
                                             git_commit="0123456789abcdef", config_hash="feedc0ffee00"))
    return pd.DataFrame(rows)


def synth_contact(seed=1):
    rng = np.random.default_rng(seed)
    rows = []
    for scene, ns in (("manufactured", (4, 8, 16, 32)), ("membranes", (4, 8, 16))):
        for k, cases in CASES_K.items():
            for case in cases:
                for n in ns:
                    e = rng.uniform(0.5, 2.0) * float(n) ** -k
                    rows.append(dict(scene=scene, case=case, k=k, family="structured", N1=n, N2=n, c1=1.0,
                                     c2=1.0, iterations=int(rng.integers(1, 9)), energy_error=e,
                                     l2_error=e / n, lambda_l2_error=rng.uniform(1e-4, 1e-2),
                                     lambda_hm12_error=rng.uniform(1e-6, 1e-3), nonunique=False,
                                     max_penetration=rng.uniform(0, 1e-3),
                                     min_lambda_pointwise=-rng.uniform(0, 1e-2)))
    return pd.DataFrame(rows)


def synth_rates(contact):
    rows = []
    for (scene, case, k), g in contact.groupby(["scene", "case", "k"]):
        for i, m in enumerate(pt.MEASURES):
            rows.append(dict(scene=scene, case=case, k=k, family="structured", measure=m,
                             slope=k + 0.0123 * (i + 1) + 0.001 * len(case), stderr=0.0042 * (i + 1), points=3,
                             h_min=1 / g.N2.max(), expected=float(k) if m == "energy_error" and
                             scene == "manufactured" else np.nan))
    return pd.DataFrame(rows)


def synth_extra():
    rows = [dict(claim_id="eq3.13-sign", paper_ref="(3.13) erratum", statement="λ = −c1 ∂u1/∂x2",
                 evidence="relative L²(Γ) mismatch 0.0412 (i=1), 0.0251 (i=2); vs +c_i∂u_ih/∂x2: 2, 1.99",
                 verdict="PASS", predicted="PASS")]
    rows += [dict(claim_id=cid, paper_ref="Rem 5.5", statement=st, evidence="β_h in [0.5, 0.6]",
                  verdict="PASS", predicted="PASS") for cid, st, *_ in REM55_INSTANCES]
    return pd.DataFrame(rows)


def synth_speed(contact):
    s = contact[["scene", "case", "k", "N2", "energy_error", "lambda_hm12_error"]].rename(columns={"N2": "N"})
    s = s.assign(seconds=1.234e-3 * s.N ** 1.5 * s.k, family="structured")
    return s.assign(pareto_energy=np.arange(len(s)) % 3 == 0)[[*pt.SPEED_COLUMNS, "family", "pareto_energy"]]


def synth_bench(what):
    rows = []
    routes = {"beta": ["ours", "limit", "eigsh"],
              "contact": ["ours", "ours_end_to_end", "floor", "limit", "osqp", "clarabel"]}[what]
    for k in (1, 2):
        for n in (8, 16):
            for i, route in enumerate(routes):
                t = 0.01 * n * k * (1 + 1.7 * i)
                rows.append(dict(what=what, route=route, k=k, N=n, seconds_median=t, seconds_min=t, seconds_max=t,
                                 ratio_to_ours=1 + 1.7 * i, max_abs_diff=0.0 if i == 0 else 3.21e-9 * i))
    return pd.DataFrame(rows)


@pytest.fixture(scope="module")
def tables():
    beta, contact = synth_beta(), synth_contact()
    rates = synth_rates(contact)
    claims = ledger(beta, rates, synth_extra(), CFG["claims"], CFG["contact"]["primary_scene"])
    prov = {"versions": {"ngsolve": "6.2.0", "numpy": "2.0", "scipy": "1.0", "snakemake": "9.0"}, "cpu_count": 2}
    return dict(beta=beta, contact=contact, rates=rates, claims=claims, speed=synth_speed(contact),
                bench_beta=synth_bench("beta"), bench_contact=synth_bench("contact"), cfg=CFG, prov=prov)


def _macros(t):
    return pt.all_macros(t["beta"], t["contact"], t["rates"], t["claims"], t["speed"], t["bench_beta"],
                         t["bench_contact"], t["cfg"], t["prov"])


def _by_name(t):
    return {m.name: m for m in _macros(t)}


# ----------------------------------------------------------------------------- naming

def test_tokens_and_number_words():
    assert [pt.token(c) for c in PAPER_CASES] == ["Tthree", "Rfivetwo", "Tfour", "Rfivefour", "Tfive"]
    assert pt.token("eq3.13-sign") == "EqthreethirteenSign"
    assert pt.token("Thm3-k1-structured-evenN") == "ThmthreeKoneStructuredEvenN"
    assert pt.number_word(64) == "sixtyfour" and pt.number_word(128) == "onehundredtwentyeight"
    assert pt.macro_name("beta", "H", "T3", "Kone") == "betaHTthreeKone"
    assert pt.is_generated_name("betaHTthreeKone") and not pt.is_generated_name("beta")
    assert not pt.is_generated_name("ref") and not pt.is_generated_name("beta2")


def test_macro_names_are_letters_only_unique_and_generated(tables):
    names = [m.name for m in _macros(tables)]
    assert all(re.fullmatch(r"[A-Za-z]+", n) for n in names)
    assert len(names) == len(set(names))
    assert all(pt.is_generated_name(n) for n in names)
    text = pt.macros_tex(_macros(tables))
    assert pt.defined_macros(text) == set(names)


def test_duplicate_macro_is_an_error():
    m = pt.Macro("betaX", "1", "a")
    with pytest.raises(pt.PaperTexError, match="defined twice"):
        pt.macros_tex([m, m])


# ----------------------------------------------------------------------------- values vs tables

_SOURCE = re.compile(r"^(?P<table>[\w/]+\.csv):(?P<col>\w+)(?::(?P<agg>min|max))?(?P<filters>(?: \S+=\S+)*)$")
TABLE_OF = {"beta.csv": "beta", "contact.csv": "contact", "rates.csv": "rates", "claims.csv": "claims",
            "speed_accuracy.csv": "speed", "benchmarks/beta.csv": "bench_beta",
            "benchmarks/contact.csv": "bench_contact"}


def _select(frame, filters):
    sel = frame
    for item in filters.split():
        key, val = item.split("=", 1)
        if key == "matching":
            sel = sel[sel.N1 == sel.N2]
            continue
        col = sel[key]
        numeric = pd.api.types.is_numeric_dtype(col) and not pd.api.types.is_bool_dtype(col)
        sel = sel[np.isclose(col.astype(float), float(val))] if numeric else sel[col.astype(str) == val]
    return sel


def _half_ulp(tex: str) -> float:
    """Half a unit in the last displayed place of a formatted number."""
    m = re.fullmatch(r"\\ensuremath\{-?\d+(?:\.(\d+))?\\times10\^\{(-?\d+)\}\}", tex)
    if m:
        return 0.5 * 10.0 ** (int(m.group(2)) - len(m.group(1) or ""))
    decimals = len(tex.split(".")[1]) if "." in tex else 0
    return 0.5 * 10.0 ** -decimals


def test_every_table_macro_is_its_table_value(tables):
    """Each macro with a table source is that table's value, rounded as displayed (a 'grep'
    of the macro's number in its CSV that knows which row and column to look at)."""
    checked = 0
    for m in _macros(tables):
        src = _SOURCE.match(m.source)
        if not src:
            continue
        rows = _select(tables[TABLE_OF[src["table"]]], src["filters"])
        assert len(rows) >= 1, m
        col = rows[src["col"]]
        if src["agg"] is None:
            assert len(rows) == 1, (m, rows)
        value = col.agg(src["agg"]) if src["agg"] else col.iloc[0]
        if src["col"] == "verdict":  # typeset (claimVerdict…) or the bare word for \byverdict (claimOutcome…)
            assert m.tex in (rf"\verdictfmt{{{value}}}", value), m
        elif src["col"] == "evidence":
            assert m.tex == pt.latex_escape(value), m
        else:
            shown = pt.parse_number(m.tex)
            assert abs(shown - float(value)) <= _half_ulp(m.tex) * (1 + 1e-9) + 1e-12, (m, value)
        checked += 1
    assert checked > 500


def test_every_number_appears_in_its_csv(tables, tmp_path):
    """The literal check: write the synthetic tables as CSV and find each table macro's number
    (at its displayed precision) among the numbers of its column in the CSV text."""
    for key in ("beta", "rates", "contact", "speed"):
        tables[key].to_csv(tmp_path / f"{key}.csv", index=False, float_format="%.12g")
    for m in _macros(tables):
        src = _SOURCE.match(m.source)
        if not src or TABLE_OF[src["table"]] not in ("beta", "rates", "contact", "speed") \
                or src["col"] in ("verdict", "evidence"):
            continue
        csv = pd.read_csv(tmp_path / f"{TABLE_OF[src['table']]}.csv", dtype=str)
        shown, tol = pt.parse_number(m.tex), _half_ulp(m.tex) * (1 + 1e-9) + 1e-12
        assert any(abs(float(v) - shown) <= tol for v in csv[src["col"]].dropna()), m


def test_changing_one_value_changes_its_macro(tables):
    before = _by_name(tables)
    t = dict(tables)
    beta = t["beta"].copy()
    b = beta[(beta.family == "structured") & (beta.case == "T3") & (beta.k == 1) & (beta.norm == "H")
             & (beta.multiplier_mesh == "omega2") & (beta.N1 == beta.N2)]
    beta.loc[b.N2.idxmax(), "beta"] = 0.123456
    rates = t["rates"].copy()
    sel = (rates.scene == "manufactured") & (rates.case == "T5") & (rates.k == 2) & (rates.measure == "energy_error")
    rates.loc[sel, "slope"] = 1.5
    claims = t["claims"].copy()
    claims.loc[claims.claim_id == "eq3.13-sign", "verdict"] = "FAIL"
    t.update(beta=beta, rates=rates, claims=claims)
    after = _by_name(t)
    assert after["betaHTthreeKone"].tex == "0.1235" != before["betaHTthreeKone"].tex
    assert after["slopeEnergyTfiveKtwo"].tex == "1.50" != before["slopeEnergyTfiveKtwo"].tex
    assert after["claimVerdictEqthreethirteenSign"].tex == r"\verdictfmt{FAIL}"
    assert after["refVerdictThreethirteenErratum"].tex == r"\verdictfmt{FAIL}"
    changed = {n for n in before if before[n].tex != after[n].tex}
    assert changed == {"betaHTthreeKone", "betaHTthreeKoneNthirtytwo", "betaMinHTthreeKone",
                       "slopeEnergyTfiveKtwo", "claimVerdictEqthreethirteenSign",
                       "claimOutcomeEqthreethirteenSign", "refOutcomeThreethirteenErratum",
                       "refVerdictThreethirteenErratum", "refPassThreethirteenErratum",
                       "nClaimsPass", "nClaimsFail", "nClaimsAsPredicted"}, changed


def test_counts_match_the_ledger(tables):
    m, claims = _by_name(tables), tables["claims"]
    beyond = claims.paper_ref.str.startswith("beyond the paper")
    paper = claims[(claims.predicted != "finding") & ~beyond]
    assert int(m["nClaims"].tex) == len(paper)
    # claims about spaces the paper does not treat (DUAL, DUAL-ALL) are counted apart
    ours = claims[(claims.predicted != "finding") & beyond]
    assert len(ours) > 0 and int(m["nBeyondClaims"].tex) == len(ours)
    assert int(m["nClaims"].tex) + int(m["nBeyondClaims"].tex) + int(m["nFindings"].tex) == len(claims)
    assert int(m["nClaimsPass"].tex) + int(m["nClaimsFail"].tex) + int(m["nClaimsInconclusive"].tex) == len(paper)
    assert int(m["nFindings"].tex) == (claims.predicted == "finding").sum()
    assert int(m["refClaimsThmThree"].tex) == (claims.paper_ref == "Thm 3").sum()


# ----------------------------------------------------------------------------- tables

def test_tables_contain_the_values(tables):
    files = pt.paper_files(**tables)
    assert set(files) == set(pt.GENERATED_FILES)
    beta = tables["beta"]
    r = beta[(beta.family == "structured") & (beta.case == "T5") & (beta.k == 2) & (beta.norm == "L2")
             & (beta.multiplier_mesh == "omega2") & (beta.N1 == 16) & (beta.N2 == 16)].iloc[0]
    assert pt.fmt_fixed(r.beta, 4) in files["beta_table.tex"]
    assert r"\begin{longtable}" in files["claims_table.tex"]
    # every claim once: in the longtable, or (non-matching bounded claims) as a letter of the grid
    grid = nonmatching_claims(tables["claims"])
    assert files["claims_table.tex"].count(r"\verdictfmt{") == len(tables["claims"]) - len(grid)
    cells = re.findall(r"\\texttt\{([-PFI]+)\}", files["nonmatching_table.tex"])
    assert sum(len(c) - c.count("-") for c in cells) == len(grid)
    assert files["rates_table.tex"].count(r"\\") >= len(tables["rates"]) // len(pt.MEASURES)
    for f in files.values():  # no raw UTF-8 left for pdflatex
        assert f.isascii()


def test_latex_escape():
    assert pt.latex_escape("50% & x_1") == r"50\% \& x$_{1}$"
    assert pt.latex_escape("β_h in H^-1/2_00") == r"$\beta_{h}$ in H$^{-1/2}_{00}$"
    assert pt.latex_escape("kernel_dim") == r"kernel\_dim"
    with pytest.raises(pt.PaperTexError, match="U\\+2603"):
        pt.latex_escape("snow ☃", "claims.csv evidence")


def test_speed_table_marks_the_pareto_front(tables):
    speed = tables["speed"]
    text = pt.speed_table(speed)
    rows = pt.speed_rows(speed)
    assert text.count(r"$\bullet$ \\") == rows.pareto_energy.sum()
    assert r"\bullet" not in pt.speed_table(speed.drop(columns="pareto_energy"))


def test_missing_speed_columns_is_a_clear_error(tables):
    with pytest.raises(pt.PaperTexError, match="speed_accuracy.csv: missing column"):
        pt.speed_macros(tables["speed"].drop(columns=["seconds"]), CFG["contact"]["primary_scene"])


# ----------------------------------------------------------------------------- paper.tex

def test_paper_uses_only_generated_macros_and_inputs(tables):
    tex = PAPER.read_text()
    files = pt.paper_files(**tables)
    pt.check_paper(tex, files)  # raises on a missing macro or \input
    used = pt.used_generated_macros(tex)
    assert {"betaHTthreeKone", "nClaimsPass", "slopeEnergyTthreeKone"} <= used
    assert pt.used_inputs(tex) <= set(pt.GENERATED_FILES) | set(pt.SOURCE_INPUTS)
    assert not {n for n in re.findall(r"\\newcommand\{\\([A-Za-z]+)\}", tex) if pt.is_generated_name(n)}


def test_paper_has_no_typed_results():
    """Results are macros: no number with 3+ decimals, no scientific notation in paper.tex."""
    body = re.sub(r"(?<!\\)%.*", "", PAPER.read_text())
    assert not re.findall(r"\d\.\d{3,}", body)
    assert not re.findall(r"\d[eE]-?\d|\\times\s*10\^", body)


def test_fastest_for_targets_is_the_cheapest_row_reaching_each_target(tables):
    speed = tables["speed"]
    front = pt.fastest_for_targets(speed, "energy_error")
    assert len(front) and set(front.scene) <= set(speed.scene)
    for _, r in front.iterrows():
        ok = speed[(speed.scene == r.scene) & (speed.energy_error <= r.target)]
        assert r.seconds == ok.seconds.min() and r.error <= r.target
    decades = np.log10(front.target.to_numpy())
    assert np.allclose(decades, np.round(decades))
    table = pt.front_table(speed)
    assert table.count(r"\\") >= len(front) and "$10^{" in table
    assert "targets)" in pt.front_winner(speed, "energy_error")


def test_benchmark_routes_left_out_by_the_config_read_n_a(tables):
    """peers: [] in the config: the paper still builds and says the peers were not run."""
    t = dict(tables)
    t["bench_contact"] = tables["bench_contact"][~tables["bench_contact"].route.isin(["osqp", "clarabel"])]
    files = pt.paper_files(**t)
    pt.check_paper(PAPER.read_text(), files)
    assert re.search(r"\\newcommand\{\\benchContactOsqpRatio\}\{n/a\}", files["macros.tex"])


def test_missing_case_is_reported_by_name(tables):
    t = dict(tables)
    t["beta"] = tables["beta"][tables["beta"].case != "T5"]
    with pytest.raises(pt.PaperTexError, match="betaHTfiveKtwo"):
        pt.check_paper(PAPER.read_text(), pt.paper_files(**t))


# ----------------------------------------------------------------------------- end to end

def placeholder_pdf(label: str, w: int = 400, h: int = 250) -> bytes:
    """A minimal valid one-page PDF (grey box and a label): stands in for a figure."""
    content = f"0.9 g 0 0 {w} {h} re f 0 g BT /F1 16 Tf 20 {h // 2} Td ({label}) Tj ET".encode()
    objs = [b"<< /Type /Catalog /Pages 2 0 R >>", b"<< /Type /Pages /Kids [3 0 R] /Count 1 >>",
            f"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 {w} {h}] /Contents 4 0 R "
            f"/Resources << /Font << /F1 5 0 R >> >> >>".encode(),
            b"<< /Length %d >>\nstream\n" % len(content) + content + b"\nendstream",
            b"<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>"]
    out, offsets = bytearray(b"%PDF-1.4\n"), []
    for i, obj in enumerate(objs, 1):
        offsets.append(len(out))
        out += b"%d 0 obj\n" % i + obj + b"\nendobj\n"
    xref = len(out)
    out += b"xref\n0 %d\n0000000000 65535 f \n" % (len(objs) + 1)
    out += b"".join(b"%010d 00000 n \n" % o for o in offsets)
    out += b"trailer\n<< /Size %d /Root 1 0 R >>\nstartxref\n%d\n%%%%EOF\n" % (len(objs) + 1, xref)
    return bytes(out)


needs_latex = pytest.mark.skipif(shutil.which("latexmk") is None or shutil.which("pdftotext") is None,
                                 reason="latexmk/pdftotext not installed (bash workflow/scripts/ensure_tex.sh)")


@needs_latex
def test_pdf_builds_and_shows_generated_numbers(tables, tmp_path):
    """As the rule paper_pdf does: generated .tex in results/paper, figures in
    results/figures, latexmk in a build dir with TEXINPUTS; the PDF text has our numbers."""
    gen, figs, build = tmp_path / "results/paper", tmp_path / "results/figures", tmp_path / "build"
    for d in (gen, figs, build):
        d.mkdir(parents=True)
    for name, text in pt.paper_files(**tables).items():
        (gen / name).write_text(text)
    for name in FIGURES:
        (figs / f"{name}.pdf").write_bytes(placeholder_pdf(name))
    # the elastic section (paper/elastic.tex) and its generated files, from small real tables
    from helpers.elastic_tables import small_elastic_tables

    from infsup_contact.report.sections.elastic import elastic_paper_files

    for name, text in elastic_paper_files(**small_elastic_tables()).items():
        (gen / name).write_text(text)
    (figs / "fig9_elastic.pdf").write_bytes(placeholder_pdf("fig9_elastic"))
    shutil.copy(ROOT / "paper" / "elastic.tex", build)
    # the face section (paper/face.tex) and its generated files, from small synthetic tables
    from helpers.face_tables import small_face_tables

    from infsup_contact.report.sections.face import face_paper_files

    for name, text in face_paper_files(**small_face_tables()).items():
        (gen / name).write_text(text)
    shutil.copy(ROOT / "paper" / "face.tex", build)
    for name in ("fig10_face_beta", "fig11_face_studies"):  # its figures (rule face_figures)
        (figs / f"{name}.pdf").write_bytes(placeholder_pdf(name))
    (gen / "model_sections.tex").write_text("")  # rule model_sections: no generated model subsection here
    shutil.copy(PAPER, build)
    shutil.copy(ROOT / "paper" / "references.bib", build)
    env = dict(os.environ, TEXINPUTS=f"{gen}:{figs}:", SOURCE_DATE_EPOCH="0", FORCE_SOURCE_DATE="1")
    run = subprocess.run(["latexmk", "-pdf", "-interaction=nonstopmode", "-halt-on-error", "paper.tex"],
                         cwd=build, env=env, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout[-3000:]
    text = subprocess.run(["pdftotext", "-layout", str(build / "paper.pdf"), "-"], capture_output=True,
                          text=True, check=True).stdout
    m = _by_name(tables)
    for name in ("betaHTthreeKone", "betaHTfiveKtwo", "slopeEnergyTthreeKone"):
        assert m[name].tex in text, name
    log = (build / "paper.log").read_text(errors="replace")
    assert not re.search(r"(Citation|Reference) `[^']+' on page \d+ undefined", log), "undefined refs"


# ----------------------------------------------------------------------------- text under any verdict

def _flipped(claims, how):
    swap = {"PASS": "FAIL", "FAIL": "PASS", "INCONCLUSIVE": "INCONCLUSIVE"}
    v = claims.verdict
    verdict = {"as is": v, "swapped": v.map(swap), "all PASS": "PASS", "all FAIL": "FAIL",
               "all INCONCLUSIVE": "INCONCLUSIVE"}[how]
    return claims.assign(verdict=verdict)


@pytest.mark.parametrize("how", ["as is", "swapped", "all PASS", "all FAIL", "all INCONCLUSIVE"])
def test_paper_text_never_contradicts_its_verdicts(tables, how):
    """Sentences that state an outcome are chosen by their verdict (\\byverdict): rendered
    under any ledger, no clause states success before FAIL, failure before PASS, or either
    before INCONCLUSIVE."""
    from infsup_contact.report.consistency import contradictions, render

    t = dict(tables, claims=_flipped(tables["claims"], how))
    text = render(PAPER.read_text(), _macros(t))
    assert "\\byverdict" not in text
    assert contradictions(text) == []


def test_the_contradiction_check_finds_a_stale_sentence():
    from infsup_contact.report.consistency import contradictions, resolve_byverdict

    stale = ("the two spaces of Remarks 5.2 and 5.4 have exactly the kernels the dimension counts "
             "predict (\\verdictfmt{PASS}, \\verdictfmt{FAIL}). Next.")
    assert len(contradictions(stale)) == 1
    assert contradictions("it is not bounded on N (\\verdictfmt{PASS}, evidence)") != []
    assert contradictions("it is bounded (\\verdictfmt{PASS}) and not bounded on M (\\verdictfmt{FAIL})") == []
    assert resolve_byverdict("x \\byverdict{FAIL}{a}{b {c}}{d} y") == "x b {c} y"


@pytest.mark.parametrize("new_id,escaped", [("Q0_2h", r"Q0\_2h"), ("A&B", r"A\&B"), ("x%y#1", r"x\%y\#1")])
def test_ids_reach_the_generated_tables_escaped(tables, new_id, escaped):
    """A space id with LaTeX specials is written literally (one escaping path, texformat.latex_id),
    never as a raw special or a subscript."""
    rename = {"DUAL": new_id}
    t = {name: (frame.replace({"case": rename}) if isinstance(frame, pd.DataFrame) and "case" in frame.columns
                else frame) for name, frame in tables.items()}
    files = pt.paper_files(**t)
    text = "".join(v for k, v in files.items() if k != "macros.tex")
    assert escaped in text
    assert new_id not in text.replace(escaped, "")
    assert "Q0$_{2h}$" not in text  # an id is not a formula
