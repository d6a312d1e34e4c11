"""An unexpected exception is exit 70 (``cli/program.py``) with one line, never 1 (which means
"the verdict differs from the expectation"), in ``main`` and in ``verdict-hook``; the traceback
only with ``INFSUP_TRACEBACK=1``. ``--version`` is the installed distribution's."""
from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

import pytest
from helpers.cli import run_in_process

from infsup_contact.cli.program import EXIT_SOFTWARE, TRACEBACK_ENV

def explode(*args, **kwargs):
    raise RuntimeError("boom\nsecond line")


@pytest.fixture
def broken_beta(monkeypatch):
    """``beta``'s computation raises something no handler expects (a bug)."""
    monkeypatch.setattr("infsup_contact.cli.beta.beta_frame", explode)
    monkeypatch.delenv(TRACEBACK_ENV, raising=False)


ARGV = ["beta", "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4"]


def test_unexpected_exception_is_exit_70_and_one_line(broken_beta):
    code, out, err = run_in_process(ARGV)
    assert code == EXIT_SOFTWARE == 70 and out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith("infsup-contact: internal error: RuntimeError: boom second line")
    assert "report" in lines[0] and TRACEBACK_ENV in lines[0]


def test_traceback_on_request(broken_beta, monkeypatch):
    monkeypatch.setenv(TRACEBACK_ENV, "1")
    code, _, err = run_in_process(ARGV)
    assert code == 70 and err.startswith("Traceback") and "in explode" in err
    assert err.splitlines()[-1].startswith("infsup-contact: internal error: RuntimeError")


def test_a_missing_module_says_the_installation_is_incomplete(monkeypatch):
    def no_yaml(*args, **kwargs):
        raise ModuleNotFoundError("No module named 'yaml'", name="yaml")

    monkeypatch.setattr("infsup_contact.cli.beta.beta_frame", no_yaml)
    code, _, err = run_in_process(ARGV)
    assert code == 70 and len(err.splitlines()) == 1
    assert "ModuleNotFoundError: No module named 'yaml'" in err and "installation is incomplete" in err


def test_hook_reports_the_bug_as_70_and_checks_the_other_manifests(monkeypatch, tmp_path):
    """The first manifest's check raises, the second is refused (2): 70 wins, both reported."""
    calls = []

    def check_one(path, criterion):
        calls.append(path)
        if len(calls) == 1:
            raise KeyError("level")
        return 2, f"infsup-contact: error: {path}: refused"

    monkeypatch.setattr("infsup_contact.cli.verdict_hook.check_one", check_one)
    code, out, err = run_in_process(["verdict-hook", "a/levels.yaml", "b/levels.yaml"])
    assert code == 70 and out == "" and calls == ["a/levels.yaml", "b/levels.yaml"]
    first, second = err.splitlines()
    assert first.startswith("infsup-contact: internal error (a/levels.yaml): KeyError") and "b/levels.yaml" in second


def test_version_is_the_distributions():
    code, out, err = run_in_process(["--version"])
    assert code == 0 and err == ""
    try:
        expected = version("infsup-contact")
    except PackageNotFoundError:  # a source tree run without installing: pyproject's version
        import tomllib
        from pathlib import Path

        pyproject = Path(__file__).resolve().parents[2] / "pyproject.toml"
        expected = tomllib.loads(pyproject.read_text())["project"]["version"]
    assert out.startswith(f"infsup-contact {expected}") and out.count("\n") == 1
