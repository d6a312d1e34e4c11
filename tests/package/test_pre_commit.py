"""The pre-commit hook as a project runs it: ``pre-commit try-repo`` (pre-commit from the hashed
requirements-gate.lock) on a scratch git repository of the hook (the tree's build inputs and
.pre-commit-hooks.yaml, committed: try-repo clones a ref), in a scratch project holding exported
manifests. pre-commit makes its own venv and pip-installs the repository into it from PyPI —
the install issue 50 found broken. Passed on a STABLE manifest (exit 0), Failed with the
verdict line on an UNSTABLE one (exit 1)."""
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
    """The hook's repository; each project is made beside it, so try-repo names it ``../repo``
    every time and pre-commit reuses the hook's venv (its store is keyed by that name and rev)."""
    repo = copy_build_inputs(tmp_path_factory.mktemp("hook") / "repo", extra=(".pre-commit-hooks.yaml",))
    git(repo, "init", "-q")
    git(repo, "add", ".")
    git(repo, "commit", "-q", "-m", "the hook's repository")
    return repo


@pytest.fixture(scope="module")
def home(tmp_path_factory):
    """PRE_COMMIT_HOME: the hook's venv is built by the first try-repo and reused by the next."""
    return tmp_path_factory.mktemp("pre-commit-home")


def try_repo(pre_commit, hook_repo, home, project, manifest):
    import time

    start = time.perf_counter()
    proc = run([pre_commit, "try-repo", hook_repo, HOOK_ID, "--files", manifest], cwd=project,
               env=clean_env(PRE_COMMIT_HOME=str(home)), timeout=1800)
    TIMINGS[f"pre-commit try-repo {manifest}"] = time.perf_counter() - start
    return proc


def project_with(hook_repo, exports, name):
    project = hook_repo.parent / f"project-{name}"
    shutil.copytree(exports, project / "systems")
    (project / "systems" / "levels.yaml").rename(project / "systems" / name)
    git(project, "init", "-q")
    git(project, "add", ".")
    return project


@pytest.mark.parametrize("name, code, word", [("stable", 0, "Passed"), ("unstable", 1, "Failed")])
def test_try_repo(pre_commit, hook_repo, home, exported, name, code, word):
    project = project_with(hook_repo, exported[name], f"{name}.levels.yaml")
    proc = try_repo(pre_commit, hook_repo, home, project, f"systems/{name}.levels.yaml")
    assert proc.returncode == code, proc.stdout[-4000:] + proc.stderr[-4000:]
    assert f"{word}" in proc.stdout and "Traceback" not in proc.stdout + proc.stderr
    verdict = "STABLE (as expected)" if name == "stable" else "UNSTABLE (expected STABLE)"
    if code:  # pre-commit shows a failing hook's output
        assert verdict in proc.stdout


def test_try_repo_skips_files_that_are_not_manifests(pre_commit, hook_repo, home, exported):
    """The hook's files: pattern: a changed matrix alone runs nothing ("no files to check")."""
    project = project_with(hook_repo, exported["unstable"], "levels.yaml")
    matrix = next(p.name for p in (project / "systems").glob("*.mtx"))
    proc = try_repo(pre_commit, hook_repo, home, project, f"systems/{matrix}")
    assert proc.returncode == 0 and "no files to check" in proc.stdout.lower(), proc.stdout
