"""The composite action (``action.yml``) and the pre-commit hook (``.pre-commit-hooks.yaml``),
offline: the action's verdict step is run by bash as the runner runs it (``bash --noprofile
--norc -eo pipefail``), with its ``env`` evaluated from the inputs and fake ``GITHUB_OUTPUT``,
``GITHUB_ENV``, ``GITHUB_STEP_SUMMARY``; the hook's entry is called on exported manifests."""
from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from helpers.cli import run_in_process

from infsup_contact.systems.manifest import load_manifest

ROOT = Path(__file__).resolve().parents[2]
ACTION = yaml.safe_load((ROOT / "action.yml").read_text())
HOOKS = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())
EXPRESSION = re.compile(r"\$\{\{\s*([\w.-]+)\s*\}\}")


@pytest.fixture(scope="module")
def systems(tmp_path_factory):
    """STABLE (T3, k = 1, N = 8 16 32) and UNSTABLE (R5.4, k = 1, N = 4 8 16) exports."""
    out = {}
    for name, case, ns in (("stable", "T3", "8 16 32"), ("unstable", "R5.4", "4 8 16")):
        target = tmp_path_factory.mktemp(name) / "exports"
        code, _, err = run_in_process(["export", "--case", case, "--k", "1", "--N", *ns.split(), "--out", str(target)])
        assert code == 0, err
        out[name] = target / "levels.yaml"
    return out


# ---------------------------------------------------------------- action.yml
def test_action_declares_the_inputs_and_outputs():
    assert ACTION["runs"]["using"] == "composite"
    assert {"system", "expect", "norm", "python-version", "version"} <= set(ACTION["inputs"])
    assert ACTION["inputs"]["system"]["required"] is True
    step = verdict_step()
    for key in ("verdict", "beta_min", "slope", "json"):
        assert ACTION["outputs"][key]["value"] == f"${{{{ steps.{step['id']}.outputs.{key} }}}}"
        assert ACTION["outputs"][key]["description"]


def test_no_expression_is_spliced_into_a_script():
    """Inputs reach the scripts through env only (an input holding `"; rm -rf ~` stays data)."""
    for step in ACTION["runs"]["steps"]:
        if "run" in step:
            assert "${{" not in step["run"], step.get("name")
            assert step["shell"] == "bash"


def verdict_step() -> dict:
    steps = [s for s in ACTION["runs"]["steps"] if s.get("id") == "verdict"]
    assert len(steps) == 1
    return steps[0]


def run_action_step(tmp_path, inputs: dict, workdir: Path):
    """The verdict step as the runner runs it; (exit code, stderr, outputs dict, output file text)."""
    step = verdict_step()
    values = {f"inputs.{k}": str(v.get("default", "")) for k, v in ACTION["inputs"].items()}
    values.update({f"inputs.{k}": str(v) for k, v in inputs.items()})
    env = {k: EXPRESSION.sub(lambda m: values[m.group(1)], str(v)) for k, v in step["env"].items()}
    files = {name: tmp_path / name for name in ("output", "env", "summary")}
    for f in files.values():
        f.write_text("")
    (tmp_path / "runner_temp").mkdir(exist_ok=True)
    env.update(GITHUB_OUTPUT=str(files["output"]), GITHUB_ENV=str(files["env"]),
               GITHUB_STEP_SUMMARY=str(files["summary"]), GITHUB_ACTIONS="true", GITHUB_WORKSPACE=str(workdir),
               RUNNER_TEMP=str(tmp_path / "runner_temp"), HOME=os.environ.get("HOME", "/tmp"),
               PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    script = tmp_path / "step.sh"
    script.write_text(step["run"])
    proc = subprocess.run(["bash", "--noprofile", "--norc", "-eo", "pipefail", str(script)], cwd=workdir, env=env,
                          capture_output=True, text=True, timeout=300)
    text = files["output"].read_text()
    outputs = dict(line.split("=", 1) for line in text.splitlines())
    return proc.returncode, proc.stderr, outputs, files


@pytest.mark.parametrize("name, expect, code", [("stable", "stable", 0), ("unstable", "stable", 1),
                                                ("unstable", "", 0)])
def test_action_step_writes_the_outputs_and_exits_with_the_verdicts_code(systems, tmp_path, name, expect, code):
    workdir = systems[name].parent.parent
    got, err, outputs, files = run_action_step(tmp_path, {"system": "exports/levels.yaml", "expect": expect}, workdir)
    assert got == code, err
    record = json.loads(Path(outputs["json"]).read_text())
    assert outputs["verdict"] == record["verdict"] == name.upper()
    assert float(outputs["beta_min"]) == record["beta_min"] and float(outputs["slope"]) == record["slope"]
    assert record["exit_code"] == code
    commands = [line for line in err.splitlines() if line.startswith("::")]
    assert len(commands) == 1 and commands[0].startswith("::notice " if name == "stable" else "::error "), err
    assert "file=exports/levels.yaml," in commands[0]
    assert f"— {name.upper()}" in files["summary"].read_text()


def test_action_norm_override_scales_beta_by_h_to_the_minus_half(systems, tmp_path):
    """norm: h-L2 makes G = h·G, so each β_h becomes β_h / √h (the pencil's eigenvalues / h):
    the override must give exactly that, and leave the user's directory as it was. The export is
    a ``norm: H`` manifest whose G is the L² mass: its β in G is the row's ``beta_L2``."""
    workdir = systems["stable"].parent.parent
    before = sorted(p.name for p in systems["stable"].parent.iterdir())
    got, err, outputs, _ = run_action_step(tmp_path, {"system": "exports/levels.yaml", "norm": "h-L2"}, workdir)
    assert got == 0, err
    record = json.loads(Path(outputs["json"]).read_text())
    assert record["norm"] == "h-L2" and record["system"] == load_manifest(systems["stable"]).name
    _, plain, _ = run_in_process(["verdict", "--system", str(systems["stable"]), "--format", "json"])
    given = json.loads(plain)["levels"]
    for lv, ref in zip(record["levels"], given):
        assert abs(lv["beta"] - ref["beta_L2"] / ref["h"] ** 0.5) <= 1e-12 * lv["beta"]
    assert float(outputs["beta_min"]) == min(lv["beta"] for lv in record["levels"])
    assert sorted(p.name for p in systems["stable"].parent.iterdir()) == before  # the copy removed


@pytest.mark.parametrize("inputs, needle", [({"norm": "H1"}, "norm"), ({"expect": "maybe"}, "--expect"),
                                            ({"system": "exports/none.yaml"}, "none.yaml")])
def test_action_bad_input_is_exit_2_one_line_no_outputs(systems, tmp_path, inputs, needle):
    workdir = systems["stable"].parent.parent
    got, err, outputs, _ = run_action_step(tmp_path, {"system": "exports/levels.yaml", **inputs}, workdir)
    assert got == 2 and outputs == {}
    lines = err.splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in err, err


# ---------------------------------------------------------------- .pre-commit-hooks.yaml
def hook() -> dict:
    assert isinstance(HOOKS, list) and len(HOOKS) == 1
    assert HOOKS[0]["id"] == "infsup-contact-verdict" and HOOKS[0]["language"] == "python"
    return HOOKS[0]


@pytest.mark.parametrize("path, matches", [
    ("levels.yaml", True), ("exports/levels.yaml", True), ("a/b/kratos.levels.yaml", True),
    ("x.levels.yml", True), ("mylevels.yaml", False), ("levels.yaml.bak", False), ("levels.json", False),
    ("levels/other.yaml", False)])
def test_hook_files_pattern(path, matches):
    assert bool(re.search(hook()["files"], path)) is matches


def test_hook_entry_is_an_installed_console_script():
    entry = shlex.split(hook()["entry"])
    pyproject = (ROOT / "pyproject.toml").read_text()
    assert re.search(rf"^{re.escape(entry[0])}\s*=", pyproject, flags=re.M), entry[0]


def with_expect(manifest: Path, value: str) -> Path:
    target = manifest.parent / f"{value}.levels.yaml"
    target.write_text(manifest.read_text() + f"expect: {value}\n")
    return target


def run_hook(*paths):
    entry = shlex.split(hook()["entry"])
    assert entry[0] == "infsup-contact"
    return run_in_process([*entry[1:], *map(str, paths)])


def test_hook_passes_manifests_meeting_their_expectation(systems):
    code, out, err = run_hook(systems["stable"], with_expect(systems["unstable"], "unstable"))
    assert code == 0, out + err
    lines = out.splitlines()
    assert len(lines) == 2 and all("as expected" in line for line in lines)


def test_hook_fails_an_unstable_manifest_without_expect(systems):
    code, out, _ = run_hook(systems["stable"], systems["unstable"])
    assert code == 1
    first, second = out.splitlines()
    assert "STABLE (as expected)" in first and "UNSTABLE (expected STABLE)" in second
    assert "kernel" in second  # the evidence says why


def test_hook_checks_every_manifest_and_reports_the_refused_one(systems, tmp_path):
    bad = tmp_path / "levels.yaml"
    bad.write_text("levels: [{h: 0.5, A: A.mtx, B: B.mtx, G: G.mtx}]\nexpect: stable\n")
    code, out, err = run_hook(bad, with_expect(systems["stable"], "unstable"), systems["stable"])
    assert code == 2
    assert len(out.splitlines()) == 2 and "expected UNSTABLE" in out.splitlines()[0]
    lines = err.splitlines()
    assert len(lines) == 1 and str(bad) in lines[0] and "at least 3" in lines[0]


def test_action_inputs_with_shell_metacharacters_stay_data(systems, tmp_path):
    """A manifest path holding quotes, `$(...)` and spaces is a path, never a command."""
    import shutil

    evil = "ex ports'\"$(touch pwned);`touch pwned2`"
    workdir = tmp_path / "work"
    shutil.copytree(systems["stable"].parent, workdir / evil)
    got, err, outputs, _ = run_action_step(tmp_path, {"system": f"{evil}/levels.yaml", "norm": "h-L2"}, workdir)
    assert got == 0, err
    assert outputs["verdict"] == json.loads(Path(outputs["json"]).read_text())["verdict"]
    assert not list(workdir.rglob("pwned*")) and not list(tmp_path.rglob("pwned*"))
    assert sorted(p.name for p in (workdir / evil).iterdir()) == sorted(p.name for p in systems["stable"].parent.iterdir())


def test_hook_bad_criterion_is_one_line_before_any_manifest(systems):
    code, out, err = run_hook("--slope-tolerance", "0.5", systems["stable"], systems["unstable"])
    assert code == 2 and out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and "--slope-tolerance" in lines[0] and "0.5" in lines[0], err
