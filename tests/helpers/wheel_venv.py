"""Helpers of the package tests (tests/package/): processes that see only the installed wheel."""
from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD_INPUTS = ("pyproject.toml", "README.md", "src")
"""What the wheel's build reads from the tree (also what action.yml copies before its install)."""
TIMINGS: dict[str, float] = {}


def _in_ci() -> bool:
    return os.environ.get("CI", "").lower() in ("true", "1", "yes")


def require(condition: bool, reason: str) -> None:
    """Skip with ``reason`` when ``condition`` fails, but fail under CI=true (tests/package/conftest.py)."""
    if not condition:
        (pytest.fail if _in_ci() else pytest.skip)(f"package test: {reason}")


def clean_env(**extra) -> dict:
    """The environment of a process that must see the installed package only: no PYTHONPATH
    (a developer's ``PYTHONPATH=src``), no active venv, one BLAS thread."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1", **extra)
    return env


def run(argv, timeout=900, **kwargs) -> subprocess.CompletedProcess:
    kwargs.setdefault("env", clean_env())
    return subprocess.run([str(a) for a in argv], capture_output=True, text=True, timeout=timeout, **kwargs)


def timed(key: str, argv, **kwargs) -> subprocess.CompletedProcess:
    start = time.perf_counter()
    proc = run(argv, **kwargs)
    TIMINGS[key] = time.perf_counter() - start
    assert proc.returncode == 0, f"{key}: exit {proc.returncode}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return proc


def copy_build_inputs(target: Path, extra=()) -> Path:
    """``target`` holding the tree's build inputs (and ``extra`` files), without caches."""
    target.mkdir(parents=True)
    for name in (*BUILD_INPUTS, *extra):
        src = ROOT / name
        if src.is_dir():
            shutil.copytree(src, target / name, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        else:
            shutil.copy2(src, target / name)
    return target
