"""The composite action (``action.yml``) as a runner executes it: every ``run:`` step in order
(``uses:`` steps — setup-python — are what the clean venv on PATH stands for), each body by
``bash --noprofile --norc -eo pipefail`` with its ``env`` evaluated from the inputs and
``github.action_path``, and ``GITHUB_OUTPUT``, ``GITHUB_STEP_SUMMARY``, ``RUNNER_TEMP`` set as
the runner sets them. The install step installs the built wheel (input ``version``), or the
action's own checkout, which it must leave as it found it. Exit codes of the verdict step: 0
the verdict matches (or no expectation), 1 it differs, 2 a refused manifest or a missing file,
70 an unexpected exception — each with the outputs the action documents."""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import yaml
from helpers.wheel_venv import ROOT, clean_env, copy_build_inputs, run

pytestmark = pytest.mark.package

ACTION = yaml.safe_load((ROOT / "action.yml").read_text())
EXPRESSION = re.compile(r"\$\{\{\s*([\w.-]+)\s*\}\}")


def run_action(tmp_path: Path, venv_bin: Path, workdir: Path, inputs: dict, action_path: Path = ROOT,
               extra_env: dict | None = None):
    """Every step; (exit code of the first failing step or 0, name of that step, outputs, stderr
    of all steps, step summary)."""
    values = {f"inputs.{k}": str(v.get("default", "")) for k, v in ACTION["inputs"].items()}
    values.update({f"inputs.{k}": str(v) for k, v in inputs.items()}, **{"github.action_path": str(action_path)})
    files = {name: tmp_path / f"github_{name}" for name in ("output", "env", "summary", "path")}
    for f in files.values():
        f.write_text("")
    runner_temp = tmp_path / "runner_temp"
    runner_temp.mkdir(exist_ok=True)
    base = clean_env(GITHUB_OUTPUT=str(files["output"]), GITHUB_ENV=str(files["env"]), GITHUB_PATH=str(files["path"]),
                     GITHUB_STEP_SUMMARY=str(files["summary"]), GITHUB_ACTIONS="true", GITHUB_WORKSPACE=str(workdir),
                     RUNNER_TEMP=str(runner_temp), **(extra_env or {}))
    base["PATH"] = f"{venv_bin}:{base['PATH']}"  # what actions/setup-python does for its Python
    stderr, code, failed = "", 0, None
    for i, step in enumerate(ACTION["runs"]["steps"]):
        if "uses" in step:
            continue
        assert step["shell"] == "bash" and "${{" not in step["run"]
        env = dict(base, **{k: EXPRESSION.sub(lambda m: values[m.group(1)], str(v)) for k, v in step.get("env", {}).items()})
        script = tmp_path / f"step{i}.sh"
        script.write_text(step["run"])
        proc = run(["bash", "--noprofile", "--norc", "-eo", "pipefail", script], cwd=workdir, env=env)
        stderr += proc.stderr
        if proc.returncode:
            code, failed = proc.returncode, step.get("id") or step.get("name")
            break
    outputs = dict(line.split("=", 1) for line in files["output"].read_text().splitlines())
    return code, failed, outputs, stderr, files["summary"].read_text()


def annotations(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("::")]


@pytest.mark.parametrize("name, expect, code", [
    ("stable", "stable", 0), ("unstable", "stable", 1), ("unstable", "unstable", 0), ("inconclusive", "", 0),
    ("inconclusive", "stable", 1)])
def test_verdicts(clean_venv, wheel, exported, tmp_path, name, expect, code):
    workdir = exported[name].parent
    got, step, outputs, err, summary = run_action(tmp_path, clean_venv, workdir,
                                                  {"system": "exports/levels.yaml", "expect": expect,
                                                   "version": str(wheel)})
    assert got == code and step in (None, "verdict"), err
    record = json.loads(Path(outputs["json"]).read_text())
    assert outputs["verdict"] == record["verdict"] == name.upper() and record["exit_code"] == code
    assert float(outputs["beta_min"]) == record["beta_min"]
    assert (record["beta_min"] == 0) is (name == "unstable")  # R5.4's kernel: β_h = 0; T3's β_h > 0
    assert "Traceback" not in err
    level = ("error" if code == 1 or name == "unstable" and not expect else
             "warning" if name == "inconclusive" else "notice")
    (command,) = annotations(err)
    assert command.startswith(f"::{level} file=exports/levels.yaml,")
    assert f"— {name.upper()}" in summary


@pytest.mark.parametrize("system, needle", [("exports/absent.yaml", "absent.yaml"), ("exports/refused.yaml", "at least 3")])
def test_refused_manifest_and_missing_file_are_exit_2_one_line(clean_venv, wheel, exported, tmp_path, system, needle):
    workdir = exported["stable"].parent
    (workdir / "exports" / "refused.yaml").write_text("levels: [{h: 0.5, A: A.mtx, B: B.mtx, G: G.mtx}]\n")
    got, step, outputs, err, _ = run_action(tmp_path, clean_venv, workdir,
                                            {"system": system, "expect": "stable", "version": str(wheel)})
    assert (got, step, outputs) == (2, "verdict", {})
    lines = [line for line in err.splitlines() if line.startswith("infsup-contact")]
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in err, err


def test_an_unexpected_exception_is_exit_70_not_1(clean_venv, wheel, exported, tmp_path):
    """A bug inside verdict (forced: system_verdict raises, by a sitecustomize on PYTHONPATH) is
    70 from the step, one line, no outputs: never 1, which the action documents as "differs"."""
    hook = tmp_path / "site"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(
        "def _boom(*args, **kwargs):\n    raise ZeroDivisionError('forced by the test')\n"
        "import infsup_contact.systems.levels as _levels\n_levels.system_verdict = _boom\n")
    got, step, outputs, err, _ = run_action(tmp_path, clean_venv, exported["stable"].parent,
                                            {"system": "exports/levels.yaml", "expect": "stable",
                                             "version": str(wheel)}, extra_env={"PYTHONPATH": str(hook)})
    assert (got, step, outputs) == (70, "verdict", {}), err
    (line,) = [line for line in err.splitlines() if "internal error" in line]
    assert "ZeroDivisionError: forced by the test" in line and "Traceback" not in err


def test_default_install_leaves_the_action_checkout_as_it_was(clean_venv, exported, tmp_path):
    """``version`` empty: the action installs its own checkout (here a copy of the tree, as the
    runner downloads it: no .git) and leaves no build/ or *.egg-info in it."""
    checkout = copy_build_inputs(tmp_path / "action", extra=("action.yml",))
    before = sorted(p.relative_to(checkout) for p in checkout.rglob("*"))
    got, step, outputs, err, _ = run_action(tmp_path, clean_venv, exported["stable"].parent,
                                            {"system": "exports/levels.yaml", "expect": "stable"}, action_path=checkout)
    assert got == 0 and outputs["verdict"] == "STABLE", err
    assert sorted(p.relative_to(checkout) for p in checkout.rglob("*")) == before
    assert not list((tmp_path / "runner_temp").glob("infsup-contact-src.*"))  # its build copy removed


def test_norm_override(clean_venv, wheel, exported, tmp_path):
    workdir = exported["stable"].parent
    before = sorted(p.name for p in exported["stable"].iterdir())
    got, _, outputs, err, _ = run_action(tmp_path, clean_venv, workdir, {"system": "exports/levels.yaml", "norm": "h-L2",
                                                                        "version": str(wheel)})
    assert got == 0, err
    assert json.loads(Path(outputs["json"]).read_text())["norm"] == "h-L2"
    assert sorted(p.name for p in exported["stable"].iterdir()) == before
