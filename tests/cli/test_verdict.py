"""`infsup-contact verdict`: the stability verdict from β_h (eq. (4.5)) over a mesh sequence.

The pure criterion on synthetic series whose slope is known by construction, then the
command as users run it (a subprocess) on spaces whose stability is proved: T3 is stable
(Thm 3), R5.4 has dim M − dim W zero modes on matching meshes (Rem 5.4); the dual basis of
T3's space spans the same space (stable), the dual basis of R5.2's has R5.2's kernel.
"""
from __future__ import annotations

import io
import re
import runpy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from infsup_contact import cli
from infsup_contact.discretization.spaces import registry
from infsup_contact.criteria import claims
from infsup_contact.criteria.stability import INCONCLUSIVE, STABLE, UNSTABLE, stability_verdict

ROOT = Path(__file__).resolve().parents[2]
ENV_THREADS = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
NS = [8, 16, 32, 64]
SMALL_NS = ["8", "16", "32"]  # N = 4 is pre-asymptotic for T3: with 1 dof its CI is too wide
COLUMNS = ("space,k,family,norm,verdict,kernel_dim,beta_min,beta_max,slope,slope_lo,slope_hi,"
           "N_list,seconds").split(",")


def series(beta, kernel_dim=0, above=None, ns=NS, **extra):
    """Synthetic beta_rows rows: β_h per mesh, its kernel dimension and β above the kernel."""
    beta = np.broadcast_to(np.asarray(beta, float), (len(ns),))
    kernel = np.broadcast_to(np.asarray(kernel_dim, int), (len(ns),))
    above = beta if above is None else np.broadcast_to(np.asarray(above, float), (len(ns),))
    return [dict(case="X", k=1, family="structured", norm="H", N1=n, N2=n, beta=b,
                 kernel_dim=int(d), smallest_nonzero=a, **extra)
            for n, b, d, a in zip(ns, beta, kernel, above)]


def h_of(ns=NS):
    return 1.0 / np.asarray(ns, float)


def ledger_says(rows):
    """The ledger's verdict on the same rows (the command must agree with it)."""
    return claims.bounded_claim(pd.DataFrame(rows), CRITERION["tol"], CRITERION["floor"],
                                CRITERION["confidence"])[0]


# --------------------------------------------------------------- the pure criterion

def test_constant_beta_is_stable_with_zero_slope():
    rows = series(0.8)
    v = stability_verdict(rows, **CRITERION)
    assert v["verdict"] == STABLE and ledger_says(rows) == claims.PASS
    assert v["slope"] == 0 and v["slope_lo"] == 0 and v["slope_hi"] == 0
    assert v["kernel_dim"] == 0 and v["beta_min"] == v["beta_max"] == 0.8


@pytest.mark.parametrize("p", [0.5, 1.0])
def test_beta_decaying_like_a_power_of_h_is_unstable(p):
    rows = series(h_of() ** p)  # min β_h = 64^-p is above the floor: the slope decides
    v = stability_verdict(rows, **CRITERION)
    assert v["verdict"] == UNSTABLE and ledger_says(rows) == claims.FAIL
    assert v["slope"] == pytest.approx(p) and v["slope_lo"] > CRITERION["tol"]
    assert min(r["beta"] for r in rows) > CRITERION["floor"]


def test_beta_below_the_floor_is_unstable_even_if_constant():
    v = stability_verdict(series(CRITERION["floor"] / 2), **CRITERION)
    assert v["verdict"] == UNSTABLE and v["slope"] == 0


def test_a_kernel_is_unstable_and_the_slope_is_the_eigenvalue_above_it():
    p = 1.0
    rows = series(0.0, kernel_dim=1, above=h_of() ** p)
    v = stability_verdict(rows, **CRITERION)
    assert v["verdict"] == UNSTABLE and v["kernel_dim"] == 1
    assert v["beta_min"] == v["beta_max"] == 0
    assert v["slope"] == pytest.approx(p)


def test_a_kernel_on_one_mesh_is_enough():
    # β_h constant except one mesh with a kernel: β_h = 0 there, so not bounded away from 0
    kernel = [0, 0, 1, 0]
    beta = np.where(np.asarray(kernel) > 0, 0.0, 0.8)
    v = stability_verdict(series(beta, kernel_dim=kernel, above=0.8), **CRITERION)
    assert v["verdict"] == UNSTABLE and v["kernel_dim"] == 1 and v["beta_min"] == 0


def test_a_wide_interval_is_inconclusive():
    # zigzag around a constant: least-squares slope 0, residuals large, so the interval
    # (Student t with n − 2 = 1 dof) reaches beyond ±τ on both sides
    ns = [8, 16, 32]
    rows = series([0.5, 0.8, 0.5], ns=ns)
    v = stability_verdict(rows, **CRITERION)
    assert v["slope_lo"] < -CRITERION["tol"] and v["slope_hi"] > CRITERION["tol"]
    assert v["verdict"] == INCONCLUSIVE and ledger_says(rows) == claims.INCONCLUSIVE


def test_row_order_does_not_matter():
    rows = series(h_of() ** 0.1 * (1 + 0.01 * np.arange(len(NS))))
    a, b = stability_verdict(rows, **CRITERION), stability_verdict(rows[::-1], **CRITERION)
    assert a == b


@pytest.mark.parametrize("bad", [
    series(0.8)[:2] + [dict(series(0.8)[2], norm="L2")],
    series(0.8) + series(0.8)[:1],
    [],
])
def test_rows_of_more_than_one_series_are_rejected(bad):
    with pytest.raises(ValueError):
        stability_verdict(bad, **CRITERION)


# ------------------------------------------------- the CLI's defaults are the config's

def test_cli_defaults_are_the_config_claims_section():
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["claims"]
    args = cli.build_parser().parse_args(["verdict", "--case", "T3", "--k", "1"])
    for key in ("slope_tolerance", "beta_floor", "confidence"):
        assert cli.VERDICT_DEFAULTS[key] == cfg[key], key
        assert getattr(args, key) == cfg[key], key


# ------------------------------------------------------------- the command line

def run(*args):
    import os

    return subprocess.run([sys.executable, "-m", "infsup_contact", "verdict", *args],
                          capture_output=True, text=True, env={**os.environ, **ENV_THREADS},
                          cwd=ROOT, timeout=300)


def one_row(proc) -> pd.Series:
    frame = pd.read_csv(io.StringIO(proc.stdout), dtype={"N_list": str})
    assert len(frame) == 1, proc.stdout
    missing = [c for c in COLUMNS if c not in frame.columns]
    assert not missing, f"missing columns {missing}"
    return frame.iloc[0]


def structural_kernel(case, k, ns):
    """The registry's dimension count dim M − dim W (Rem 5.2/5.4), largest over the meshes."""
    return max(registry.structural_kernel_dim(case, k, int(n)) for n in ns)


@pytest.fixture(scope="module")
def r54_k1():
    return run("--case", "R5.4", "--k", "1", "--N", *SMALL_NS)


def test_r54_k1_is_unstable_with_its_kernel(r54_k1):
    assert r54_k1.returncode == 0, r54_k1.stderr  # no --expect: a verdict is not an error
    r = one_row(r54_k1)
    assert r.verdict == UNSTABLE and r.space == "R5.4" and r.k == 1
    assert r.kernel_dim == structural_kernel("R5.4", 1, SMALL_NS) > 0
    assert r.N_list == " ".join(SMALL_NS) and r.family == "structured" and r.norm == "H"
    assert r.seconds > 0


@pytest.mark.parametrize("expect, code", [("stable", 1), ("unstable", 0)])
def test_r54_k1_exit_code_follows_expect(expect, code):
    proc = run("--case", "R5.4", "--k", "1", "--N", *SMALL_NS, "--expect", expect)
    assert proc.returncode == code, proc.stderr
    assert one_row(proc).verdict == UNSTABLE  # the row is printed either way


def test_t3_k1_is_stable():
    proc = run("--case", "T3", "--k", "1", "--N", *SMALL_NS, "--expect", "stable")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    r = one_row(proc)
    assert r.verdict == STABLE and r.kernel_dim == 0
    assert r.beta_min > cli.VERDICT_DEFAULTS["beta_floor"]
    tol = cli.VERDICT_DEFAULTS["slope_tolerance"]
    assert -tol <= r.slope_lo <= r.slope <= r.slope_hi <= tol


def test_dual_k1_is_stable():
    proc = run("--case", "DUAL", "--k", "1", "--N", *SMALL_NS, "--expect", "stable")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert one_row(proc).kernel_dim == 0


def test_dual_all_k2_is_unstable():
    proc = run("--case", "DUAL-ALL", "--k", "2", "--N", *SMALL_NS)
    assert proc.returncode == 0, proc.stderr
    r = one_row(proc)
    assert r.verdict == UNSTABLE and r.kernel_dim == structural_kernel("DUAL-ALL", 2, SMALL_NS) > 0


def test_user_space_equal_to_r54_gets_r54_verdict(tmp_path):
    # a user's copy of Rem 5.4's M^0_{k-1} under another id: the same space, the same kernel
    path = tmp_path / "copy_r54.py"
    path.write_text(
        "from infsup_contact.discretization.segment.multipliers import make_space\n"
        "from infsup_contact.discretization.spaces.spec import SpaceSpec\n\n"
        "def space():\n"
        "    return SpaceSpec('COPY-R5.4', 'user', 'M^0_{k-1}', lambda k, x: make_space(x, k - 1, False, False),\n"
        "                     lambda k: k - 1, dimension=lambda k, n: n * k)\n")
    proc = run("--space", f"{path}:space", "--k", "1", "--N", *SMALL_NS, "--expect", "unstable")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    r = one_row(proc)
    assert r.space == "COPY-R5.4" and r.kernel_dim == structural_kernel("R5.4", 1, SMALL_NS)


def test_example_space_meets_its_stated_expectation():
    example = ROOT / "examples" / "macro_p0.py"
    expected = runpy.run_path(str(example))["space"]().expected
    assert expected in ("stable", "unstable")
    proc = run("--space", f"{example}:space", "--k", "1", "--N", *SMALL_NS, "--expect", expected)
    assert proc.returncode == 0, proc.stdout + proc.stderr


BAD = {
    # id: (args, substrings the single stderr line must contain; the first is the key)
    "two-N": (["--case", "T3", "--k", "1", "--N", "4", "8"], ["N", "at least 3"]),
    "repeated-N": (["--case", "T3", "--k", "1", "--N", "8", "8", "8"], ["N", "distinct"]),
    "N-zero": (["--case", "T3", "--k", "1", "--N", "0", "4", "8"], ["N", "0"]),
    "N-not-int": (["--case", "T3", "--k", "1", "--N", "4", "8.5", "16"], ["--N", "8.5"]),
    "k0": (["--case", "T3", "--k", "0"], ["k", "0", "1..4"]),
    "k5": (["--case", "T3", "--k", "5"], ["k", "5", "1..4"]),
    "T4-k1": (["--case", "T4", "--k", "1"], ["k", "k >= 2", "T4"]),
    "unknown-case": (["--case", "T9", "--k", "1"], ["--case", "T9"]),
    "no-case": (["--k", "1"], ["--case", "--space"]),
    "case-and-space": (["--case", "T3", "--space", "examples/macro_p0.py:space", "--k", "1"],
                       ["--case", "--space"]),
    "space-no-file": (["--space", "examples/no_such_file.py:space", "--k", "1"],
                      ["space", "no_such_file.py"]),
    "space-no-func": (["--space", "examples/macro_p0.py", "--k", "1"], ["space", "FILE.py:FUNC"]),
    "unknown-family": (["--case", "T3", "--k", "1", "--family", "hexagonal"], ["--family", "hexagonal"]),
    "unknown-norm": (["--case", "T3", "--k", "1", "--norm", "H1"], ["--norm", "H1"]),
    "unknown-expect": (["--case", "T3", "--k", "1", "--expect", "maybe"], ["--expect", "maybe"]),
    "tolerance-zero": (["--case", "T3", "--k", "1", "--slope-tolerance", "0"], ["slope-tolerance"]),
    "floor-negative": (["--case", "T3", "--k", "1", "--beta-floor", "-1"], ["beta-floor"]),
    "confidence-one": (["--case", "T3", "--k", "1", "--confidence", "1"], ["confidence"]),
}


@pytest.mark.parametrize("args, needles", list(BAD.values()), ids=list(BAD))
def test_bad_input_one_line_exit_2(args, needles):
    proc = run(*args)
    assert proc.returncode == 2, f"exit {proc.returncode}, stderr:\n{proc.stderr}"
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert lines[0].startswith("infsup-contact: error:"), lines[0]
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    key = needles[0].lstrip("-")
    assert re.search(rf"(?<![\w-])-*{re.escape(key)}\b", lines[0]), f"key {key!r} not named: {lines[0]!r}"
    assert proc.stdout == "", "no partial CSV on bad input"
