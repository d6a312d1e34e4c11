"""The command line, run as users run it: a subprocess, CSV/JSON on stdout, exit codes.

Bad input must give exit code 2 and exactly one line on stderr naming the offending key
(no traceback).
"""
from __future__ import annotations

import datetime as dt
import io
import itertools
import json
import os
import platform
import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[2]
CONSOLE_SCRIPT = Path(sys.prefix) / "bin" / "infsup-contact"
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}

COLUMNS = ("case,k,family,N1,N2,multiplier_mesh,c1,c2,norm,beta,kernel_dim,"
           "structural_kernel_dim,smallest_nonzero,dim_M,dim_W,n_max,nmax_rel_error,ndof,"
           "t_assemble,t_interface,t_eig").split(",")
ALL_CASES = ("T3", "R5.2", "T4", "R5.4", "T5", "DUAL", "DUAL-ALL")  # every built-in space
K1_CASES = ("T3", "R5.2", "R5.4", "DUAL", "DUAL-ALL")  # T4 and T5 need k >= 2
NORMS = ("H", "L2")
SMALL = ["--N1", "4", "--N2", "4"]


def run(*args, cmd=None, check=False):
    cmd = cmd or [sys.executable, "-m", "infsup_contact"]
    proc = subprocess.run([*cmd, *args], capture_output=True, text=True, env=ENV,
                          cwd=ROOT, timeout=120)
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}\nstderr:\n{proc.stderr}"
    return proc


def csv(stdout: str) -> pd.DataFrame:
    return pd.read_csv(io.StringIO(stdout))


# ---------------------------------------------------------------------------- beta

@pytest.fixture(scope="module")
def beta_k2():
    return csv(run("beta", "--case", "all", "--k", "2", "--family", "structured", *SMALL,
                   check=True).stdout)


def test_beta_columns(beta_k2):
    missing = [c for c in COLUMNS if c not in beta_k2.columns]
    assert not missing, f"missing columns {missing}; got {list(beta_k2.columns)}"


def test_beta_one_row_per_case_and_norm(beta_k2):
    assert len(beta_k2) == len(ALL_CASES) * len(NORMS)
    got = sorted(zip(beta_k2["case"], beta_k2["norm"]))
    assert got == sorted(itertools.product(ALL_CASES, NORMS))


def test_beta_echoes_request(beta_k2):
    assert (beta_k2["k"] == 2).all()
    assert (beta_k2["family"] == "structured").all()
    assert (beta_k2["N1"] == 4).all() and (beta_k2["N2"] == 4).all()
    assert (beta_k2["multiplier_mesh"] == "omega2").all()
    assert (beta_k2["c1"] == 1.0).all() and (beta_k2["c2"] == 1.0).all()
    assert (beta_k2["beta"] >= 0).all() and beta_k2["beta"].notna().all()
    assert (beta_k2["kernel_dim"] >= 0).all()
    assert (beta_k2[["t_assemble", "t_interface", "t_eig"]] >= 0).all().all()


def test_beta_k1_all_skips_T4_T5():
    df = csv(run("beta", "--case", "all", "--k", "1", "--family", "structured", *SMALL,
                 check=True).stdout)
    assert sorted(zip(df["case"], df["norm"])) == sorted(itertools.product(K1_CASES, NORMS))
    assert (df["k"] == 1).all()


# ------------------------------------------------------------------- bad input

BAD = {
    # id: (extra args, substrings the single stderr line must contain)
    "T4-k1": (["--case", "T4", "--k", "1"], ["k", "k >= 2", "Thm 4", "T4"]),
    "T5-k1": (["--case", "T5", "--k", "1"], ["k", "k >= 2", "Thm 5", "T5"]),
    "unknown-case": (["--case", "T9", "--k", "2"], ["--case", "T9"]),
    "unknown-family": (["--k", "2", "--family", "hexagonal"], ["--family", "hexagonal"]),
    "N1-zero": (["--k", "2", "--N1", "0"], ["N1", "0"]),
    "N2-negative": (["--k", "2", "--N2", "-3"], ["N2", "-3"]),
    "N1-not-int": (["--k", "2", "--N1", "4.5"], ["--N1", "4.5"]),
    "c1-zero": (["--k", "2", "--c1", "0"], ["c1"]),
    "c2-negative": (["--k", "2", "--c2", "-1"], ["c2", "-1"]),
    "k0": (["--k", "0"], ["k", "0", "1..4"]),
    "k5": (["--k", "5"], ["k", "5", "1..4"]),
    "k0-one-case": (["--case", "T3", "--k", "0"], ["k", "0", "1..4"]),
    "k5-one-case": (["--case", "T3", "--k", "5"], ["k", "5", "1..4"]),
    "unknown-norm": (["--k", "2", "--norm", "H1"], ["--norm", "H1"]),
    "unknown-multiplier-mesh": (["--k", "2", "--multiplier-mesh", "omega3"],
                                ["--multiplier-mesh", "omega3"]),
    # issue 17: the request is refused before anything is allocated or computed
    "N1-beyond-memory": (["--k", "2", "--N1", "100000", "--N2", "4"], ["N1", "100000", "memory", "GiB"]),
    "c1-inf": (["--k", "2", "--c1", "inf"], ["c1", "inf", "rigid body"]),
    "c2-nan": (["--k", "2", "--c2", "nan"], ["c2", "nan"]),
    "seed-negative": (["--k", "1", "--family", "perturbed", "--seed", "-1"], ["seed", "-1", ">= 0"]),
    "alpha-half": (["--k", "1", "--family", "perturbed", "--alpha", "0.5"], ["alpha", "0.5"]),
}


@pytest.mark.parametrize("args, needles", list(BAD.values()), ids=list(BAD))
def test_bad_input_one_line_exit_2(args, needles):
    # SMALL first: a later --N1/--N2 in args overrides it (argparse keeps the last value)
    proc = run("beta", *SMALL, *args)
    assert proc.returncode == 2, f"exit {proc.returncode}, stderr:\n{proc.stderr}"
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, f"expected one stderr line, got:\n{proc.stderr}"
    line = lines[0]
    assert line.startswith("infsup-contact: error:"), line
    for needle in needles:
        assert needle in line, f"{needle!r} not in {line!r}"
    # the key is named as a word, not only as part of another token
    key = needles[0].lstrip("-")
    assert re.search(rf"(?<![\w-])-*{re.escape(key)}\b", line), f"key {key!r} not named: {line!r}"
    assert proc.stdout == "", "no partial CSV on bad input"


@pytest.mark.parametrize("content, needles", [
    ("a,b\n1,2\n", ["missing columns", "N1", "energy_error"]),   # the issue: AttributeError 'N1'
    ("", ["empty file"]),
    (None, ["no such file"]),
])
def test_rates_bad_table_one_line_exit_2(tmp_path, content, needles):
    table = tmp_path / "file.csv"
    if content is not None:
        table.write_text(content)
    proc = run("rates", str(table))
    assert proc.returncode == 2 and proc.stdout == "" and "Traceback" not in proc.stderr, proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"infsup-contact: error: table {table}"), proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]


def test_dry_run_prints_the_estimate_and_computes_nothing():
    proc = run("beta", "--k", "2", *SMALL, "--dry-run", check=True)
    assert proc.stdout.startswith("dry run: valid request; estimated ~") and "peak memory" in proc.stdout
    assert len(proc.stdout.splitlines()) == 1 and proc.stderr == ""


def test_missing_subcommand_is_usage_error():
    proc = run()
    assert proc.returncode == 2
    assert len(proc.stderr.splitlines()) == 1 and "Traceback" not in proc.stderr


# ------------------------------------------------------- entry points agree

def test_module_and_console_script_agree():
    assert CONSOLE_SCRIPT.is_file(), f"console script not installed at {CONSOLE_SCRIPT}"
    args = ["beta", "--case", "all", "--k", "2", *SMALL, "--norm", "L2"]
    a = csv(run(*args, check=True).stdout)
    b = csv(run(*args, cmd=[str(CONSOLE_SCRIPT)], check=True).stdout)
    assert list(a.columns) == list(b.columns)
    assert len(a) == len(ALL_CASES) and (a["norm"] == "L2").all()
    timing = [c for c in a.columns if c.startswith("t_")]
    assert timing, "expected timing columns t_*"
    pd.testing.assert_frame_equal(a.drop(columns=timing), b.drop(columns=timing), check_exact=True)


# --------------------------------------------------------------- provenance

def test_provenance_json():
    proc = run("provenance", check=True)
    info = json.loads(proc.stdout)
    versions = info["versions"]
    for pkg in ("python", "ngsolve", "numpy", "scipy", "snakemake"):
        assert isinstance(versions.get(pkg), str) and versions[pkg], f"no version for {pkg}"
        assert versions[pkg] != "not installed", pkg
        assert re.match(r"^\d+(\.\d+)+", versions[pkg]), f"{pkg}: {versions[pkg]!r}"
    assert versions["python"] == platform.python_version()

    commit = info["git_commit"]
    if (ROOT / ".git").exists():
        assert re.fullmatch(r"[0-9a-f]{40}(\+dirty)?", commit), commit
    else:
        assert commit == "unknown" or re.fullmatch(r"[0-9a-f]{40}(\+dirty)?", commit), commit

    assert isinstance(info["platform"], str) and info["platform"]
    date = dt.datetime.fromisoformat(info["date"])
    assert date.tzinfo is not None, "date must carry a timezone"
    assert abs(dt.datetime.now(dt.timezone.utc) - date) < dt.timedelta(minutes=10)


# ------------------------------------------------------------------------ bench

BENCH_COLUMNS = ("what,route,k,N,seconds_median,seconds_min,seconds_max,ratio_to_ours,"
                 "max_abs_diff").split(",")


def test_bench_contact_csv_with_peers_and_floor():
    frame = csv(run("bench", "--what", "contact", "--N", "4", "--k", "1", "--repeats", "1",
                    check=True).stdout)
    assert set(BENCH_COLUMNS) <= set(frame.columns)
    assert {"ours", "ours_end_to_end", "floor", "limit", "osqp", "clarabel"} <= set(frame.route)
    solved = frame[frame.route != "limit"]
    assert (solved.rel_diff_lambda <= 1e-8).all()


def test_bench_beta_csv_without_eigsh():
    frame = csv(run("bench", "--what", "beta", "--N", "4", "--k", "1", "--repeats", "1",
                    "--eigsh-max-N", "2", check=True).stdout)
    assert set(BENCH_COLUMNS) <= set(frame.columns)
    assert "eigsh" not in set(frame.route) and {"ours", "limit", "dense"} <= set(frame.route)


@pytest.mark.parametrize("args, key", [
    (["--what", "contact", "--N", "4", "--k", "1", "--peers", "gurobi"], "peers"),
    (["--what", "beta", "--N", "0", "--k", "1"], "N"),
    (["--what", "beta", "--N", "4", "--k", "7"], "k"),
    (["--what", "beta", "--N", "4", "--k", "1", "--repeats", "0"], "repeats"),
    (["--what", "gamma", "--N", "4", "--k", "1"], "--what"),
    (["--what", "elastic", "--N", "4", "--k", "1", "--nu", "0.5"], "nu"),
    (["--what", "elastic", "--N", "4", "--k", "1", "--case", "T9"], "case"),
])
def test_bench_bad_input_one_line_exit_2(args, key):
    proc = run("bench", *args)
    assert proc.returncode == 2 and proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr and key in lines[0], proc.stderr
