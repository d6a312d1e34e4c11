"""Every bad input, systematically (issue 17): a table of mutations generated from
config/config.yaml and from the command line's own argparse parsers, so that a new key or
flag is covered without editing this file.

For each mutation the property is: either the input is accepted (the config passes every
check and its jobs can be enumerated with their memory estimates; the command line's
validation passes, ``--dry-run`` prints the estimate and exits 0), or it is refused with ONE
line naming the key/flag — ``config key <key>: …`` (exit 1 in the workflow, before any job:
tests/workflow/test_workflow_config.py runs the real ``snakemake -n`` on representatives) or
``infsup-contact: error: …`` with exit code 2 — and never a traceback. Nothing is computed:
the config checks are pure functions and every command runs with ``--dry-run`` (which stops
after the same validation a real run performs first), so the whole file takes seconds.
The counts (tried / refused / accepted) are printed.
"""
from __future__ import annotations

import argparse
import contextlib
import copy
import io
import math
import os
import re
import time
from pathlib import Path

import pytest
import yaml

from helpers.cli import run_in_process

from infsup_contact import cli, resources
from infsup_contact.config.checks import (CROSS_KEY_RULES, REFERENCE_MARGIN, ConfigError, check_config,
                                          key_path, scene_meshes)
from infsup_contact.config.memory import check_job_memory, memory_notes

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
FULL_CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
MISSING = object()
MEM_TOTAL = resources.total_bytes() or 16e9
LOG = os.environ.get("INFSUP_MUTATION_LOG")
"""If set, a file that receives one line per mutation: outcome, input, message."""


def log(*parts) -> None:
    if LOG:
        with open(LOG, "a") as fh:
            fh.write(" | ".join(str(p) for p in parts) + "\n")


@pytest.fixture(autouse=True)
def _at_root_registry_as_found(monkeypatch):
    """Run from the repository (user spaces resolve from it); leave the registry as found."""
    from infsup_contact.discretization.spaces import user_spaces
    from infsup_contact.discretization.spaces.registry import SPACES

    monkeypatch.chdir(ROOT)
    before = set(SPACES)
    yield
    user_spaces.forget_since(before)


# ================================================================= config mutations

def key_paths(node, path=()):
    """Every key of the config (the first element of a list stands for all of them)."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield (*path, key)
            yield from key_paths(value, (*path, key))
    elif isinstance(node, list) and node:
        yield (*path, 0)
        yield from key_paths(node[0], (*path, 0))


def bad_values(value, in_dict: bool):
    """(label, replacement) for one value: missing, empty, wrong type, out of range, non-finite."""
    out = [("missing", MISSING)] if in_dict else []
    out += [("null", None)]
    if isinstance(value, bool):
        out += [("string", "x"), ("number", 2)]
    elif isinstance(value, int):
        out += [("negative", -1), ("zero", 0), ("huge", 10 ** 9), ("non-integer", 2.5), ("whole float", float(value)),
                ("bool", True), ("nan", math.nan), ("inf", math.inf), ("string", "x"), ("empty", "")]
    elif isinstance(value, float):
        out += [("negative", -1.0), ("zero", 0.0), ("huge", 1e300), ("tiny", 1e-300), ("nan", math.nan),
                ("inf", math.inf), ("-inf", -math.inf), ("string", "x"), ("empty", ""), ("bool", False)]
    elif isinstance(value, str):
        out += [("empty", ""), ("unknown", "bogus"), ("number", 7), ("list", [value])]
    elif isinstance(value, list):
        out += [("empty", []), ("string", "x"), ("scalar", 4), ("nested", [value])]
        if value:
            out += [("duplicate", [value[0], *value])]
    elif isinstance(value, dict):
        out += [("empty", {}), ("string", "x"), ("list", [1])]
        if value:
            first = next(iter(value.values()))
            out += [("unknown key", {**value, "bogus": copy.deepcopy(first)})]
    return out


def mutated(cfg, path, new):
    cfg = copy.deepcopy(cfg)
    node = cfg
    for part in path[:-1]:
        node = node[part]
    if new is MISSING:
        del node[path[-1]]
    else:
        node[path[-1]] = new
    return cfg


def cross_key_mutations(cfg):
    """(label, mutated path, config) breaking each cross-key rule on purpose."""
    cc = cfg["contact"]
    membranes = next(name for name, s in cc["scenes"].items() if s["kind"] == "membranes")
    finest = max(scene_meshes(cfg)[membranes])
    shortest = min(len(ns) for ns in scene_meshes(cfg).values())
    n = cfg["infsup"]["N"][0]
    return [
        ("reference_N = 1x the finest membranes mesh", ("contact", "reference_N"),
         mutated(cfg, ("contact", "reference_N"), finest)),
        ("reference_N = 8 (the issue)", ("contact", "reference_N"), mutated(cfg, ("contact", "reference_N"), 8)),
        ("reference_N exactly the margin", ("contact", "reference_N"),
         mutated(cfg, ("contact", "reference_N"), REFERENCE_MARGIN * finest)),
        ("finer membranes scene than the reference", ("contact", "scenes", membranes, "N"),
         mutated(cfg, ("contact", "scenes", membranes, "N"), [4, 8, cc["reference_N"]])),
        ("rate_window one more than the meshes", ("contact", "rate_window"),
         mutated(cfg, ("contact", "rate_window"), shortest + 1)),
        ("rate_window = 9 (the issue)", ("contact", "rate_window"), mutated(cfg, ("contact", "rate_window"), 9)),
        ("rate_window = the meshes", ("contact", "rate_window"), mutated(cfg, ("contact", "rate_window"), shortest)),
        ("matching pair among non-matching", ("infsup", "nonmatching", 0),
         mutated(cfg, ("infsup", "nonmatching", 0), [n, n])),
        ("membranes scene with p", ("contact", "scenes", membranes, "p"),
         mutated(cfg, ("contact", "scenes", membranes, "p"), 3.0)),
        ("speed_accuracy_scene not a scene", ("benchmarks", "speed_accuracy_scene"),
         mutated(cfg, ("benchmarks", "speed_accuracy_scene"), "bogus")),
        ("speed_accuracy_scene a scene kind", ("benchmarks", "speed_accuracy_scene"),
         mutated(cfg, ("benchmarks", "speed_accuracy_scene"), "membranes")),
        ("T4 with k = 1", ("infsup", "cases", "T4"), mutated(cfg, ("infsup", "cases", "T4"), [1, 2])),
        ("T5 with k = 1 (contact)", ("contact", "cases", "T5"), mutated(cfg, ("contact", "cases", "T5"), [1])),
        ("unknown case id", ("contact", "cases", "T9"), mutated(cfg, ("contact", "cases", "T9"), [1])),
        ("user space not listed", ("spaces",), mutated(cfg, ("spaces",), [])),
        ("fit_window longer than every β series (logged shrink)", ("claims", "fit_window"),
         mutated(cfg, ("claims", "fit_window"), 50)),
        ("seed = -1 (the issue)", ("infsup", "seed"), mutated(cfg, ("infsup", "seed"), -1)),
    ]


def _related(a: str, b: str) -> bool:
    """a and b are the same key, or one contains the other."""
    return a == b or not a or not b or any(x.startswith(y + sep) for x, y in ((a, b), (b, a)) for sep in ".[")


def names_the_key(err_key: str, path) -> bool:
    """The error names the mutated key (itself, a parent or a child), or a key of a cross-key
    rule that relates it to the mutated key."""
    mut = key_path(path) if path else ""
    if _related(err_key, mut):
        return True
    return any(any(_related(err_key, k) for k in keys) and any(_related(mut, k) for k in keys)
               for keys in CROSS_KEY_RULES.values())


def config_outcome(cfg):
    """('refused', message, key) or ('accepted', notes, None); anything else escapes (a bug)."""
    try:
        _, notes = check_config(cfg, SCHEMA)
        check_job_memory(cfg, MEM_TOTAL)  # what common.smk adds for a local run
    except ConfigError as err:
        return "refused", str(err), err.key
    return "accepted", notes + memory_notes(cfg, MEM_TOTAL), None


def test_base_configs_are_valid():
    for name in ("config.yaml", "ci.yaml"):
        status, notes, _ = config_outcome(yaml.safe_load((ROOT / "config" / name).read_text()))
        assert status == "accepted", notes


@pytest.mark.slow_first  # one of the longest tests: started first under xdist (tests/conftest.py)
def test_every_config_key_mutated(capsys):
    t0 = time.perf_counter()
    tried, refused, accepted, failures, covered = 0, 0, 0, [], set()
    cases = []
    for path in key_paths(FULL_CONFIG):
        parent = FULL_CONFIG
        for part in path[:-1]:
            parent = parent[part]
        for label, new in bad_values(parent[path[-1]], isinstance(parent, dict)):
            cases.append((f"{key_path(path)} {label}", path, mutated(FULL_CONFIG, path, new)))
    cases += [(f"{label}", path, cfg) for label, path, cfg in cross_key_mutations(FULL_CONFIG)]
    cases += [("top level unknown key", (), {**copy.deepcopy(FULL_CONFIG), "bogus": 1}),
              ("top level not a mapping", (), ["x"])]
    for label, path, cfg in cases:
        tried += 1
        covered.add(key_path(path) if path else "")
        try:
            status, detail, key = config_outcome(cfg)
        except Exception as exc:  # noqa: BLE001 - the property under test: no other exception
            failures.append(f"{label}: {type(exc).__name__}: {exc}")
            continue
        log("config", status, label, detail)
        if status == "accepted":
            accepted += 1
            continue
        refused += 1
        if "\n" in detail or not detail.startswith("config key ") or "Traceback" in detail:
            failures.append(f"{label}: not one 'config key' line: {detail!r}")
        elif not names_the_key(key, path):
            failures.append(f"{label}: names {key!r}, not the mutated key: {detail}")
    every_key = {key_path(p) for p in key_paths(FULL_CONFIG)}
    assert every_key <= covered, f"keys never mutated: {sorted(every_key - covered)}"
    with capsys.disabled():
        print(f"\nconfig mutations (config/config.yaml, {len(every_key)} keys): tried {tried}, "
              f"refused {refused}, accepted {accepted}, {time.perf_counter() - t0:.1f} s")
    assert not failures, "\n".join(failures)


def test_cross_key_rules_refuse_and_accept_as_documented():
    outcome = {label: config_outcome(cfg) for label, _, cfg in cross_key_mutations(FULL_CONFIG)}
    accepted = {"reference_N exactly the margin", "rate_window = the meshes", "speed_accuracy_scene a scene kind",
                "fit_window longer than every β series (logged shrink)"}
    for label, (status, detail, key) in outcome.items():
        assert status == ("accepted" if label in accepted else "refused"), (label, detail)
    notes = outcome["fit_window longer than every β series (logged shrink)"][1]
    assert notes and all("claims.fit_window" in n and ("shrunk explicitly" in n or "skipped" in n) for n in notes)
    assert "contact.reference_N" in outcome["reference_N = 8 (the issue)"][1]
    assert "allowed reference_N >= 64" in outcome["reference_N = 8 (the issue)"][1]
    assert "got 9; allowed 2..4" in outcome["rate_window = 9 (the issue)"][1]
    assert outcome["seed = -1 (the issue)"][2] == "infsup.seed"


# ================================================================= command-line mutations

RATES_TABLE = ("scene,case,k,family,N1,N2,energy_error,l2_error,lambda_l2_error,lambda_hm12_error\n"
               + "".join(f"manufactured,T3,1,structured,{n},{n},{1 / n},{1 / n ** 2},{1 / n},{1 / n}\n"
                         for n in (4, 8, 16)))


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    d = tmp_path_factory.mktemp("tables")
    files = {"good": RATES_TABLE, "empty": "", "header-only": RATES_TABLE.splitlines()[0] + "\n",
             "wrong-columns": "a,b\n1,2\n", "no N1": RATES_TABLE.replace("N1,", "M1,", 1),
             "non-numeric N2": RATES_TABLE.replace(",16,16,", ",16,sixteen,"),
             "non-matching only": RATES_TABLE.replace(",4,4,", ",4,8,").replace(",8,8,", ",8,4,").replace(",16,16,", ",16,8,")}
    paths = {}
    for name, text in files.items():
        paths[name] = d / f"{name.replace(' ', '_')}.csv"
        paths[name].write_text(text)
    paths["binary"] = d / "binary.csv"
    paths["binary"].write_bytes(b"\x00\xff\xfe\x00")
    paths["missing"] = d / "no_such_file.csv"
    paths["directory"] = d
    return paths


def _tiny_manifest(folder):
    """levels.yaml of three levels (A = 2I, B = [I 0], G = I; n = 2m): valid, never computed here."""
    import scipy.io
    import scipy.sparse as sp

    folder.mkdir(exist_ok=True)
    lines = ["levels:"]
    for i, m in enumerate((2, 4, 8)):
        mats = {"A": 2 * sp.identity(2 * m), "B": sp.hstack([sp.identity(m), sp.csr_matrix((m, m))]),
                "G": sp.identity(m)}
        for key, mat in mats.items():
            scipy.io.mmwrite(folder / f"{key}{i}.mtx", sp.coo_matrix(mat))
        lines.append(f"  - {{h: {1 / m}, A: A{i}.mtx, B: B{i}.mtx, G: G{i}.mtx}}")
    (folder / "levels.yaml").write_text("\n".join(lines) + "\n")
    return folder / "levels.yaml"


def base_commands(tables):
    return {
        "beta": ["beta", "--k", "1", "--N1", "4", "--N2", "4"],
        "contact": ["contact", "--scene", "manufactured", "--case", "T3", "--k", "1", "--N1", "4", "--N2", "4"],
        "rates": ["rates", str(tables["good"])],
        "bench": ["bench", "--what", "beta", "--N", "4", "--k", "1"],
        "verdict": ["verdict", "--case", "T3", "--k", "1"],
        "export": ["export", "--case", "T3", "--k", "1", "--N", "4", "--out", str(tables["good"].parent / "export")],
        "provenance": ["provenance"],
        # a valid manifest of three tiny levels (--dry-run checks it; the manifests' own faults:
        # tests/test_systems_*.py, tests/systems/test_gate_action.py)
        "verdict-hook": ["verdict-hook", str(_tiny_manifest(tables["good"].parent / "hook"))],
    }


ALTERNATIVES = {"--space": "--case", "--case": "--space", "--system": "--case"}
"""Flags that exclude each other: mutating one drops the other from the base command."""


def subcommands():
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


def flag_values(action):
    """Bad (and some good) values for one argparse action, as lists of command-line tokens."""
    if action.nargs == 0:  # store_true: given, or given a value
        return [("given", []), ("with a value", ["x"])]
    if action.choices is not None:
        return [("unknown", ["bogus"]), ("empty", [""]), ("valid", [str(list(action.choices)[0])])]
    if action.type is int:
        singles = ["-1", "0", "10000000", "2.5", "abc", "", "nan", "inf", "1e3"]
    elif action.type is float:
        singles = ["-1", "0", "1e300", "1e-300", "1e-200", "nan", "inf", "-inf", "abc", ""]
    elif action.dest == "space":
        singles = ["", "bogus", "examples/no_such_file.py:space", "examples/macro_p0.py",
                   "examples/macro_p0.py:nofunc", "examples/macro_p0.py:space"]
    else:
        singles = ["bogus", ""]
    out = [(repr(v), [v]) for v in singles]
    if action.nargs in ("+", "*"):
        out += [("none given", []), ("repeated", [singles[0], singles[0]] if action.type else ["osqp", "osqp"])]
        if action.type is int:
            out += [("repeated valid", ["4", "4", "8"]), ("valid list", ["4", "8", "16"])]
        if action.dest == "peers":
            out += [("none", ["none"]), ("one peer", ["osqp"])]
    return out




def cli_mutations(tables):
    """(command, flag, label, argv) for every flag and positional of every subcommand."""
    bases = base_commands(tables)
    out = []
    for command, parser in subcommands().items():
        base = bases[command]
        out.append((command, "--bogus-flag", "unknown flag", [*base, "--bogus-flag", "1"]))
        for action in parser._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            if not action.option_strings:  # positional: the table of `rates`
                for name, path in tables.items():
                    out.append((command, action.dest, name, [command, str(path), *base[2:]]))
                continue
            flag = max(action.option_strings, key=len)
            drop = ALTERNATIVES.get(flag)
            trimmed = list(base)
            for f in (flag, drop):
                while f in trimmed:  # drop the flag (and its value) from the base
                    i = trimmed.index(f)
                    del trimmed[i:i + 2]
            for label, values in flag_values(action):
                out.append((command, flag, label, [*trimmed, flag, *values]))
    return out


def flag_named(line: str, flag: str, label: str) -> bool:
    """The line names the flag (``--N1``, or argparse's ``argument --N1``), the file of the
    positional table, or — for an unknown flag or a value given to a switch — the stray token."""
    if flag == "table":
        return " table " in line or line.startswith("infsup-contact: error: table ")
    if label in ("unknown flag", "with a value"):
        return "unrecognized arguments" in line
    return re.search(rf"(?<![\w-]){re.escape(flag)}\b", line) is not None


REQUIRED_WITH = {"--gamma": ("--radius",)}
"""Flags whose values need another flag: ``--gamma arc`` (or ``cylinder``) alone is refused at the
edge, where Γ is resolved, naming the radius it needs."""


def test_every_cli_flag_mutated(tables, capsys):
    t0 = time.perf_counter()
    tried, refused, accepted, failures = 0, 0, 0, []
    covered = set()
    for command, flag, label, argv in cli_mutations(tables):
        tried += 1
        covered.add((command, flag))
        extra = ["--dry-run"] if command != "provenance" else []
        try:
            code, out, err = run_in_process([*argv, *extra])
        except Exception as exc:  # noqa: BLE001 - the property under test: no other exception
            failures.append(f"{' '.join(argv)}: {type(exc).__name__}: {exc}")
            continue
        lines = err.splitlines()
        log("cli", code, " ".join(argv), out.strip() if code == 0 else err.strip())
        if code == 0:
            accepted += 1
            if command != "provenance" and not out.startswith("dry run: valid request"):
                failures.append(f"{' '.join(argv)}: exit 0 without the dry-run line: {out!r}")
            continue
        refused += 1
        if code != 2 or len(lines) != 1 or out or "Traceback" in err:
            failures.append(f"{' '.join(argv)}: exit {code}, stdout {out[:80]!r}, stderr {err!r}")
        elif not lines[0].startswith("infsup-contact: error:") or not any(
                flag_named(lines[0], f, label) for f in (flag, *REQUIRED_WITH.get(flag, ()))):
            failures.append(f"{' '.join(argv)}: does not name {flag}: {lines[0]}")
    every_flag = {(c, max(a.option_strings, key=len) if a.option_strings else a.dest)
                  for c, p in subcommands().items() for a in p._actions if not isinstance(a, argparse._HelpAction)}
    assert every_flag <= covered, f"flags never mutated: {sorted(every_flag - covered)}"
    with capsys.disabled():
        print(f"\nCLI mutations ({len(subcommands())} subcommands, {len(every_flag)} flags): tried {tried}, "
              f"refused {refused}, accepted {accepted}, {time.perf_counter() - t0:.1f} s")
    assert not failures, "\n".join(failures)


@pytest.mark.parametrize("argv, flag", [
    (["beta", "--k", "2", "--N1", "100000", "--N2", "4"], "--N1"),       # the issue: 74.5 GiB traceback
    (["beta", "--k", "1", "--N1", "4", "--N2", "4", "--c1", "inf"], "--c1"),
    (["beta", "--k", "1", "--N1", "4", "--N2", "4", "--seed", "-1", "--family", "perturbed"], "--seed"),
    (["contact", "--scene", "membranes", "--case", "T3", "--k", "1", "--N1", "64", "--N2", "64"], "--n-ref"),
    (["verdict", "--case", "T3", "--k", "1", "--N", "8", "16", "100000"], "--N"),
    (["bench", "--what", "contact", "--N", "100000", "--k", "1"], "--N"),
])
def test_refused_without_dry_run_before_any_computation(argv, flag):
    """Without --dry-run too: the same validation refuses before anything is allocated."""
    t0 = time.perf_counter()
    code, out, err = run_in_process(argv)
    assert code == 2 and out == "" and len(err.splitlines()) == 1, (code, out, err)
    assert flag in err and "Traceback" not in err, err
    assert time.perf_counter() - t0 < 5, "validation must not compute"


def test_every_table_is_read_through_the_check():
    """The package, the CLI and every workflow script read tables through io.read_table (one
    line naming the file and the row); io.py itself is the only place that calls read_csv."""
    code = [*(ROOT / "src").rglob("*.py"), *(ROOT / "workflow" / "scripts").glob("*.py"),
            *(ROOT / "workflow").rglob("*.smk"), ROOT / "workflow" / "Snakefile"]
    plain = re.compile(r"read_csv\(|pd\.read_table\(|read_fwf\(|csv\.(reader|DictReader)\(|loadtxt\(|genfromtxt\(")
    # compare_results.py compares two results trees cell by cell *as text* (a schema's parsing
    # would hide a changed digit), so it reads CSV rows without io.read_table on purpose
    as_text = {"compare_results.py"}
    offenders = [str(p.relative_to(ROOT)) for p in sorted(code)
                 if p.name != "io.py" and p.name not in as_text and plain.search(p.read_text())]
    assert not offenders, f"read tables with io.read_table (via _glue.read_table): {offenders}"


# ------------------------------------------------------------------ issue 39, item 5.4: flags a request does not use
UNUSED = [  # (argv, flag, who uses it)
    (["contact", "--model", "elastic", "--scene", "patch", "--case", "T3", "--k", "2", "--N1", "5", "--N2", "4",
      "--p", "7"], "--p", "--scene manufactured"),
    (["contact", "--model", "elastic", "--scene", "patch", "--case", "T3", "--k", "2", "--N1", "5", "--N2", "4",
      "--q", "3"], "--q", "--scene manufactured"),                     # its default value, typed: still unused
    (["contact", "--model", "elastic", "--scene", "patch", "--case", "T3", "--k", "2", "--N1", "5", "--N2", "4",
      "--n-ref", "10"], "--n-ref", "--scene membranes"),
    (["contact", "--scene", "manufactured", "--case", "T3", "--k", "1", "--N1", "4", "--N2", "4", "--n-r", "64"],
     "--n-ref", "--scene membranes"),                                  # abbreviated
    (["contact", "--scene", "manufactured", "--case", "T3", "--k", "1", "--N1", "4", "--N2", "4", "--R", "1"],
     "--R", "--scene hertz"),
    (["beta", "--k", "1", "--N1", "4", "--N2", "4", "--alpha", "0.1"], "--alpha", "--family perturbed"),
    (["beta", "--k", "1", "--N1", "4", "--N2", "4", "--seed=3"], "--seed", "--family perturbed"),
    (["beta", "--model", "membranes3d", "--case", "T3", "--k", "1", "--N1", "2", "--N2", "2", "--alpha", "0.1"],
     "--alpha", "--family perturbed"),
    (["beta", "--model", "membranes3d", "--case", "T3", "--k", "1", "--N1", "2", "--N2", "2", "--h-route", "series"],
     "--h-route", "2D model"),
    (["beta", "--k", "1", "--N1", "4", "--N2", "4", "--norm", "L2", "--h-route", "series"], "--h-route", "--norm H"),
    (["beta", "--k", "1", "--N1", "4", "--N2", "4", "--nu", "0.3"], "--nu", "--model elastic"),
    (["export", "--case", "T3", "--k", "1", "--N", "4", "--out", "x", "--element", "hex"], "--element",
     "--model membranes3d"),
    (["verdict", "--case", "T3", "--k", "1", "--element", "hex"], "--element", "--model membranes3d"),
    (["bench", "--what", "beta", "--N", "4", "--k", "1", "--peers", "osqp"], "--peers", "--what contact"),
    (["bench", "--what", "beta", "--N", "4", "--k", "1", "--kkt-max-N", "64"], "--kkt-max-N", "--what contact"),
    (["bench", "--what", "contact", "--N", "4", "--k", "1", "--dense-max-size", "2500"], "--dense-max-size",
     "--what beta"),
    (["bench", "--what", "face", "--N", "2", "--k", "1", "--eigsh-max-N", "4"], "--eigsh-max-N", "--what beta"),
    (["bench", "--what", "contact", "--N", "4", "--k", "1", "--element", "hex"], "--element", "--what face"),
    (["bench", "--what", "beta", "--N", "4", "--k", "1", "--nu", "0.3"], "--nu", "--what elastic"),
    (["bench", "--what", "face", "--N", "2", "--k", "1", "--case", "T3"], "--case", "--what elastic"),
    (["bench", "--what", "elastic", "--N", "4", "--k", "1", "--dense-max-size", "10"], "--dense-max-size",
     "--what beta"),
]


@pytest.mark.parametrize("argv, flag, users", UNUSED, ids=[f"{a[0]}-{f}-{i}" for i, (a, f, _) in enumerate(UNUSED)])
def test_a_flag_the_request_does_not_use_is_refused(argv, flag, users):
    """One rule (cli/common.refuse_unused) for every subcommand: a flag the request does not use
    is one line naming the flag, who uses it and the request, exit 2 (they were accepted and
    ignored: --p/--q/--n-ref for the elastic patch scene, --alpha/--seed without --family
    perturbed, in 3D too, while --R outside Hertz was refused)."""
    code, out, err = run_in_process([*argv, "--dry-run"])
    assert code == 2 and out == "" and len(err.splitlines()) == 1, (code, out, err)
    assert err.startswith(f"infsup-contact: error: invalid {flag} (got ") and "used only by" in err, err
    assert users in err and "this request:" in err, err


@pytest.mark.parametrize("argv", [
    ["contact", "--scene", "manufactured", "--case", "T3", "--k", "1", "--N1", "4", "--N2", "4", "--p", "3", "--q", "3"],
    ["contact", "--scene", "membranes", "--case", "T3", "--k", "1", "--N1", "4", "--N2", "4", "--n-ref", "16"],
    ["contact", "--model", "elastic", "--scene", "hertz", "--case", "T4", "--k", "2", "--N1", "8", "--N2", "8",
     "--R", "1", "--d", "0.05", "--nu", "0.3"],
    ["beta", "--k", "1", "--N1", "4", "--N2", "4", "--family", "perturbed", "--seed", "3", "--alpha", "0.1"],
    ["beta", "--model", "membranes3d", "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4", "--element", "tet",
     "--family", "perturbed", "--seed", "3"],
    ["beta", "--k", "1", "--N1", "4", "--N2", "4", "--norm", "H", "--h-route", "series"],
    ["bench", "--what", "beta", "--N", "4", "--k", "1", "--eigsh-max-N", "2", "--dense-max-size", "2500"],
    ["bench", "--what", "contact", "--N", "4", "--k", "1", "--peers", "osqp", "clarabel", "--kkt-max-N", "64"],
    ["bench", "--what", "face", "--N", "2", "--k", "1", "--element", "tet"],
    ["bench", "--what", "elastic", "--N", "4", "--k", "1", "--nu", "0.25", "--case", "T3", "DUAL"],
])
def test_a_flag_the_request_uses_is_accepted(argv):
    code, out, err = run_in_process([*argv, "--dry-run"])
    assert code == 0 and out.startswith("dry run: valid request"), (code, out, err)


def test_every_subcommand_declares_its_conditional_flags():
    """The rule is applied to every computing subcommand: each declares its flag uses (rates: none)."""
    for command, parser in subcommands().items():
        if command != "provenance":
            assert parser.get_default("flag_uses") is not None, command  # set_defaults(flag_uses=...)


# ------------------------------------------------------------------ issue 50, item 8: hostile inputs
# Each one line on stderr, exit 2, before anything is computed or written (they were tracebacks,
# files of the user replaced, or the matrices of a symlinked manifest looked for beside the link).

def _variant(root, name, edit_level=None, files=None):
    """A copy of the tiny manifest in ``root/name``: ``edit_level`` appended to level 0's
    mapping (``", constrained: [5]"``), ``files`` {name: bytes or callable(path)} written."""
    folder = root / name
    manifest = _tiny_manifest(folder)
    if edit_level:
        text = manifest.read_text().replace("G: G0.mtx}", f"G: G0.mtx{edit_level}}}", 1)
        manifest.write_text(text)
    for fname, data in (files or {}).items():
        data(folder / fname) if callable(data) else (folder / fname).write_bytes(data)
    return manifest


def _npy_header_only(shape, descr):
    """An .npy file of ``shape`` whose body is a hole (a sparse file: a few kB on disk)."""
    import numpy as np

    def write(path):
        with open(path, "wb") as fh:
            np.lib.format.write_array_header_1_0(fh, {"descr": descr, "fortran_order": False, "shape": shape})
            fh.truncate(fh.tell() + int(np.prod(shape)) * np.dtype(descr).itemsize)
    return write


@pytest.fixture(scope="module")
def hostile(tmp_path_factory):
    root = tmp_path_factory.mktemp("hostile")
    out = {"good": _tiny_manifest(root / "good")}
    (root / "link").mkdir()
    (root / "link" / "levels.yaml").symlink_to(out["good"])
    out["link"] = root / "link" / "levels.yaml"
    out["loop"] = root / "loop.yaml"
    out["loop"].symlink_to(out["loop"])
    zero = _variant(root, "zero")
    (zero.parent / "A0.mtx").write_text("%%MatrixMarket matrix coordinate real general\n4 4 0\n")
    out["zero A"] = zero
    out["constrained 10**20"] = _variant(root, "big", ", constrained: [100000000000000000000]")
    out["constrained file 10**23"] = _variant(root, "bigfile", ", constrained: c.txt",
                                              {"c.txt": b"100000000000000000000000\n"})
    out["multipliers null"] = _variant(root, "mnull", ", multipliers: null")
    out["constrained .npy of 150M dofs"] = _variant(root, "npyc", ", constrained: c.npy",
                                                    {"c.npy": _npy_header_only((150_000_000,), "<i8")})
    npy_a = _variant(root, "npya", files={"A0.npy": _npy_header_only((12_000, 12_000), "<f8")})
    npy_a.write_text(npy_a.read_text().replace("A0.mtx", "A0.npy"))
    out["A .npy of 1.15 GB that B does not fit"] = npy_a
    out["dir"] = root
    return out


HOSTILE_MANIFESTS = {  # name: a needle of the one line
    "loop": "symlink loop",
    "zero A": "A is zero",
    "constrained 10**20": "constrained dof 100000000000000000000 outside 0..3",
    "constrained file 10**23": "beyond 64-bit integers",
    "multipliers null": "levels[0].multipliers: no value (null)",
    "constrained .npy of 150M dofs": "declares 150000000 constrained dofs",
    "A .npy of 1.15 GB that B does not fit": "B is 2 x 4, but A (A0.npy) is 12000 x 12000",
}


def refused(argv, flag, needle=""):
    """Run ``argv`` (no --dry-run): exit 2, nothing on stdout, one stderr line naming ``flag``."""
    code, out, err = run_in_process([str(a) for a in argv])
    assert code == 2 and out == "" and len(err.splitlines()) == 1 and "Traceback" not in err, (code, out, err)
    assert flag in err and needle in err, err
    return err


@pytest.mark.parametrize("name", list(HOSTILE_MANIFESTS))
@pytest.mark.parametrize("command", ["verdict", "beta"])
def test_hostile_manifest_is_one_line(hostile, name, command):
    refused([command, "--system", hostile[name]], "--system", HOSTILE_MANIFESTS[name])


def test_a_symlinked_manifest_reads_the_matrices_beside_its_target(hostile):
    code, out, err = run_in_process(["verdict", "--system", str(hostile["link"]), "--dry-run"])
    assert code == 0 and out.startswith("dry run: valid request"), (code, out, err)


TABLE_COMMANDS = {  # command → argv (a small request; never computed here: refused or --dry-run)
    "beta": ["beta", "--k", "1", "--N1", "4", "--N2", "4"],
    "contact": ["contact", "--scene", "manufactured", "--case", "T3", "--k", "1", "--N1", "4", "--N2", "4"],
    "bench": ["bench", "--what", "beta", "--N", "4", "--k", "1"],
    "verdict": ["verdict", "--case", "T3", "--k", "1"],
}


@pytest.mark.parametrize("command", [*TABLE_COMMANDS, "rates"])
def test_output_never_replaces_an_existing_file_without_force(tables, tmp_path, command):
    """Every subcommand writing a table has --output FILE; an existing file is refused (one line
    naming --output and --force, the file untouched), with --force accepted; --force alone
    (nothing written) is refused as unused; /proc, where no temporary file can be created, is
    refused by the flag's type."""
    argv = TABLE_COMMANDS.get(command, ["rates", str(tables["good"])])
    victim = tmp_path / "precious.txt"
    victim.write_text("keep me\n")
    refused([*argv, "--output", victim], "--output", "--force")
    assert victim.read_text() == "keep me\n"
    code, out, err = run_in_process([*argv, "--output", str(victim), "--force", "--dry-run"])
    assert code == 0 and out.startswith("dry run: valid request"), (code, out, err)
    refused([*argv, "--force"], "--force", "used only by")
    refused([*argv, "--output", "/proc/x.csv"], "--output", "no file can be created in /proc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["precious.txt"]  # no temporary file left


def test_verdict_output_force_replaces_and_rates_output_is_not_its_table(hostile, tables, tmp_path):
    target = tmp_path / "v.json"
    target.write_text("old\n")
    code, out, err = run_in_process(["verdict", "--system", str(hostile["good"]), "--format", "json",
                                     "--output", str(target), "--force"])
    assert code == 0 and out == "" and '"verdict"' in target.read_text(), (code, out, err)
    refused(["rates", tables["good"], "--output", tables["good"], "--force"], "--output", "other than the inputs")


def test_export_refuses_a_place_it_cannot_write_before_computing(tmp_path):
    base = ["export", "--case", "T3", "--k", "1", "--N", "2", "3", "4"]
    for out in ("/proc/infsup-x", "/proc/infsup-x/sub"):
        refused([*base, "--out", out], "--out", "no file can be created in /proc")


def test_export_on_an_arc_names_its_radius(tmp_path):
    """The system name joins the mesh options as text (a float radius was a TypeError)."""
    code, out, err = run_in_process(["export", "--case", "T3", "--k", "1", "--N", "2", "3", "4", "--gamma", "arc",
                                     "--radius", "2", "--out", str(tmp_path / "e")])
    assert code == 0 and "arc-2-exact" in (tmp_path / "e" / "levels.yaml").read_text(), (code, out, err)


@pytest.mark.parametrize("argv, flag, needle", [
    (["beta", "--model", "membranes3d", "--case", "DUAL-Q9", "--k", "2", "--N1", "2", "--N2", "2", "--gamma",
      "cylinder", "--radius", "1e300"], "--radius", "1e+08"),
    (["export", "--model", "membranes3d", "--case", "DUAL-Q9", "--k", "2", "--N", "2", "3", "4", "--gamma",
      "cylinder", "--radius", "1e20", "--out", "unused"], "--radius", "1e+08"),
])
def test_a_radius_beyond_round_off_is_refused(argv, flag, needle):
    refused(argv, flag, needle)


def test_the_elastic3d_face_estimate_above_the_dense_gate():
    """The estimate of a 3-component face above the dense route's gate (a RecursionError)."""
    code, out, err = run_in_process(["beta", "--model", "elastic3d", "--case", "T3", "--k", "2", "--N1", "16",
                                     "--N2", "16", "--dry-run"])
    assert code == 0 and out.startswith("dry run: valid request"), (code, out, err)


@pytest.mark.parametrize("name", ["A .npy of 1.15 GB that B does not fit", "constrained .npy of 150M dofs"])
def test_a_large_declared_npy_is_refused_by_its_header_before_its_body(hostile, name):
    """The refusal reads headers only: the traced peak stays far below the 1.15/1.2 GB body."""
    import tracemalloc

    tracemalloc.start()
    try:
        refused(["verdict", "--system", hostile[name]], "--system", HOSTILE_MANIFESTS[name])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100e6, f"{peak / 1e6:.0f} MB traced"
