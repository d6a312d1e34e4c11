"""Provenance of a run: library versions, git commit, platform, date."""
from __future__ import annotations

import datetime as _dt
import importlib.metadata as _md
import platform
import subprocess
from pathlib import Path

PACKAGES = ("ngsolve", "numpy", "scipy", "pandas", "matplotlib", "snakemake")


def git_commit(root: Path | None = None) -> str:
    """HEAD of the repository holding this package ("unknown" outside git); "+dirty" if modified."""
    root = root or Path(__file__).resolve().parents[2]
    try:
        run = lambda *a: subprocess.run(["git", *a], cwd=root, capture_output=True, text=True, check=True).stdout.strip()
        sha = run("rev-parse", "HEAD")
        dirty = run("status", "--porcelain", "--untracked-files=no")
        return sha + ("+dirty" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def versions() -> dict:
    """Installed versions of the libraries the numbers depend on."""
    out = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = _md.version(name)
        except _md.PackageNotFoundError:
            out[name] = "not installed"
    out["infsup_contact"] = _md.version("infsup-contact")
    return out


def provenance() -> dict:
    """Everything needed to say where a result came from."""
    return {
        "versions": versions(),
        "git_commit": git_commit(),
        "platform": platform.platform(),
        "machine": platform.machine(),
        "cpu_count": __import__("os").cpu_count(),
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    }
