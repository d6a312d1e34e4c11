"""Shared glue for workflow scripts: thread limits, provenance columns, logging."""
import hashlib
import json
import os
import sys


def limit_threads(n: int) -> None:
    """Cap BLAS/OpenMP threads at the job's `threads:` (must run before numpy loads)."""
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = str(n)


def config_hash(cfg) -> str:
    """Short stable hash of a config (sub)tree."""
    return hashlib.sha256(json.dumps(cfg, sort_keys=True).encode()).hexdigest()[:12]


def add_provenance(frame, cfg):
    """Provenance columns: package version, git commit, config hash."""
    from infsup_contact import __version__
    from infsup_contact.provenance import git_commit

    return frame.assign(package_version=__version__, git_commit=git_commit(), config_hash=config_hash(cfg))


def register_user_spaces(config) -> None:
    """Register the config's user-defined spaces (key ``spaces``) in this job's process, so
    that its case ids resolve here as they did when the config was validated."""
    from infsup_contact.discretization.spaces.user_spaces import load_user_spaces

    load_user_spaces(config.get("spaces") or [])


def log_to(path):
    """Send this script's stderr to the rule's log file."""
    sys.stderr = open(path, "w")


def fail(message: str) -> None:
    """Stop the job with one line, in its log and on the terminal (exit status 1)."""
    print(message, file=sys.stderr)
    if sys.stderr is not sys.__stderr__:
        print(message, file=sys.__stderr__)
    sys.exit(1)


def read_table(path, kind: str, **kwargs):
    """A workflow table, checked (``infsup_contact.io.read_table``): a missing file or column
    is one line naming the file, never an AttributeError deep in a plot."""
    from infsup_contact.io import TableError, read_table as read

    try:
        return read(path, kind, **kwargs)
    except TableError as err:
        name = os.path.basename(sys.argv[0]) or "script"
        if name.startswith("tmp") and name.count(".") > 1:  # Snakemake's copy: tmp<random>.claims.py
            name = name.split(".", 1)[1]
        fail(f"{name}: {err}")


def write_claims(path, table) -> None:
    """Write a claims table (the ledger or one model's claims, columns
    ``infsup_contact.criteria.claims.COLUMNS``) atomically and list its ids, verdicts and
    predictions in the job's log: every claims job writes through here."""
    from infsup_contact.io import write_csv_atomic

    write_csv_atomic(path, table)
    print(table[["claim_id", "verdict", "predicted"]].to_string(), file=sys.stderr)
