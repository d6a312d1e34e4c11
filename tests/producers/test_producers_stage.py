"""The producers stage (rules/producers.smk, study/producers.py, report/sections/producers.py) on a fake
producer: a tiny script obeying the exporter contract, so the stage is tested without Kratos.

The fake system has a closed form: A = 2 I on n = N + 2 dofs, B = h [I_N | 0] (m = N P0
multipliers on N intervals of length h = 1/N), G = h I (their L² mass). Then B A⁻¹ Bᵀ = h²/2 I,
so β_h = (h/2)^{1/2} in L² (UNSTABLE, slope 1/2) and β_h = 2^{-1/2} in h-L² (G = h² I: STABLE).
"""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from infsup_contact.errors import InputError
from infsup_contact.io import read_table, write_csv_atomic
from infsup_contact.report.sections.producers import producers_tex
from infsup_contact.study.producers import norm_copy, producers_claims, producers_modes, producers_table

ROOT = Path(__file__).resolve().parents[2]
CRITERION = {"slope_tolerance": 0.15, "beta_floor": 1e-3, "confidence": 0.95}

FAKE = textwrap.dedent('''\
    """A fake producer obeying the contract (tests/producers/test_producers_stage.py)."""
    import argparse, os, sys
    from pathlib import Path
    import numpy as np, scipy.io, scipy.sparse as sp
    p = argparse.ArgumentParser()
    p.add_argument("--out", type=Path); p.add_argument("--space"); p.add_argument("--N", type=int, nargs="+")
    p.add_argument("--offset", type=int, default=0); p.add_argument("--list-spaces", action="store_true")
    a = p.parse_args()
    if a.list_spaces:
        print("p0\\tdiscontinuous P0"); sys.exit(0)
    if a.space != "p0":
        sys.stderr.write(f"fake: --space {a.space!r} unknown\\n"); sys.exit(2)
    if os.environ.get("FAKE_NOISY"):
        print("a banner on stdout")
    a.out.mkdir(parents=True, exist_ok=True)
    lines = ["name: fake-1.0 p0", "norm: H", "gamma: {shape: segment, length: 1.0}", "levels:"]
    for n in a.N:
        h = 1.0 / n
        A = 2 * sp.identity(n + 2); B = sp.hstack([h * sp.identity(n), sp.csr_matrix((n, 2))]); G = h * sp.identity(n)
        for key, mat in (("A", A), ("B", B), ("G", G)):
            scipy.io.mmwrite(str(a.out / f"{key}{n}.mtx"), sp.coo_matrix(mat), precision=17)
        bp = [i * h for i in range(n + 1)]
        lines += [f"  - h: {h!r}", f"    A: A{n}.mtx", f"    B: B{n}.mtx", f"    G: G{n}.mtx",
                  f"    multipliers: {{basis: discontinuous, degree: 0, breakpoints: {bp}}}"]
    (a.out / "levels.yaml").write_text("\\n".join(lines) + "\\n")
''')


def _cfg(tmp_path, python=sys.executable, distribution="numpy", install="make producers-fake"):
    script = tmp_path / "fake" / "export.py"
    script.parent.mkdir(exist_ok=True)
    script.write_text(FAKE)
    return {"N": [4, 8, 16], "offsets": [0, 1], "norms": ["H", "L2", "h-L2"], "criterion": CRITERION,
            "codes": {"fake": {"python": str(python), "export": str(script), "distribution": distribution,
                               "spaces": ["p0"], "install": install,
                               # B A⁻¹ Bᵀ = h²/2 I: h-L2 (G = h² I) β² = 1/2; L2 (G = h I) β² = h/2; H: the
                               # H^-1/2 Gram of P0 holds the constant, 1ᵀG1/N = 7ζ(3)/(π³ N) ~ 0.27 h, so β² ≲ 2h
                               "predictions": {"p0": {"verdicts": {"H": "UNSTABLE", "L2": "UNSTABLE", "h-L2": "STABLE"},
                                                      "kernel": 0, "why": "a diagonal coupling"}}}}}


def test_fake_producer_rows_and_closed_forms(tmp_path):
    table = producers_table(_cfg(tmp_path), tmp_path / "work")
    assert len(table) == 6 and set(table.norm) == {"H", "L2", "h-L2"} and set(table.offset) == {0, 1}
    ok = table[table.status == "ok"]
    l2, hl2 = ok[ok.norm == "L2"], ok[ok.norm == "h-L2"]
    for r in l2.itertuples():
        betas = np.array(r.beta_levels.split(), float)
        assert np.allclose(betas, np.sqrt(np.array([1 / 4, 1 / 8, 1 / 16]) / 2), rtol=1e-5)  # 6 digits written
        assert r.verdict == "UNSTABLE" and r.slope == pytest.approx(0.5, abs=1e-6)
    for r in hl2.itertuples():
        assert np.allclose(np.array(r.beta_levels.split(), float), 2 ** -0.5, rtol=1e-5) and r.verdict == "STABLE"
    assert all(r.kernel_levels == "0 0 0" for r in ok.itertuples())
    h = table[table.norm == "H"]  # certified once the certifier reads norm: H; until then refused, by name
    assert all(s == "ok" or s.startswith("refused: ") for s in h.status)
    assert (tmp_path / "work" / "fake" / "p0_k1" / "levels-L2.yaml").is_file()
    assert all(r.dim_M_levels == "4 8 16" for r in ok.itertuples())  # m = N P0 multipliers, none constrained
    modes = producers_modes(table, tmp_path / "work")  # the finest level's worst mode of each H export
    hok = h[h.status == "ok"]
    assert sorted(set(zip(modes.offset, modes.level))) == [(k, 2) for k in sorted(hok.offset)]
    for r in hok.itertuples():
        m = modes[modes.offset == r.offset]
        assert m.beta.iloc[0] == pytest.approx(float(r.beta_levels.split()[-1]), rel=1e-5)
        assert m.mu.abs().max() == pytest.approx(1.0) and m.x.between(0.0, 1.0).all()


def test_claims_follow_the_certificates(tmp_path):
    cfg = _cfg(tmp_path)
    table = producers_table(cfg, tmp_path / "work")
    claims = producers_claims(table, cfg)
    assert list(claims.claim_id) == ["producer-fake-p0"] and claims.predicted.iloc[0] == "PASS"
    h_ok = (table[table.norm == "H"].status == "ok").all()
    assert claims.verdict.iloc[0] == ("PASS" if h_ok else "INCONCLUSIVE"), claims.evidence.iloc[0]
    # a wrong prediction on a decided certificate is a FAIL, whatever the H rows say
    cfg["codes"]["fake"]["predictions"]["p0"]["verdicts"]["h-L2"] = "UNSTABLE"
    assert producers_claims(table, cfg).verdict.iloc[0] == "FAIL"


def test_not_installed_is_a_row_not_a_failure(tmp_path):
    for cfg in (_cfg(tmp_path, python=tmp_path / "no-such-python"), _cfg(tmp_path, distribution="no-such-dist-xyz")):
        table = producers_table(cfg, tmp_path / "work")
        assert len(table) == 1 and table.status.iloc[0] == "not installed"
        assert "make producers-fake" in table.evidence.iloc[0] and table.install.iloc[0] == "make producers-fake"
        claims = producers_claims(table, cfg)  # the prediction kept, the verdict NOT RUN, the command named
        assert list(claims.claim_id) == ["producer-fake-p0"] and list(claims.verdict) == ["NOT RUN"]
        assert claims.predicted.iloc[0] == "PASS" and "make producers-fake" in claims.evidence.iloc[0]
        assert "h-L2 STABLE" in claims.statement.iloc[0]
        write_csv_atomic(tmp_path / "producers.csv", table)  # what the rule writes, read back as the paper rule reads it
        assert read_table(tmp_path / "producers.csv", "producers").status.iloc[0] == "not installed"
        tex = producers_tex(table, producers_claims(table, cfg), {})
        assert "not installed" in tex and r"\section{Certifying production codes}" in tex
        assert "so none was run: fake" in tex and r"\verdictfmt{NOT RUN}" in tex


def test_a_broken_exporter_is_named(tmp_path, monkeypatch):
    cfg = _cfg(tmp_path)
    cfg["codes"]["fake"]["spaces"] = ["p1"]
    with pytest.raises(InputError, match="export.py.*exit 2.*--space p1"):
        producers_table(cfg, tmp_path / "work")
    cfg["codes"]["fake"]["spaces"] = ["p0"]
    monkeypatch.setenv("FAKE_NOISY", "1")
    with pytest.raises(InputError, match="printed on stdout"):
        producers_table(cfg, tmp_path / "work")


def test_norm_copy_drops_the_description(tmp_path):
    subprocess.run([sys.executable, str(_cfg(tmp_path)["codes"]["fake"]["export"]), "--out", str(tmp_path / "x"),
                    "--space", "p0", "--N", "4", "8", "16"], check=True)
    manifest = tmp_path / "x" / "levels.yaml"
    assert norm_copy(manifest, "H") == manifest
    data = yaml.safe_load(norm_copy(manifest, "h-L2").read_text())
    assert data["norm"] == "h-L2" and "gamma" not in data and all("multipliers" not in lv for lv in data["levels"])


@pytest.mark.slow
def test_the_rule_runs_the_fake_producer(tmp_path):
    """snakemake builds results/tables/producers.csv and the paper section with the quick config
    plus a producers section naming the fake producer (the repository linked into tmp_path)."""
    for name in ("Snakefile", "workflow", "src", "examples", "config", "paper"):
        (tmp_path / name).symlink_to(ROOT / name)
    cfg = yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())
    fake = _cfg(tmp_path)
    cfg["producers"] = {k: v for k, v in fake.items() if k != "criterion"}
    (tmp_path / "test.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False, allow_unicode=True))
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    done = subprocess.run([str(Path(sys.executable).parent / "snakemake"), "--configfile", "test.yaml", "-c1",
                           "results/tables/producers.csv", "results/paper/producers.tex"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    table = read_table(tmp_path / "results" / "tables" / "producers.csv", "producers")
    assert len(table) == 6 and set(table.producer) == {"fake"}
    claims = read_table(tmp_path / "results" / "tables" / "producers_claims.csv", "claims")
    assert list(claims.claim_id) == ["producer-fake-p0"]
    tex = (tmp_path / "results" / "paper" / "producers.tex").read_text()
    assert r"\section{Certifying production codes}" in tex and "0.7071" in tex  # β_h in h-L2 = 2^(-1/2)
    assert isinstance(pd.read_csv(tmp_path / "results" / "tables" / "producers.csv"), pd.DataFrame)


def test_the_section_compiles(tmp_path):
    """The generated section typesets (booktabs tables, refused rows, not-installed producers)."""
    import shutil

    if shutil.which("latexmk") is None:
        pytest.skip("latexmk not installed (workflow/scripts/ensure_tex.sh installs TeX)")
    cfg = _cfg(tmp_path)
    table = producers_table(cfg, tmp_path / "work")
    missing = producers_table(_cfg(tmp_path, python=tmp_path / "none"), tmp_path / "work2").assign(producer="absent")
    both = pd.concat([table, missing], ignore_index=True)
    (tmp_path / "producers.tex").write_text(producers_tex(both, producers_claims(table, cfg), {"fake": "A fake code."}))
    (tmp_path / "t.tex").write_text("\\documentclass{article}\\usepackage{booktabs}\\begin{document}\\section{M}"
                                    "\\label{sec:model}\\input{producers.tex}\\end{document}\n")
    run = subprocess.run(["latexmk", "-pdf", "-interaction=nonstopmode", "-halt-on-error", "t.tex"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout[-2000:]


def test_a_codes_own_levels_replace_the_sections(tmp_path):
    """``codes.<name>.N`` (GetFEM's levels in config.yaml): the exporter gets that --N and the rows'
    levels are its meshes, the L2 β_h still the closed form sqrt(h/2) on each of them."""
    cfg = _cfg(tmp_path)
    cfg["codes"]["fake"]["N"] = [8, 16, 32, 64]
    table = producers_table(cfg, tmp_path / "work")
    ok = table[(table.status == "ok") & (table.norm == "L2")]
    assert len(ok) == 2
    for r in ok.itertuples():
        assert np.allclose(np.array(r.h_levels.split(), float), [1 / 8, 1 / 16, 1 / 32, 1 / 64])
        assert np.allclose(np.array(r.beta_levels.split(), float), np.sqrt(np.array([1 / 8, 1 / 16, 1 / 32, 1 / 64]) / 2),
                           rtol=1e-5)

