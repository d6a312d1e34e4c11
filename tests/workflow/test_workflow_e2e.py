"""End to end: the DAG verifies the paper's claims; reruns are deterministic and survive kills.

These run real Snakemake jobs in temporary copies of the workflow (a few minutes in all). The
runs two tests share are made once per pytest run, whichever xdist workers the tests land on
(:func:`helpers.once.once`): ``ci_run`` (verify-claims; the paper test works on a copy of it)
and ``clean_targets`` (the reference run the determinism and the kill tests both compare with);
the tests only read them.
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from helpers.once import once

from infsup_contact.io import read_table

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent


def _copy_workflow(dest: Path) -> Path:
    for name in ("Snakefile", "workflow", "config", "profiles", "src", "paper", "examples"):
        src = ROOT / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, dest / name)
    return dest


def _env():
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env["PATH"] = f"{BIN}:{env.get('PATH', '')}"
    return env


def _snakemake(cwd, *args, timeout=900):
    return subprocess.run([str(BIN / "snakemake"), *args], cwd=cwd, env=_env(),
                          capture_output=True, text=True, timeout=timeout)


KEY_CLAIMS = ["Thm3-k1-structured-evenN", "Thm3-k2-unstructured-oddN", "Thm4-k2-perturbed-evenN",
              "Thm5-k2-structured-evenN", "Thm5-k2-structured-oddN", "Rem5.2-structured",
              "Rem5.4-perturbed", "Rem3.1-T3-k1-structured", "Rem5.5-shrink-M", "Rem5.5-enlarge-W",
              "Rem5.5-enlarge-M-unstable", "eq5.10-sufficient", "eq5.10-matching-worst-finer-omega1-ratio3-2",
              "finding-matching-worst-finer-omega1-plus1-structured", "finding-plus1-T3-omega2-k1-structured",
              "finding-sqrt2-R5.4-union-k2-perturbed",
              "eq3.13-sign", "rate-T3-k1", "rate-T5-k2"]


def _verify_claims(wd: Path) -> str:
    _copy_workflow(wd)
    run = _snakemake(wd, "verify-claims", "--profile", "profiles/ci")
    assert run.returncode == 0, run.stderr[-4000:]
    return str(wd)


@pytest.fixture
def ci_run(tmp_path_factory):
    """One `verify-claims` run on the quick profile, shared (read only) by the tests below."""
    return Path(once(tmp_path_factory, "e2e_ci_run", _verify_claims))


def test_verify_claims_ci_profile(ci_run):
    """`snakemake verify-claims --profile profiles/ci`: every claim as the paper predicts."""
    wd = ci_run
    ledger = read_table(wd / "results" / "claims.csv", "claims")  # checked: the schema holds
    assert list(ledger.columns[:5]) == ["claim_id", "paper_ref", "statement", "evidence", "verdict"]
    assert set(ledger.verdict) <= {"PASS", "FAIL", "INCONCLUSIVE"}
    assert set(KEY_CLAIMS) <= set(ledger.claim_id)
    paper = ledger[ledger.predicted != "finding"]
    assert (paper.verdict == paper.predicted).all(), paper[paper.verdict != paper.predicted]
    assert (ledger.predicted == "finding").any(), "the ledger lists findings beyond the paper"


HAVE_TEX = shutil.which("latexmk") and shutil.which("pdflatex") and shutil.which("pdftotext")


def _pdf_text(path: Path) -> str:
    return subprocess.run(["pdftotext", str(path), "-"], capture_output=True, text=True, check=True).stdout


def _macro(macros: Path, name: str) -> str:
    """The value of ``\\newcommand{\\name}{value}`` in the generated macros file."""
    found = re.search(r"\\newcommand\{\\" + name + r"\}\{([^}]*)\}", macros.read_text())
    assert found, f"macro {name} not generated"
    return found.group(1)


# slow_first (tests/conftest.py): the longest call of the suite, and the first to ask for ci_run builds it
# at the front of the run, so test_verify_claims_ci_profile (left in place, not next to it: two workers
# would wait on one lock) finds it built instead of forming the run's tail
@pytest.mark.slow_first
@pytest.mark.skipif(not HAVE_TEX, reason="TeX (latexmk, pdflatex) or pdftotext missing: .ci/run installs them")
def test_paper_numbers_follow_tables_and_config(ci_run, tmp_path):
    """`snakemake paper --profile profiles/ci` builds the PDF; its numbers come from the tables,
    and changing one config value (the rate-fit window) changes the number in the PDF, rerunning
    the rates and what follows them, not the contact solves nor the timings."""
    wd = ci_run
    run = _snakemake(wd, "paper", "--profile", "profiles/ci")
    assert run.returncode == 0, run.stderr[-4000:]
    pdf, macros = wd / "results/paper/paper.pdf", wd / "results/paper/macros.tex"
    rates = read_table(wd / "results/tables/rates.csv", "rates")
    row = rates[(rates.scene == "manufactured") & (rates.case == "T3") & (rates.k == 2)
                & (rates.measure == "lambda_l2_error") & (rates.family == "structured")].iloc[0]
    before = _macro(macros, "slopeLambdaLtwoTthreeKtwo")
    assert float(before) == pytest.approx(row.slope, abs=0.006)
    assert before in _pdf_text(pdf)
    cfg = (wd / "config/ci.yaml").read_text()
    (wd / "config/ci.yaml").write_text(cfg.replace("rate_window: 3", "rate_window: 2"))
    run = _snakemake(wd, "paper", "--profile", "profiles/ci")
    assert run.returncode == 0, run.stderr[-4000:]
    reran = set(re.findall(r"^(?:local)?rule (\w+):", run.stderr, re.M))
    # the fit window is read by the rates and what follows: no solve and no timing reruns
    assert "rates" in reran and not reran & {"contact_job", "membranes_reference", "speed_accuracy"}, reran
    after = _macro(macros, "slopeLambdaLtwoTthreeKtwo")
    assert after != before and after in _pdf_text(pdf)


def _batch_with(family, k, pair):
    """The β batch of the CI config holding ``pair`` (a β job computes a batch of pairs)."""
    import yaml

    from infsup_contact.study.beta.batches import beta_batches

    ic = yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())["infsup"]
    return next(f"results/tables/beta/{b}.csv" for b, v in beta_batches(ic).items()
                if v["family"] == family and v["k"] == k and pair in v["pairs"])


# a matching and a non-matching β batch (two seeds on perturbed meshes) and a membranes
# contact job (which needs the reference job first)
TARGETS = [_batch_with("structured", 2, (8, 8)), _batch_with("perturbed", 1, (6, 4)),
           "results/tables/contact/membranes_structured_k1.csv"]


def _clean_run(wd: Path) -> Path:
    """``TARGETS`` made by one uninterrupted run in a fresh copy of the workflow in ``wd``."""
    wd.mkdir()
    _copy_workflow(wd)
    run = _snakemake(wd, *TARGETS, "--profile", "profiles/ci")
    assert run.returncode == 0, run.stderr[-3000:]
    return wd


@pytest.fixture
def clean_targets(tmp_path_factory):
    """One clean run of ``TARGETS`` per pytest run: the first of the two compared below and the
    reference of the killed run (read only)."""
    return Path(once(tmp_path_factory, "e2e_targets", lambda folder: str(_clean_run(folder / "a"))))


def test_two_clean_runs_are_byte_identical(clean_targets, tmp_path):
    outs = [[(wd / t).read_bytes() for t in TARGETS] for wd in (clean_targets, _clean_run(tmp_path / "b"))]
    assert outs[0] == outs[1]


def _job_pids(wd: Path):
    """PIDs of running job scripts of the Snakemake run in ``wd`` (their cmdline names its copy)."""
    pids = []
    for proc in Path("/proc").iterdir():
        try:
            cmd = (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except (OSError, ValueError):
            continue
        if str(wd) in cmd and ".snakemake/scripts" in cmd:
            pids.append(int(proc.name))
    return pids


@pytest.mark.slow_first  # builds clean_targets early; test_two_clean_runs_are_byte_identical then finds it
def test_killed_job_then_rerun_completes_identically(clean_targets, tmp_path):
    """SIGKILL a job mid-run, run again: same tables as an uninterrupted run (``clean_targets``)."""
    clean = clean_targets
    (tmp_path / "killed").mkdir()
    wd = _copy_workflow(tmp_path / "killed")
    proc = subprocess.Popen([str(BIN / "snakemake"), *TARGETS, "--profile", "profiles/ci"], cwd=wd,
                            env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline, killed = time.time() + 120, []
    while time.time() < deadline and not killed and proc.poll() is None:
        for pid in _job_pids(wd):
            time.sleep(0.5)  # let the job get into its computation
            try:
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
            except ProcessLookupError:
                pass
        time.sleep(0.05)
    assert proc.wait(timeout=300) != 0 and killed, "no job was killed"
    partial = [t for t in TARGETS if (wd / t).exists()]
    assert len(partial) < len(TARGETS), "the run finished before the kill; nothing was tested"
    rerun = _snakemake(wd, *TARGETS, "--profile", "profiles/ci")
    assert rerun.returncode == 0, rerun.stderr[-3000:]
    for t in TARGETS:
        assert (wd / t).read_bytes() == (clean / t).read_bytes(), t
