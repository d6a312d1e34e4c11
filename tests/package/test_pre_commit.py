"""The pre-commit hook as a project runs it (pre-commit from the hashed requirements-gate.lock) on
a scratch git repository of the hook (the tree's build inputs and .pre-commit-hooks.yaml,
committed: pre-commit clones a ref), in a scratch project holding exported manifests: once by
``pre-commit try-repo`` and then by ``pre-commit run`` from a ``.pre-commit-config.yaml`` that
pins the repository's commit. pre-commit makes its own venv and pip-installs the repository
into it from PyPI — the install issue 50 found broken. try-repo keeps no store between calls
(a fresh one in a temporary directory, pre_commit/commands/try_repo.py), so it runs once."""
from __future__ import annotations

import shutil
import subprocess

import pytest
from helpers.wheel_venv import TIMINGS, clean_env, copy_build_inputs, run

pytestmark = pytest.mark.package

HOOK_ID = "infsup-contact-verdict"


def git(cwd, *args):
    subprocess.run(["git", "-c", "user.name=test", "-c", "user.email=test@example.invalid", "-c",
                    "init.defaultBranch=main", *args], cwd=cwd, check=True, capture_output=True, timeout=120)


@pytest.fixture(scope="module")
def hook_repo(pre_commit, tmp_path_factory):
    """The hook's repository, committed (pre-commit clones a rev)."""
    repo = copy_build_inputs(tmp_path_factory.mktemp("hook") / "repo", extra=(".pre-commit-hooks.yaml",))
    git(repo, "init", "-q")
    git(repo, "add", ".")
    git(repo, "commit", "-q", "-m", "the hook's repository")
    return repo


@pytest.fixture(scope="module")
def project(hook_repo, exported):
    """A project (a git repository) with a STABLE and an UNSTABLE manifest, neither with expect:."""
    root = hook_repo.parent / "project"
    for name in ("stable", "unstable"):
        shutil.copytree(exported[name], root / "systems" / name)
    git(root, "init", "-q")
    git(root, "add", ".")
    return root


def pre_commit_run(pre_commit, argv, cwd, home, key):
    import time

    start = time.perf_counter()
    proc = run([pre_commit, *argv], cwd=cwd, env=clean_env(PRE_COMMIT_HOME=str(home)), timeout=1800)
    TIMINGS[key] = time.perf_counter() - start
    assert "Traceback" not in proc.stdout + proc.stderr, proc.stdout[-4000:] + proc.stderr[-4000:]
    return proc


def test_try_repo(pre_commit, hook_repo, project, tmp_path):
    """try-repo (its own store and hook venv, the repository pip-installed from PyPI): one line
    per manifest, Failed because one is UNSTABLE without expect: (expected STABLE)."""
    proc = pre_commit_run(pre_commit, ["try-repo", hook_repo, HOOK_ID, "--files", "systems/stable/levels.yaml",
                                       "systems/unstable/levels.yaml"], project, tmp_path / "home",
                          "pre-commit try-repo (builds the hook's venv)")
    assert proc.returncode == 1 and "Failed" in proc.stdout, proc.stdout[-4000:] + proc.stderr[-4000:]
    assert "systems/stable/levels.yaml: STABLE (as expected)" in proc.stdout
    assert "systems/unstable/levels.yaml: UNSTABLE (expected STABLE)" in proc.stdout


@pytest.fixture(scope="module")
def configured(hook_repo, project, tmp_path_factory):
    """The project's .pre-commit-config.yaml naming the hook's repository at its commit, as a
    project pins it (``rev:``), and one PRE_COMMIT_HOME: the hook's venv is built once."""
    import yaml

    rev = subprocess.run(["git", "rev-parse", "HEAD"], cwd=hook_repo, capture_output=True, text=True,
                         check=True).stdout.strip()
    config = {"repos": [{"repo": str(hook_repo), "rev": rev, "hooks": [{"id": HOOK_ID}]}]}
    (project / ".pre-commit-config.yaml").write_text(yaml.safe_dump(config))
    git(project, "add", ".pre-commit-config.yaml")  # pre-commit refuses an unstaged config
    return project, tmp_path_factory.mktemp("pre-commit-home")


def test_run_passes_a_stable_manifest(pre_commit, configured):
    project, home = configured
    proc = pre_commit_run(pre_commit, ["run", "--files", "systems/stable/levels.yaml"], project, home,
                          "pre-commit run (first: builds the hook's venv)")
    assert proc.returncode == 0 and "Passed" in proc.stdout, proc.stdout[-4000:] + proc.stderr[-4000:]


def test_run_skips_files_that_are_not_manifests(pre_commit, configured):
    """The hook's files: pattern: a changed matrix alone runs nothing ("no files to check")."""
    project, home = configured
    matrix = next((project / "systems" / "unstable").glob("*.mtx")).relative_to(project)
    proc = pre_commit_run(pre_commit, ["run", "--files", str(matrix)], project, home, "pre-commit run (a matrix)")
    assert proc.returncode == 0 and "no files to check" in proc.stdout.lower(), proc.stdout
