"""The package as a user gets it: a wheel built from the tree, installed into a clean venv from
PyPI WITHOUT environment.lock (``pip install <wheel>``, what ``action.yml`` and pre-commit do).

Runs only under ``pytest -m package`` (``.ci/run`` runs it after ``make test``); otherwise each
test is skipped with the reason. Selected, a missing prerequisite (``git``, the ``venv`` module)
skips with the reason outside CI and FAILS under ``CI=true``: CI has all of them, so a skip
there would hide a gate that never ran. Failing installs are failures everywhere (that is what
is tested). The wheel is built from a copy of what the build reads (pyproject.toml, README.md,
src/) in a temporary directory, so the checkout gets no build/ or *.egg-info (checked).
Timings (wheel build, install) go to the terminal summary.
"""
from __future__ import annotations

import sys

import pytest
from helpers.wheel_venv import ROOT, TIMINGS, copy_build_inputs, require, timed


def _tree_state() -> set:
    """The names the build could leave in the checkout: top level and src/."""
    return {p.name for p in ROOT.iterdir()} | {f"src/{p.name}" for p in (ROOT / "src").iterdir()}


def _asked_for(markexpr: str, marker: str) -> bool:
    from helpers.markers import asked_for

    return asked_for(markexpr, marker)


@pytest.fixture(scope="session")
def package_selected(request):
    if not _asked_for(request.config.getoption("markexpr") or "", "package"):
        pytest.skip("package test: runs only under `pytest -m package` (.ci/run runs it; it installs from PyPI)")
    try:
        import venv  # noqa: F401
        import ensurepip  # noqa: F401
        have_venv = True
    except ImportError:
        have_venv = False
    require(have_venv, "the venv module with ensurepip is missing (Debian: apt-get install python3-venv)")


@pytest.fixture(scope="session")
def wheel(package_selected, tmp_path_factory) -> Path:
    """The wheel built from the tree (pip wheel --no-deps; build isolation fetches setuptools)."""
    base = tmp_path_factory.mktemp("wheel")
    before = _tree_state()
    source = copy_build_inputs(base / "source")
    timed("wheel build", [sys.executable, "-m", "pip", "wheel", "--no-deps", "--disable-pip-version-check",
                          "--wheel-dir", base / "dist", source], cwd=base)
    assert _tree_state() == before, "the build left files in the checkout"
    wheels = list((base / "dist").glob("infsup_contact-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


@pytest.fixture(scope="session")
def clean_venv(wheel, tmp_path_factory) -> Path:
    """A venv with only the wheel, its dependencies resolved from PyPI (no lock): its bin/."""
    root = tmp_path_factory.mktemp("venv") / "venv"
    timed("venv create", [sys.executable, "-m", "venv", root])
    timed("clean-venv install", [root / "bin" / "python", "-m", "pip", "install", "--disable-pip-version-check",
                                 wheel])
    return root / "bin"


def pytest_terminal_summary(terminalreporter):
    if TIMINGS:
        terminalreporter.section("package: timings")
        for key, seconds in TIMINGS.items():
            terminalreporter.write_line(f"{key}: {seconds:.1f} s")


SYSTEMS = {"stable": ("T3", "8 16 32"), "inconclusive": ("T3", "4 8 16"), "unstable": ("R5.4", "4 8 16")}
"""k = 1 exports (as tests/cli/test_verdict_formats.py): T3 is STABLE on 8, 16, 32 and still
INCONCLUSIVE on 4, 8, 16 (its slope's interval reaches past τ); R5.4 has a kernel: UNSTABLE."""


@pytest.fixture(scope="session")
def exported(clean_venv, tmp_path_factory) -> dict:
    """name → the directory of ``export --case ID --k 1 --N ...`` by the clean venv's CLI."""
    out = {}
    for name, (case, ns) in SYSTEMS.items():
        target = tmp_path_factory.mktemp(name) / "exports"
        timed(f"export {name}", [clean_venv / "infsup-contact", "export", "--case", case, "--k", "1", "--N",
                                 *ns.split(), "--out", target], cwd=target.parent)
        out[name] = target
    return out


@pytest.fixture(scope="session")
def pre_commit(package_selected, tmp_path_factory) -> Path:
    """pre-commit from requirements-gate.lock (hash-checked) in a tool venv: its executable."""
    import shutil

    require(shutil.which("git") is not None, "git is not installed (pre-commit try-repo needs it)")
    root = tmp_path_factory.mktemp("gate") / "venv"
    timed("gate venv", [sys.executable, "-m", "venv", root])
    timed("gate install", [root / "bin" / "python", "-m", "pip", "install", "--disable-pip-version-check",
                           "--require-hashes", "-r", ROOT / "requirements-gate.lock"])
    return root / "bin" / "pre-commit"
