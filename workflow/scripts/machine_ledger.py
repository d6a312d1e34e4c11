"""The CI profile's ledger on one machine path, in a workflow copy of its own.

usage: machine_ledger.py PATH OUTPUT.json CORES

PATH is a path of infsup_contact.study.machines.paths.PATHS by its wildcard (``openblas-Haswell``,
``mkl-COMPATIBLE``). Links the workflow's sources into results/machines/PATH/work, runs
`snakemake results/claims.csv --profile profiles/ci` there in the path's environment
(machines.machine_env), copies the tables of machines.LEDGER_TABLES to
results/machines/PATH/ledger/ and writes OUTPUT.json: whether it ran (or why not, when the CPU
cannot take the path), its environment, the kernels OpenBLAS reported and MKL's branch and
digits there (the evidence the path took effect), the ledger's folder. A failed run or a
table missing exits non-zero, with no OUTPUT.json.
"""
import json
import shutil
import subprocess
import sys
from pathlib import Path

from infsup_contact.io import write_atomic
from infsup_contact.study.machines.ledgers import LEDGER_TABLES
from infsup_contact.study.machines.paths import SWITCHES, machine_env, machine_path, runnable

SOURCES = ("Snakefile", "workflow", "src", "config", "profiles", "paper", "examples")


def main(wildcard: str, output: str, cores: str) -> None:
    path = machine_path(wildcard)
    out = Path(output)
    ok, reason = runnable(path.name)
    if not ok:
        print(f"machine_ledger: {path.name} skipped: {reason}", file=sys.stderr)
        write_atomic(out, json.dumps(dict(path=path.name, ran=False, reason=reason), indent=1))
        return
    work = out.parent / path.wildcard / "work"
    work.mkdir(parents=True, exist_ok=True)
    for name in SOURCES:
        link = work / name
        if not link.is_symlink():
            link.symlink_to(Path(name).resolve())
    env = machine_env(path.name)
    switches = {k: env[k] for k in SWITCHES if k in env}
    cmd = ["snakemake", "results/claims.csv", "--profile", "profiles/ci", "--cores", cores, "--quiet"]
    run = subprocess.run(cmd, cwd=work, env=env)
    if run.returncode:
        sys.exit(f"machine_ledger: the CI ledger on {path.name} ({switches}) failed (exit {run.returncode}); "
                 f"see {work}/.snakemake/log")
    ledger = out.parent / path.wildcard / "ledger"
    for table in LEDGER_TABLES:
        src = work / table
        if not src.is_file():
            sys.exit(f"machine_ledger: the CI run on {path.name} wrote no {table}")
        (ledger / table).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, ledger / table)
    probe = subprocess.run([sys.executable, "-m", "infsup_contact.study.machines.paths", "--probe"], env=env,
                           capture_output=True, text=True, check=True).stdout
    write_atomic(out, json.dumps(dict(path=path.name, ran=True, reason="", env=switches, **json.loads(probe),
                                      ledger=str(ledger)), indent=1))


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:4])
