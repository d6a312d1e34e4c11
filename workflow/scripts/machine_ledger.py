"""The CI profile's ledger under one OpenBLAS core type, in a workflow copy of its own.

usage: machine_ledger.py CORE OUTPUT.json CORES

Links the workflow's sources into results/machines/CORE/work, runs `snakemake results/claims.csv
--profile profiles/ci` there with OPENBLAS_CORETYPE=CORE, copies the ledger to
results/machines/CORE/claims.csv and writes OUTPUT.json: whether it ran (or why not, when the
CPU cannot execute that core type's kernels), the kernels OpenBLAS reported, the ledger's path.
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from infsup_contact.io import write_atomic
from infsup_contact.study.machines import machine_env, runnable

SOURCES = ("Snakefile", "workflow", "src", "config", "profiles", "paper", "examples")


def main(core: str, output: str, cores: str) -> None:
    out = Path(output)
    ok, reason = runnable(core)
    if not ok:
        print(f"machine_ledger: {core} skipped: {reason}", file=sys.stderr)
        write_atomic(out, json.dumps(dict(core=core, ran=False, reason=reason), indent=1))
        return
    work = out.parent / core / "work"
    work.mkdir(parents=True, exist_ok=True)
    for name in SOURCES:
        link = work / name
        if not link.is_symlink():
            link.symlink_to(Path(name).resolve())
    env = machine_env(core)
    cmd = ["snakemake", "results/claims.csv", "--profile", "profiles/ci", "--cores", cores, "--quiet"]
    run = subprocess.run(cmd, cwd=work, env=env)
    if run.returncode:
        sys.exit(f"machine_ledger: the CI ledger under OPENBLAS_CORETYPE={core} failed (exit {run.returncode}); "
                 f"see {work}/.snakemake/log")
    ledger = out.parent / core / "claims.csv"
    shutil.copyfile(work / "results" / "claims.csv", ledger)
    names = subprocess.run([sys.executable, "-c", "import json; from infsup_contact.study.machines import "
                            "openblas_corenames as f; print(json.dumps(f()))"], env=env, capture_output=True,
                           text=True, check=True).stdout
    write_atomic(out, json.dumps(dict(core=core, ran=True, reason="", openblas=json.loads(names),
                                      ledger=str(ledger)), indent=1))


if __name__ == "__main__":
    main(*sys.argv[1:4])
