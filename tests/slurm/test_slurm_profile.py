"""The Slurm profile on a live Slurm: `verify-claims` through profiles/slurm gives the local ledger.

Runs only under ``pytest -m slurm`` and only when a Slurm controller answers (as root on
Debian, ``bash tests/slurm/standup.sh`` stands up a single-node one); otherwise skipped with
the reason. Two scratch copies of the workflow run the CI config, one locally
(``--profile profiles/ci``) and one through ``--profile profiles/slurm``; ``results/claims.csv``
and every table must be byte-identical. At the end the daemons standup.sh started are stopped
by their recorded PIDs (tests/slurm/stop.sh; INFSUP_SLURM_KEEP=1 keeps them running).
"""
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent
HERE = Path(__file__).resolve().parent
STATE = Path(os.environ.get("INFSUP_SLURM_STATE", "/run/infsup-contact-slurm"))

pytestmark = pytest.mark.slurm


def _slurm_unavailable():
    """Why Slurm cannot be used here, or None when a node is ready for jobs."""
    if shutil.which("sinfo") is None or shutil.which("sbatch") is None:
        how = ("run `bash tests/slurm/standup.sh` first" if os.geteuid() == 0
               else "as root, `bash tests/slurm/standup.sh` stands up a single-node Slurm")
        return f"no Slurm client (sinfo/sbatch) on PATH: {how}"
    try:
        out = subprocess.run(["sinfo", "-h", "-o", "%t"], capture_output=True, text=True, timeout=30)
    except subprocess.TimeoutExpired:
        return "sinfo did not answer within 30 s"
    states = {s.rstrip("*~#") for s in out.stdout.split()}
    if out.returncode != 0 or not states & {"idle", "mix", "alloc"}:
        return (f"no Slurm node ready (sinfo: {(out.stdout + out.stderr).strip() or 'nothing'}):"
                " run `bash tests/slurm/standup.sh` as root")
    return None


@pytest.fixture(scope="module")
def slurm(request):
    """Skip unless selected with ``-m slurm`` and a controller answers; stop standup.sh's daemons after."""
    if "slurm" not in (request.config.getoption("markexpr") or ""):
        pytest.skip("Slurm test: runs only under `pytest -m slurm` (after `bash tests/slurm/standup.sh` as root)")
    reason = _slurm_unavailable()
    if reason:
        pytest.skip(reason)
    yield
    if (STATE / "daemons.pid").exists() and os.environ.get("INFSUP_SLURM_KEEP") != "1":
        subprocess.run(["bash", str(HERE / "stop.sh")], check=True)


def _copy_workflow(dest: Path) -> Path:
    """The checkout without its results, environment, tests and caches."""
    top = {".git", ".venv", ".snakemake", "results", "tests"}

    def skip(directory, names):
        return [n for n in names if n == "__pycache__" or (Path(directory) == ROOT and n in top)]

    return Path(shutil.copytree(ROOT, dest, ignore=skip))


def _snakemake(cwd, *args, timeout):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env["PATH"] = f"{BIN}:{env.get('PATH', '')}"  # sbatch exports it: jobs use this venv
    start = time.monotonic()
    run = subprocess.run([str(BIN / "snakemake"), *args], cwd=cwd, env=env,
                         capture_output=True, text=True, timeout=timeout)
    return run, time.monotonic() - start


def _outputs(wd: Path):
    """Relative path → bytes of the ledger and every table of a run."""
    files = [wd / "results/claims.csv", *sorted((wd / "results/tables").rglob("*.csv"))]
    return {str(f.relative_to(wd)): f.read_bytes() for f in files}


def test_verify_claims_on_slurm_equals_local_ledger(slurm, tmp_path_factory):
    # a shared file system is needed on a real cluster: INFSUP_SLURM_TMP names one
    base = Path(os.environ.get("INFSUP_SLURM_TMP") or tmp_path_factory.mktemp("slurm"))
    stamp = f"{os.getpid()}-{time.time_ns()}"
    local, cluster = _copy_workflow(base / f"local-{stamp}"), _copy_workflow(base / f"slurm-{stamp}")

    run, t_local = _snakemake(local, "verify-claims", "--profile", "profiles/ci", timeout=1800)
    assert run.returncode == 0, run.stderr[-4000:]

    # the target first: --configfile takes several values and would swallow it
    run, t_slurm = _snakemake(cluster, "verify-claims", "--profile", "profiles/slurm",
                              "--configfile", "config/ci.yaml", timeout=3600)
    assert run.returncode == 0, run.stderr[-4000:]

    log = run.stderr
    submitted = re.findall(r"has been submitted with SLURM jobid (\d+)", log)
    jobs = int(re.search(r"^total\s+(\d+)\s*$", log, re.M).group(1))
    print(f"\nlocal (profiles/ci): {t_local:.0f} s; Slurm (profiles/slurm): {t_slurm:.0f} s, "
          f"{jobs} Snakemake jobs in {len(submitted)} Slurm jobs")
    assert submitted, "no job went through Slurm"
    assert len(set(submitted)) == len(submitted)
    assert len(submitted) < jobs, "the profile's groups did not batch any jobs"

    ours, theirs = _outputs(cluster), _outputs(local)
    assert "results/claims.csv" in ours and sorted(ours) == sorted(theirs)
    for name in theirs:
        assert ours[name] == theirs[name], f"{name} differs between Slurm and the local run"
