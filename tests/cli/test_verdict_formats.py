"""``verdict --format csv|json|junit``, ``--output``, the GitHub annotations and step summary,
the manifest's ``expect:`` key and the exit-code table — on systems exported by ``export``
(T3 and R5.4 with k = 1: STABLE on N = 8 16 32, INCONCLUSIVE on 4 8 16, UNSTABLE with its
kernel) and on the ``--case`` and ``--space`` forms."""
from __future__ import annotations

import errno
import io
import json
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from urllib.parse import unquote

import pandas as pd
import pytest
from helpers.cli import run_in_process

from infsup_contact.cli import github, verdict_formats
from infsup_contact.cli.verdict_formats import EXIT_CODES, VerdictResult, render_json, render_junit
from infsup_contact.systems.manifest import load_manifest

ROOT = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
CSV_ROUNDING = 5e-6
"""Relative error of a number printed with %.6g (half a unit in the 6th digit)."""
SYSTEMS = {"stable": ("T3", "8 16 32"), "inconclusive": ("T3", "4 8 16"), "unstable": ("R5.4", "4 8 16")}


@pytest.fixture(scope="module")
def systems(tmp_path_factory):
    """name → manifest path of ``export --case ID --k 1 --N ...`` (module docstring)."""
    out = {}
    for name, (case, ns) in SYSTEMS.items():
        target = tmp_path_factory.mktemp(name) / "sys"
        code, _, err = run_in_process(["export", "--case", case, "--k", "1", "--N", *ns.split(), "--out", str(target)])
        assert code == 0, err
        out[name] = target / "levels.yaml"
    return out


@pytest.fixture(autouse=True)
def no_github(monkeypatch):
    """Tests run outside GitHub Actions unless they say otherwise (CI itself sets these)."""
    for var in ("GITHUB_ACTIONS", "GITHUB_STEP_SUMMARY", "GITHUB_WORKSPACE"):
        monkeypatch.delenv(var, raising=False)


def verdict(*args):
    return run_in_process(["verdict", *map(str, args)])


def one_line(err: str, *needles) -> str:
    lines = err.splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


def strict_json(text: str):
    """json.loads refusing NaN/Infinity tokens (Python's json accepts them by default)."""
    def refuse(token):
        raise AssertionError(f"non-standard JSON token {token}")
    return json.loads(text, parse_constant=refuse)


# ---------------------------------------------------------------- CSV, unchanged
def test_csv_is_the_default_and_the_case_header_is_the_documented_one():
    args = ["--case", "R5.4", "--k", "1", "--N", "4", "8", "16"]
    code, default, _ = verdict(*args)
    code_csv, explicit, _ = verdict(*args, "--format", "csv")
    assert code == code_csv == 0
    strip = [re.sub(r",[^,]*\n$", "\n", text) for text in (default, explicit)]  # `seconds` differs
    assert strip[0] == strip[1]
    readme = (ROOT / "docs" / "cli.md").read_text()
    documented = re.search(r"`(space,k,model,element,family,norm,multiplier_mesh,N1_offset,verdict,[^`]*)`", readme).group(1)
    assert default.splitlines()[0] == documented
    assert pd.read_csv(io.StringIO(default), dtype={"N_list": str}).N_list[0] == "4 8 16"


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_json_and_csv_carry_the_same_numbers(systems, name):
    _, csv_text, _ = verdict("--system", systems[name])
    _, json_text, _ = verdict("--system", systems[name], "--format", "json")
    row, record = pd.read_csv(io.StringIO(csv_text)).iloc[0], strict_json(json_text)
    for col in ("beta_min", "beta_max", "slope", "slope_lo", "slope_hi", "max_residual"):
        assert abs(row[col] - record[col]) <= CSV_ROUNDING * abs(record[col]) + 1e-300, col
    for col in ("verdict", "evidence", "system", "norm", "kernel_dim"):
        assert row[col] == record[col], col


# ---------------------------------------------------------------- JSON
def test_json_numbers_lists_levels_and_exit_code(systems):
    manifest = load_manifest(systems["stable"])
    code, out, err = verdict("--system", systems["stable"], "--format", "json", "--expect", "stable")
    record = strict_json(out)
    assert code == record["exit_code"] == 0 and record["verdict"] == "STABLE", err
    assert record["form"] == "system" and record["expect"] == "STABLE"
    assert record["schema"] == verdict_formats.SCHEMA
    assert isinstance(record["kernel_dim"], int) and isinstance(record["beta_min"], float)
    assert record["h_list"] == [lv.h for lv in manifest.levels]  # exact: from the levels, not from %g text
    assert record["routes"] == ["gamma-dense"]
    assert len(record["levels"]) == len(manifest.levels)
    assert [lv["h"] for lv in record["levels"]] == record["h_list"]
    assert min(lv["beta"] for lv in record["levels"]) == record["beta_min"]
    assert record["criterion"] == {"slope_tolerance": 0.15, "beta_floor": 0.001, "confidence": 0.95}


def test_json_of_the_case_form_has_n_list_as_integers():
    code, out, _ = verdict("--case", "R5.4", "--k", "1", "--N", "4", "8", "16", "--format", "json",
                           "--expect", "unstable")
    record = strict_json(out)
    assert code == record["exit_code"] == 0
    assert record["form"] == "case" and record["space"] == "R5.4" and record["N_list"] == [4, 8, 16]
    assert record["verdict"] == "UNSTABLE" and record["kernel_dim"] >= 1 and "levels" not in record


def test_json_nan_and_inf_are_null():
    row = dict(space="X", verdict="UNSTABLE", beta_min=0.0, beta_max=float("inf"), slope=float("nan"),
               slope_lo=float("-inf"), slope_hi=float("nan"), evidence="e", kernel_dim=1, N_list=(4, 8, 16))
    record = strict_json(render_json(VerdictResult("case", row, None, {})))
    assert record["beta_max"] is record["slope"] is record["slope_lo"] is record["slope_hi"] is None
    assert record["beta_min"] == 0.0 and record["N_list"] == [4, 8, 16]


# ---------------------------------------------------------------- JUnit
def junit_counts_consistent(root) -> dict:
    """The structure JUnit consumers read: one <testsuite>, its counts equal to its children."""
    assert root.tag == "testsuite"
    cases = root.findall("testcase")
    counts = {key: sum(len(c.findall(key)) for c in cases) for key in ("failure", "error", "skipped")}
    assert int(root.get("tests")) == len(cases) == 1
    assert int(root.get("failures")) == counts["failure"]
    assert int(root.get("errors")) == counts["error"] == 0
    assert int(root.get("skipped")) == counts["skipped"]
    assert float(root.get("time")) >= 0 and root.get("timestamp") and root.get("name")
    case = cases[0]
    assert case.get("classname") == "infsup-contact" and case.get("name")
    assert counts["failure"] + counts["skipped"] <= 1
    return counts


@pytest.mark.parametrize("name, expect, code, outcome", [
    ("stable", "stable", 0, "pass"), ("unstable", "stable", 1, "failure"), ("unstable", None, 0, "pass"),
    ("inconclusive", None, 0, "skipped"), ("inconclusive", "stable", 1, "failure")])
def test_junit_is_one_suite_with_a_failure_exactly_when_the_exit_code_is_1(systems, name, expect, code, outcome):
    extra = [] if expect is None else ["--expect", expect]
    got, out, err = verdict("--system", systems[name], "--format", "junit", *extra)
    assert got == code, err
    root = ET.fromstring(out)
    counts = junit_counts_consistent(root)
    assert outcome == ("failure" if counts["failure"] else "skipped" if counts["skipped"] else "pass")
    case = root.find("testcase")
    assert case.get("name") == load_manifest(systems[name]).name
    props = {p.get("name"): p.get("value") for p in root.find("properties")}
    _, json_text, _ = verdict("--system", systems[name], "--format", "json")
    record = strict_json(json_text)
    for key in ("beta_min", "slope", "slope_lo", "slope_hi"):  # full precision (repr) both ways
        assert float(props[key]) == record[key], key
    assert props["verdict"] == record["verdict"] and props["confidence"] == "0.95"
    if outcome == "failure":
        assert record["evidence"] in case.find("failure").get("message")
    if outcome == "skipped":
        assert record["evidence"] in case.find("skipped").get("message")


def test_junit_of_the_space_form(tmp_path):
    code, out, err = verdict("--space", ROOT / "examples" / "macro_p0.py:space", "--k", "1", "--N", "8", "16", "32",
                             "--format", "junit", "--expect", "stable")
    root = ET.fromstring(out)
    assert code == 0 and junit_counts_consistent(root)["failure"] == 0, err
    assert root.find("testcase").get("name") == "P0-2h"


def test_junit_escapes_markup_and_drops_characters_xml_cannot_hold():
    evil = 'a<b>&"c" ]]> \x1b[31m\x00'
    row = dict(system=evil, verdict="INCONCLUSIVE", beta_min=1.0, beta_max=1.0, slope=0.0, slope_lo=-1.0,
               slope_hi=1.0, evidence=evil, kernel_dim=0, seconds=0.5)
    root = ET.fromstring(render_junit(VerdictResult("system", row, "STABLE", {"confidence": 0.95})))
    junit_counts_consistent(root)
    clean = evil.replace("\x1b", "\ufffd").replace("\x00", "\ufffd")
    assert root.find("testcase").get("name") == clean
    assert root.find("testcase/failure").get("message") == f"INCONCLUSIVE, expected STABLE: {clean}"


# ---------------------------------------------------------------- --output
@pytest.mark.parametrize("fmt", verdict_formats.FORMATS)
def test_output_writes_the_file_and_nothing_on_stdout(systems, tmp_path, fmt):
    target = tmp_path / "deep" / f"verdict.{fmt}"
    code, out, err = verdict("--system", systems["unstable"], "--format", fmt, "--output", target,
                             "--expect", "stable")
    assert code == 1 and out == "", err
    text = target.read_text(encoding="utf-8")
    parsed = {"csv": lambda t: pd.read_csv(io.StringIO(t)).verdict[0], "json": lambda t: strict_json(t)["verdict"],
              "junit": lambda t: [p.get("value") for p in ET.fromstring(t).find("properties")
                                  if p.get("name") == "verdict"][0]}[fmt](text)
    assert parsed == "UNSTABLE"
    assert sorted(p.name for p in target.parent.iterdir()) == [target.name]  # no temporary file left


@pytest.mark.parametrize("where", ["directory", "under-a-file", "empty"])
def test_bad_output_is_refused_before_computing(systems, tmp_path, where):
    (tmp_path / "afile").write_text("x")
    target = {"directory": tmp_path, "under-a-file": tmp_path / "afile" / "v.json", "empty": ""}[where]
    code, out, err = verdict("--system", systems["stable"], "--output", target)
    assert code == 2 and out == ""
    one_line(err, "--output")


def test_output_failing_at_the_end_is_exit_74(systems, tmp_path, monkeypatch):
    def full(path, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr("infsup_contact.io.write_bytes_atomic", full)
    code, out, err = verdict("--system", systems["stable"], "--output", tmp_path / "v.json")
    assert code == 74 and out == ""
    one_line(err, "cannot write the result", "No space left on device")


# ---------------------------------------------------------------- GitHub
@pytest.mark.parametrize("text", ["plain", "50% of a:b,c", "line\nbreak\r\n", "%0A already", "::error::x", ""])
def test_workflow_command_escapes_invert_to_the_text(text):
    for escape in (github.escape_data, github.escape_property):
        escaped = escape(text)
        assert "\n" not in escaped and "\r" not in escaped
        assert unquote(escaped) == text  # the runner's unescaping (percent-decoding) restores it
    assert ":" not in github.escape_property(text) and "," not in github.escape_property(text)


@pytest.mark.parametrize("name, expect, level", [
    ("stable", None, "notice"), ("stable", "stable", "notice"), ("unstable", None, "error"),
    ("unstable", "unstable", "notice"), ("unstable", "stable", "error"), ("inconclusive", None, "warning"),
    ("inconclusive", "stable", "error")])
def test_annotation_on_stderr_keeps_stdout_clean(systems, monkeypatch, tmp_path, name, expect, level):
    monkeypatch.setenv("GITHUB_ACTIONS", "true")
    monkeypatch.setenv("GITHUB_WORKSPACE", str(systems[name].parent.parent))
    extra = [] if expect is None else ["--expect", expect]
    code, out, err = verdict("--system", systems[name], "--format", "json", *extra)
    record = strict_json(out)  # stdout is the JSON alone
    commands = [line for line in err.splitlines() if line.startswith("::")]
    assert len(commands) == 1, err
    match = re.fullmatch(r"::(\w+) file=([^,:]*),title=([^,:]*)::(.*)", commands[0])
    assert match and match.group(1) == level, commands[0]
    assert unquote(match.group(2)) == "sys/levels.yaml"  # relative to the workspace
    assert unquote(match.group(3)) == f"infsup-contact verdict: {record['system']}"
    assert record["evidence"] in unquote(match.group(4))
    assert code == record["exit_code"]


def test_no_annotation_outside_github(systems):
    _, _, err = verdict("--system", systems["unstable"])
    assert "::" not in err


def test_step_summary_is_appended_with_the_level_table(systems, monkeypatch, tmp_path):
    summary = tmp_path / "summary.md"
    summary.write_text("earlier step\n")
    monkeypatch.setenv("GITHUB_STEP_SUMMARY", str(summary))
    for name in ("stable", "unstable"):
        verdict("--system", systems[name])
    text = summary.read_text(encoding="utf-8")
    assert text.startswith("earlier step\n")
    assert text.count("### ") == 2 and "— STABLE" in text and "— UNSTABLE" in text
    levels = len(load_manifest(systems["stable"]).levels) + len(load_manifest(systems["unstable"]).levels)
    assert len(re.findall(r"^\| \d+ \| 0\.\d+ \|", text, flags=re.M)) == levels  # one table row per level


def test_unwritable_step_summary_is_a_note_not_a_failure(systems, monkeypatch, tmp_path):
    monkeypatch.setenv("GITHUB_STEP_SUMMARY", str(tmp_path))  # a directory: open() fails
    code, out, err = verdict("--system", systems["stable"], "--expect", "stable")
    assert code == 0 and "STABLE" in out
    one_line(err, "GITHUB_STEP_SUMMARY", "not written")


# ---------------------------------------------------------------- the manifest's expect:
def with_expect(manifest: Path, value) -> Path:
    text = manifest.read_text() + f"expect: {value}\n"
    target = manifest.parent / f"expect-{value}.levels.yaml"
    target.write_text(text)
    return target


def test_manifest_expect_sets_the_exit_code_and_expect_overrides_it(systems):
    unstable = with_expect(systems["unstable"], "unstable")
    assert verdict("--system", unstable)[0] == 0
    assert verdict("--system", with_expect(systems["unstable"], "stable"))[0] == 1
    code, out, _ = verdict("--system", unstable, "--expect", "stable", "--format", "json")
    assert code == 1 and strict_json(out)["expect"] == "STABLE"


@pytest.mark.parametrize("value", ["maybe", "[stable]", "1", "STABLE"])
def test_bad_manifest_expect_is_one_line(systems, value):
    code, out, err = verdict("--system", with_expect(systems["stable"], value))
    assert code == 2 and out == ""
    one_line(err, "expect", "stable, unstable")


# ---------------------------------------------------------------- the exit codes, one table
def test_each_documented_exit_code_is_produced_by_its_case(systems, tmp_path, monkeypatch):
    produced = {0: verdict("--system", systems["stable"], "--expect", "stable")[0],
                1: verdict("--system", systems["stable"], "--expect", "unstable")[0],
                2: verdict("--system", tmp_path / "missing.yaml")[0]}
    with open("/dev/full", "w") as full:  # 74: stdout full
        produced[74] = subprocess.run([sys.executable, "-m", "infsup_contact", "verdict", "--system",
                                       str(systems["stable"])], stdout=full, stderr=subprocess.PIPE, env=ENV,
                                      cwd=ROOT, timeout=120).returncode
    with monkeypatch.context() as m:  # 2 again: the memory gate, nothing computed
        m.setattr("infsup_contact.resources.available_bytes", lambda: 1024)
        code, _, err = verdict("--system", systems["stable"])
        assert code == 2 and "available" in one_line(err)

    def ctrl_c(*args, **kwargs):
        raise KeyboardInterrupt

    with monkeypatch.context() as m:  # 130: Ctrl-C during the computation
        m.setattr("infsup_contact.systems.levels.system_verdict", ctrl_c)
        produced[130], out, err = verdict("--system", systems["stable"])
        assert out == "" and "interrupted" in one_line(err)

    def bug(*args, **kwargs):
        raise ZeroDivisionError("float division by zero")

    with monkeypatch.context() as m:  # 70: an unexpected exception, never 1
        m.setattr("infsup_contact.systems.levels.system_verdict", bug)
        produced[70], out, err = verdict("--system", systems["stable"], "--expect", "stable")
        assert out == "" and "ZeroDivisionError" in one_line(err)
    assert produced == {code: code for code, _ in EXIT_CODES}


def test_exit_code_table_is_in_help_and_readme():
    code, out, _ = run_in_process(["verdict", "--help"])
    assert code == 0
    epilog = out[out.index("exit codes:"):]
    readme = (ROOT / "docs" / "cli.md").read_text()
    section = readme[readme.index("## Exit codes"):]
    end = section.find("\n## ", 5)  # the next section, if any
    section = section if end < 0 else section[:end]
    for code, text in EXIT_CODES:
        assert re.search(rf"^\s+{code}\s+{re.escape(text.split()[0])}", epilog, flags=re.M), code
        assert re.search(rf"^\| {code} \| ", section, flags=re.M), f"docs/cli.md table lacks exit code {code}"


@pytest.mark.parametrize("which", ["manifest", "matrix"])
def test_output_onto_an_input_is_refused(systems, which):
    manifest = systems["stable"]
    target = manifest if which == "manifest" else load_manifest(manifest).levels[0].B
    before = target.read_bytes()
    code, out, err = verdict("--system", manifest, "--format", "json", "--output", target)
    assert code == 2 and out == ""
    one_line(err, "--output", "other than the inputs")
    assert target.read_bytes() == before


def test_unknown_format_is_one_line(systems):
    code, out, err = verdict("--system", systems["stable"], "--format", "xml")
    assert code == 2 and out == ""
    one_line(err, "--format", "xml")


def test_output_to_a_device_writes_through_it_and_leaves_the_node(systems):
    """``--output /dev/stdout`` (a common idiom) and ``--output -``: the result on stdout, and
    the device node not replaced by a renamed temporary file (we may run as root)."""
    for target in ("/dev/stdout", "-"):
        proc = subprocess.run([sys.executable, "-m", "infsup_contact", "verdict", "--system", str(systems["stable"]),
                               "--format", "json", "--output", target], capture_output=True, text=True, env=ENV,
                              cwd=ROOT, timeout=120)
        assert proc.returncode == 0, proc.stderr
        assert strict_json(proc.stdout)["verdict"] == "STABLE"
    assert os.path.islink("/dev/stdout") or not os.path.isfile("/dev/stdout")
