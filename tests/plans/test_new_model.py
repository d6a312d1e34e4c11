"""A new model is a model file plus one entry of the config's model table (plans/beta.py).

The model file is ``examples/orthotropic_membranes.py`` (K = diag(1, 4)): nothing in the package
names it. What follows from mathematics and is asserted here:

* the kernel of B A⁻¹ Bᵀ depends on B alone, so the orthotropic kernels equal the membranes' on
  every row (a second route: the membranes computed by the same study);
* |v|²_mem ≤ a_orth(v, v) ≤ 4 |v|²_mem, so β_mem / 2 ≤ β_orth ≤ β_mem on every row;
* the study's claims come out as predicted, and the workflow runs the entry with no other change.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from infsup_contact.config.models import check_models
from infsup_contact.config.schema import ConfigError
from infsup_contact.io import read_table
from infsup_contact.plans import study_of

ROOT = Path(__file__).resolve().parents[2]
MODEL_FILE = "examples/orthotropic_membranes.py:MODEL"
ENTRY = {"study": "beta", "model": MODEL_FILE, "k": [1], "N": [8, 16, 24, 32], "nonmatching": [[12, 8]],
         "cases": ["T3", "R5.2", "R5.4"], "norms": ["H"]}
CLAIMS = {"slope_tolerance": 0.15, "beta_floor": 1e-3, "confidence": 0.95, "fit_window": 3}


@pytest.fixture(scope="module")
def tables(request):
    cwd = os.getcwd()
    os.chdir(ROOT)  # the entry names the model file relative to the workflow, as a config does
    try:
        config = {"studies": {"orthotropic": ENTRY, "reference": dict(ENTRY, model="membranes")}}
        check_models(config)
        out = {}
        for name in config["studies"]:
            study = study_of(config, name)
            out[name] = pd.concat([job.run() for job in study.jobs().values()], ignore_index=True)
        out["claims"] = study_of(config, "orthotropic").claims({"beta": out["orthotropic"]}, CLAIMS)
        return out
    finally:
        os.chdir(cwd)


def test_the_kernels_are_the_membranes_ones(tables):
    orth, mem = tables["orthotropic"], tables["reference"]
    key = ["case", "k", "N1", "N2", "norm"]
    both = orth.merge(mem, on=key, suffixes=("", "_mem"))
    assert len(both) == len(orth) == len(mem) == 3 * 5
    assert (both.kernel_dim == both.kernel_dim_mem).all()
    assert set(both[both.case == "R5.2"].query("N1 == N2").kernel_dim) == {2}


def test_beta_lies_between_half_and_all_of_the_membranes_one(tables):
    both = tables["orthotropic"].merge(tables["reference"], on=["case", "k", "N1", "N2", "norm"], suffixes=("", "_mem"))
    live = both[both.kernel_dim == 0]
    assert len(live) >= 4
    rtol = 1e-8
    assert np.all(live.beta <= live.beta_mem * (1 + rtol)) and np.all(live.beta >= 0.5 * live.beta_mem * (1 - rtol))
    assert np.all(live.beta < live.beta_mem * (1 - 1e-3))  # K ≠ I: the bound is not an identity


def test_the_claims_come_out_as_predicted(tables):
    claims = tables["claims"]
    assert {"orthotropic-kernel-at-least-count", "orthotropic-Thm3-k1"} <= set(claims.claim_id)
    assert (claims.verdict == claims.predicted).all(), claims[["claim_id", "verdict", "predicted", "evidence"]]


@pytest.mark.parametrize("entry, key", [
    ({"model": "examples/no_such_file.py:MODEL"}, "studies.toy.model"),
    ({"model": "examples/orthotropic_membranes.py:STIFFNESS_Y"}, "studies.toy.model"),
    ({"model": "membranes", "elements": ["hex"]}, "studies.toy.elements[0]"),
    ({"model": "membranes3d"}, "studies.toy.elements"),
    ({"model": "membranes", "cases": ["T3", "NOPE"]}, "studies.toy.cases[1]"),
    ({"model": "membranes", "nonmatching": [[5, 5]]}, "studies.toy.nonmatching[0]"),
])
def test_a_bad_entry_is_one_line_naming_its_key(entry, key):
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        with pytest.raises(ConfigError) as err:
            check_models({"studies": {"toy": dict(ENTRY, **entry)}})
    finally:
        os.chdir(cwd)
    text = str(err.value)
    assert key in text and "\n" not in text and "Traceback" not in text


def test_reserved_and_built_in_names_are_refused():
    with pytest.raises(ConfigError, match="studies.contact"):
        check_models({"studies": {"contact": ENTRY}})
    with pytest.raises(ConfigError, match="studies.my_elastic.study"):  # the paper reads it by its name
        check_models({"studies": {"my_elastic": {"study": "elastic"}}})


def test_the_workflow_runs_a_new_model_from_its_entry(tmp_path):
    """The real DAG: the entry added to the CI config, nothing else changed, its claims and section built."""
    for name in ("Snakefile", "workflow", "config", "profiles", "src", "paper", "examples"):
        src = ROOT / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / name,
                                                           **({"ignore": shutil.ignore_patterns("__pycache__")}
                                                              if src.is_dir() else {}))
    config = yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())
    config["studies"]["orthotropic"] = ENTRY
    (tmp_path / "config" / "new_model.yaml").write_text(yaml.safe_dump(config, sort_keys=False))
    bin_dir = Path(sys.executable).parent
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", PATH=f"{bin_dir}:{os.environ['PATH']}")
    run = subprocess.run([str(bin_dir / "snakemake"), "results/tables/orthotropic_claims.csv",
                          "results/paper/orthotropic", "results/paper/model_sections.tex", "--cores", "2",
                          "--configfile", "config/new_model.yaml"],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    claims = read_table(tmp_path / "results/tables/orthotropic_claims.csv", "claims")
    assert (claims.verdict == claims.predicted).all()
    section = (tmp_path / "results/paper/orthotropic/orthotropic.tex").read_text()
    assert r"\subsection{The model \texttt{orthotropic}}" in section and r"\begin{tabular}" in section
    assert (tmp_path / "results/paper/model_sections.tex").read_text() == "\\input{orthotropic}\n"


def test_an_entry_too_large_for_this_machine_is_refused_before_any_job():
    from infsup_contact.config.memory import check_job_memory

    config = yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())
    config["studies"]["huge"] = dict(ENTRY, model="membranes3d", elements=["hex"], k=[4], N=[8, 16, 200])
    with pytest.raises(ConfigError) as err:
        check_job_memory(config, 24e9)
    assert "studies.huge.N" in str(err.value) and "model_job huge k=4 200x200" in str(err.value)
