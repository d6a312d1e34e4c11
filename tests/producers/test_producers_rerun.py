"""Rule producers reruns when a producer's installation changes (issue 50, item 2): its params
hold each code's interpreter and the version that interpreter reports (study/producers.py
``installation``), and params are one of Snakemake's default rerun triggers. So
``make producers-<code> && make reproduce-all`` recomputes the stale "not installed" rows
without deleting a table by hand.

The producer here is a fake interpreter (a shell script in tmp_path) that reports no version
until a marker file exists: "installing" it is creating the marker. The rule runs once for real
(the code not installed: a NOT RUN claim, seconds), then dry runs show what Snakemake plans.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from infsup_contact.io import read_table
from test_producers_stage import ROOT, _cfg

TARGET = "results/tables/producers_claims.csv"


def _workdir(tmp_path) -> Path:
    """The repository linked into tmp_path, the quick config plus a producers section whose one
    code runs under tmp_path/fakepy (a version only once tmp_path/installed exists)."""
    for name in ("Snakefile", "workflow", "src", "examples", "config", "paper"):
        (tmp_path / name).symlink_to(ROOT / name)
    fakepy = tmp_path / "fakepy"
    fakepy.write_text(f'#!/bin/sh\n[ -e "{tmp_path / "installed"}" ] || exit 1\nexec "{sys.executable}" "$@"\n')
    fakepy.chmod(0o755)
    cfg = yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())
    producers = _cfg(tmp_path, python=fakepy)
    producers["codes"]["fake"]["version"] = f"print(open({str(tmp_path / 'installed')!r}).read().strip())"
    cfg["producers"] = {k: v for k, v in producers.items() if k != "criterion"}
    (tmp_path / "test.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False, allow_unicode=True))
    return tmp_path


def _snakemake(cwd: Path, *args) -> subprocess.CompletedProcess:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")]),
               PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    done = subprocess.run([str(Path(sys.executable).parent / "snakemake"), "--configfile", "test.yaml", "-c1",
                           *args, TARGET], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    return done


def _planned(done: subprocess.CompletedProcess) -> str:
    """The dry run's report (jobs and their reasons), lower case."""
    return (done.stdout + done.stderr).lower()


@pytest.mark.slow  # three snakemake processes (~13 s CPU)
def test_installing_a_producer_reruns_the_stage(tmp_path):
    cwd = _workdir(tmp_path)
    _snakemake(cwd)  # not installed: the rule runs, its claim NOT RUN naming the install command
    claims = read_table(cwd / TARGET, "claims")
    assert list(claims.verdict) == ["NOT RUN"] and "make producers-fake" in claims.evidence.iloc[0]

    unchanged = _planned(_snakemake(cwd, "-n"))
    assert "nothing to be done" in unchanged and "rule producers:" not in unchanged  # probing reruns nothing

    (tmp_path / "installed").write_text("1.0\n")  # `make producers-fake`
    rerun = _planned(_snakemake(cwd, "-n"))
    assert "rule producers:" in rerun and "params have changed" in rerun, rerun[-3000:]
