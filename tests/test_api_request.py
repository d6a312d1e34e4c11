"""The request the API builds: from typed values, through the builder the command line's parsed
flags go through (``cli.request_of``), never through argparse's parsing; the same rows as the
command line; ``space=`` an object checked as a file's space."""
import argparse
import csv
import io
import runpy
from pathlib import Path

import pytest

import infsup_contact as ic
from infsup_contact.cli import build_parser, options, request_of
from infsup_contact.cli.request import build
from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.spaces.user_spaces import forget_since
from infsup_contact.errors import InputError
from helpers.cli import run_in_process

ROOT = Path(__file__).resolve().parents[1]
TIMING = ("t_assemble", "t_interface", "t_eig", "seconds")
"""Columns of wall-clock times: the only cells two runs of one request may differ in."""


def cells(text: str) -> list:
    """The CSV ``text`` as rows of cell strings (the bytes of each cell), timing columns left out."""
    rows = list(csv.reader(io.StringIO(text)))
    keep = [i for i, name in enumerate(rows[0]) if name not in TIMING]
    return [[row[i] for i in keep] for row in rows]


def cli_csv(argv) -> str:
    code, out, err = run_in_process([*argv, "--quiet"])
    assert code == 0, err
    return out


# ---------------------------------------------------------------- no command line on the API's path
@pytest.fixture(scope="module")
def manifest(tmp_path_factory):
    out = tmp_path_factory.mktemp("export")
    code, _, err = run_in_process(["export", "--case", "T3", "--k", "2", "--N", "4", "8", "16", "--out", str(out)])
    assert code == 0, err
    return out / "levels.yaml"


def test_the_api_parses_no_command_line(monkeypatch, manifest):
    def refuse(self, *args, **kwargs):
        raise AssertionError("argparse parsed a command line on the API's path")

    for name in ("parse_args", "parse_known_args", "parse_intermixed_args"):
        monkeypatch.setattr(argparse.ArgumentParser, name, refuse)
    assert ic.beta(case="T3", k=1, N1=2, N2=2, norm="L2").beta[0] > 0
    assert ic.verdict(case="R5.4", k=1, N=[2, 4, 8]).verdict[0] == "UNSTABLE"
    assert ic.certify(manifest).verdict[0] in ("STABLE", "INCONCLUSIVE")
    code, _, err = run_in_process(["beta", "--case", "T3", "--k", "1", "--N1", "2", "--N2", "2"])
    assert code == 70 and "argparse parsed" in err  # the command line does parse: the patch bites


# ---------------------------------------------------------------- one builder for both
@pytest.mark.parametrize("argv", [
    ["beta", "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4"],
    ["beta", "--model", "membranes3d", "--element", "hex", "--k", "1", "--N1", "2", "--N2", "3", "--norm", "H"],
    ["beta", "--family", "perturbed", "--seed", "3", "--alpha", "0.1", "--k", "1", "--N1", "5", "--N2", "4"],
    ["verdict", "--space", "examples/macro_p0.py:space", "--k", "1", "--N", "4", "8", "16", "--N1-offset", "1"],
    ["contact", "--scene", "manufactured", "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4", "--p", "2.5"],
    ["export", "--case", "T3", "--k", "2", "--N", "4", "8", "--out", "somewhere", "--force"],
])
def test_the_builder_makes_argparses_namespace(argv):
    """The same flags as typed values: the namespace argparse makes from their text, the flags given kept."""
    parser = build_parser()
    parsed = parser.parse_args(argv)
    given = parsed.given  # noted by the actions argparse called: the flags typed
    declared = parser.commands[argv[0]].declared
    values = {d: getattr(parsed, d) for d in given if d in options(argv[0], parser)}
    built = build(declared, argv[0], values, given)
    assert vars(built) == {**vars(parsed), "given": given}
    assert given - {"command"} == set(values) and values  # the values were the builder's, not the defaults'


@pytest.mark.parametrize("keywords, argv", [
    (dict(case="T3", k=2, N1=4, N2=4), ["--case", "T3", "--k", "2", "--N1", "4", "--N2", "4"]),
    (dict(model="membranes3d", element="hex", case="T3", k=1, N1=2, N2=2),
     ["--model", "membranes3d", "--element", "hex", "--case", "T3", "--k", "1", "--N1", "2", "--N2", "2"]),
])
def test_beta_rows_are_the_commands_cells(keywords, argv):
    frame = ic.beta(**keywords)
    assert cells(frame.to_csv(index=False, float_format="%.12g")) == cells(cli_csv(["beta", *argv]))


def test_verdict_row_is_the_commands_cells():
    frame = ic.verdict(case="T3", k=2, N=[2, 4, 8], norm="L2")
    table = cli_csv(["verdict", "--case", "T3", "--k", "2", "--N", "2", "4", "8", "--norm", "L2"])
    assert cells(frame.to_csv(index=False, float_format="%.6g")) == cells(table)


def test_a_keyword_is_checked_as_its_flag_is():
    with pytest.raises(InputError) as err:
        request_of("beta", {"N1": [4, 8]})  # one value
    assert err.value.key == "N1"
    with pytest.raises(InputError) as err:
        request_of("verdict", {"case": "T3", "k": 1, "N": []})  # nargs "+"
    assert err.value.key == "N" and "at least one" in str(err.value)
    with pytest.raises(InputError) as err:
        request_of("beta", {"case": "T3", "k": 1, "N1": 4, "N2": 4, "quiet": "yes"})  # a switch
    assert err.value.key == "quiet" and "True or False" in str(err.value)
    with pytest.raises(InputError) as err:
        request_of("contact", {"case": "T3", "k": 1, "N1": 4, "N2": 4})  # argparse's required=True
    assert err.value.key == "scene"
    with pytest.raises(InputError) as err:  # a type raising argparse's error: one line too
        request_of("beta", {"case": "T3", "k": 1, "N1": 4, "N2": 4, "worst_mode": str(ROOT)})
    assert err.value.key == "worst_mode" and "is a directory" in str(err.value) and "\n" not in str(err.value)


# ---------------------------------------------------------------- space= an object
@pytest.fixture
def space_file(tmp_path):
    """examples/macro_p0.py under an id of its own (a registry holds an id once), restored after."""
    path = tmp_path / "api_p0.py"
    path.write_text((ROOT / "examples" / "macro_p0.py").read_text(encoding="utf-8").replace('"P0-2h"', '"API-P0"'),
                    encoding="utf-8")
    before = set(registry.SPACES)
    yield path
    forget_since(before)


def test_a_space_object_gives_the_file_spaces_rows(space_file):
    """The same space as a file reference, a function and a SpaceSpec: the same rows, to the bit."""
    function = runpy.run_path(str(space_file))["space"]
    before = set(registry.SPACES)
    tables = {}
    for name, space in (("file", f"{space_file}:space"), ("function", function), ("spec", function())):
        beta = ic.beta(space=space, k=1, N1=6, N2=8)
        verdict = ic.verdict(space=space, k=1, N=[4, 8, 16])
        tables[name] = (beta.drop(columns=[c for c in TIMING if c in beta]),
                        verdict.drop(columns=[c for c in TIMING if c in verdict]))
        assert beta.case[0] == verdict.space[0] == "API-P0"
        forget_since(before)  # the next reference registers the id again
    for name in ("function", "spec"):
        for got, want in zip(tables[name], tables["file"]):
            assert got.to_csv(index=False, float_format="%.17g") == want.to_csv(index=False, float_format="%.17g")


def _not_a_spec():
    return 42


def _raising():
    raise RuntimeError("no such space here")


@pytest.mark.parametrize("space, says", [
    (3, "a SpaceSpec"),
    (_not_a_spec, "returning a SpaceSpec (got int)"),
    (_raising, "RuntimeError: no such space here"),
])
@pytest.mark.parametrize("command", ["beta", "verdict"])
def test_a_wrong_space_object_is_one_line_naming_space(space, says, command):
    before = set(registry.SPACES)
    with pytest.raises(InputError) as err:
        if command == "beta":
            ic.beta(space=space, k=1, N1=4, N2=4)
        else:
            ic.verdict(space=space, k=1, N=[4, 8, 16])
    assert err.value.key == "space" and says in str(err.value) and "\n" not in str(err.value)
    assert set(registry.SPACES) == before  # nothing registered


def test_the_package_exports_the_error_its_api_raises():
    """``except ic.InputError`` catches a bad keyword: the package's name is the error the API raises."""
    assert ic.InputError is InputError
    with pytest.raises(ic.InputError, match="N1"):
        ic.beta(case="T3", k=2, N1=0, N2=4, norm="H")


def _typed_by_a_second_parse(parser, argv) -> set:
    """The reference route: ``argv`` parsed again with every default suppressed (what the
    command line did before its actions noted their dests): the dests present were typed."""
    parsers, todo = [], [parser]
    while todo:
        p = todo.pop()
        parsers.append(p)
        todo += [q for a in p._actions if isinstance(a, argparse._SubParsersAction) for q in a.choices.values()]
    saved = [(p, dict(p._defaults), [(a, a.default) for a in p._actions]) for p in parsers]
    try:
        for p in parsers:
            p._defaults.clear()
            for a in p._actions:
                if not isinstance(a, argparse._SubParsersAction):
                    a.default = argparse.SUPPRESS
        return set(vars(parser.parse_args(argv))) - {"given"}  # the set the actions noted: not a flag
    finally:
        for p, defaults, actions in saved:
            p._defaults.update(defaults)
            for a, default in actions:
                a.default = default


@pytest.mark.parametrize("argv", [
    ["beta", "--case", "T3", "--k", "2", "--N1=4", "--N2", "4", "--quiet"],
    ["beta", "--family", "perturbed", "--seed", "0", "--alpha", "0.2", "--k", "1", "--N1", "5", "--N2", "4"],
    ["verdict", "--case", "T3", "--k", "1", "--N", "2", "4", "8", "--N1-off", "1", "--dry-run"],
    ["verdict-hook", "a.yaml", "b.yaml"],
    ["rates", "x.csv"],
])
def test_argv_is_parsed_once_and_the_flags_typed_are_those_a_second_parse_finds(argv, monkeypatch):
    """The flags typed (a default value typed counts, an abbreviation too) are noted as argparse
    calls their actions: the same set as the reference route's, from one parse of argv."""
    from infsup_contact import cli

    parser = build_parser()
    calls = []
    real = parser.parse_args
    monkeypatch.setattr(parser, "parse_args", lambda a: calls.append(a) or real(a))
    args = cli.parse(parser, argv)
    assert len(calls) == 1
    monkeypatch.undo()
    assert args.given == _typed_by_a_second_parse(build_parser(), argv)
