"""Every command and code block of README.md and docs/*.md runs, or is validated as a real run
validates it (docs/testing.md, "Docs that are true by construction"; the marks:
tests/helpers/doc_blocks.py). The commands run in a scratch directory holding the repository's
``examples/``, ``config/`` and ``tests/`` and an exported ``levels.yaml`` (the docs' stand-in
for "your manifest"), so a path a command reads must exist there."""
from __future__ import annotations

import ast
import contextlib
import importlib
import io
import re

import pytest
from helpers.doc_blocks import MARKS, ROOT, all_blocks, commands, variants
from helpers.cli import run_in_process

BASH = all_blocks("bash")
PYTHON = all_blocks("python")
SHELL_BUILTINS = {"exit"}
"""Shell words around the commands (``... || exit 1``): nothing to check."""
_PLACEHOLDER = re.compile(r"^([A-Z][A-Z0-9_]*|\.\.\.|…|[A-Z]+\.py:[A-Z]+|\d+(\.\d+)?|-)$")


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """A scratch working directory: the repository's inputs and one exported system, levels.yaml
    (T3 with k = 2 on N = 8, 16, 32: STABLE, as the docs' ``--expect stable`` says of it)."""
    path = tmp_path_factory.mktemp("docs")
    for name in ("examples", "config", "tests", "src"):
        (path / name).symlink_to(ROOT / name)
    code, _, err = run_in_process(["export", "--case", "T3", "--k", "2", "--N", "8", "16", "32", "--out",
                                   str(path), "--force"])
    assert code == 0, err
    return path


def test_the_marks_are_known():
    assert all(b.mark in (None, *MARKS) for b in [*BASH, *PYTHON])
    assert BASH and PYTHON


def _expected(lines, argv):
    """The words of a shown output up to the first number the command does not state (sizes,
    times and memory vary by machine)."""
    words = []
    for word in " ".join(lines).split():
        if re.search(r"\d", word) and word.strip("(),:;") not in argv:
            break
        words.append(word)
    return " ".join(words)


@pytest.mark.parametrize("block", BASH, ids=lambda b: b.id)
def test_bash_block(block, workdir, monkeypatch):
    monkeypatch.chdir(workdir)
    cmds = commands(block)
    assert cmds, f"{block.id}: a bash block without a command"
    for cmd in cmds:
        where = f"{block.id}: {cmd.program} {' '.join(cmd.argv)}"
        if cmd.program in SHELL_BUILTINS:
            continue
        check = {"infsup-contact": _infsup, "python": _python, "snakemake": _snakemake, "make": _make}.get(cmd.program)
        assert check is not None, f"{where}: a program the docs test does not check ({cmd.program})"
        check(block.mark, cmd, where)


# ------------------------------------------------------------------ infsup-contact
def _subparser(command):
    import argparse

    from infsup_contact.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    assert command in sub.choices, f"no subcommand {command!r} (allowed: {', '.join(sub.choices)})"
    return sub.choices[command]


def _synopsis(argv, where):
    if argv[0].startswith("-"):  # a top-level flag (--version, --help): it runs, in a blink
        code, out, err = run_in_process(list(argv[:1]))
        assert code == 0 and out.strip(), f"{where}: infsup-contact {argv[0]}: exit {code}, {err.strip()}"
        return None
    parser = _subparser(argv[0])
    flags = {s: a for a in parser._actions for s in a.option_strings}
    action = None
    for raw in argv[1:]:
        word = raw.strip("[]()")
        if word.startswith("--"):
            action = flags.get(word)
            assert action is not None, f"{where}: {argv[0]} has no flag {word}"
            continue
        for value in filter(None, word.split("|")):
            if action is not None and action.choices is not None and not _PLACEHOLDER.match(value) \
                    and not value.startswith("-"):
                assert value in action.choices, f"{where}: {value!r} is not a choice of {action.option_strings[-1]}"


def _infsup(mark, cmd, where):
    if mark == "synopsis":
        return _synopsis(cmd.argv, where)
    for n, argv in enumerate(variants(cmd.argv)):
        dry = mark == "slow" or n > 0
        has_dry = any("--dry-run" in a.option_strings for a in _subparser(argv[0])._actions)
        code, out, err = run_in_process(argv + (["--dry-run"] if dry and has_dry else []))
        shown = _expected(cmd.output, argv)
        if cmd.output and cmd.output[0].startswith("infsup-contact: error:"):
            assert code == 2 and err.startswith(shown), f"{where}: exit {code}, {err!r}; the docs show {shown!r}"
            continue
        assert code == 0, f"{where}: exit {code}: {err.strip()}"
        assert out.startswith(shown), f"{where}: printed {out[:200]!r}; the docs show {shown!r}"


# ------------------------------------------------------------------ python -m / python -c
def _python(mark, cmd, where):
    argv = list(cmd.argv)
    if argv[:1] == ["-c"]:
        code = compile(argv[1], where, "exec")
        if mark != "slow":
            with contextlib.redirect_stdout(io.StringIO()):
                exec(code, {})
        return
    assert argv[:1] == ["-m"], f"{where}: python is documented as python -m MODULE or python -c CODE"
    module = importlib.import_module(argv[1])
    assert hasattr(module, "main"), f"{where}: {argv[1]} has no main()"
    for n, args in enumerate(variants(tuple(argv[2:]))):
        _run_study_main(module, args, dry=mark == "slow" or n > 0, where=where)


def _run_study_main(module, args, dry, where):
    """A study module's main(args): with ``dry`` its parser and checks only (``run`` skipped)."""
    from infsup_contact import command_line

    real = command_line.run_study
    out, err = io.StringIO(), io.StringIO()

    def checked_only(parser, argv, check, run):
        return real(parser, argv, check, lambda a: None)

    command_line.run_study = checked_only if dry else real
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = module.main(args)
            except SystemExit as exc:
                code = exc.code
    finally:
        command_line.run_study = real
    assert code == 0, f"{where}: exit {code}: {err.getvalue().strip()}"


# ------------------------------------------------------------------ snakemake / make
def _rule_names():
    text = "\n".join(p.read_text(encoding="utf-8") for p in [ROOT / "Snakefile", *ROOT.glob("workflow/**/*.smk"),
                                                            ROOT / "workflow" / "Snakefile"] if p.exists())
    names = set(re.findall(r"^rule (\w+)", text, re.M)) | set(re.findall(r'^\s+name:\s*"([\w-]+)"', text, re.M))
    return names


_SNAKE_VALUES = {"--profile": "dir", "--configfile": "file", "--cores": None, "-j": None, "--jobs": None,
                 "--report": None, "--config": None}


def _snakemake(mark, cmd, where):
    rules, words, i = _rule_names(), list(cmd.argv), 0
    while i < len(words):
        word = words[i]
        if word in _SNAKE_VALUES:
            kind, value = _SNAKE_VALUES[word], words[i + 1]
            if kind is not None:
                assert (ROOT / value).exists(), f"{where}: {word} {value} does not exist"
            i += 2
            continue
        if not word.startswith("-"):
            assert word in rules, f"{where}: no rule {word!r}"
        i += 1


def _make(mark, cmd, where):
    targets = set(re.findall(r"^([\w.-]+):", (ROOT / "Makefile").read_text(encoding="utf-8"), re.M))
    for word in cmd.argv:
        if not word.startswith("-"):
            assert word in targets, f"{where}: the Makefile has no target {word!r}"


# ------------------------------------------------------------------ python blocks
PYTHON_PAGES = sorted({b.page for b in PYTHON})


@pytest.mark.parametrize("page", PYTHON_PAGES, ids=lambda p: p.name)
def test_python_blocks(page, workdir, monkeypatch):
    """A page's python blocks in order, in one namespace, like a notebook (one test per page, so
    that xdist never splits a page's blocks between workers)."""
    monkeypatch.chdir(workdir)
    namespace = {"__name__": "__docs__"}
    for block in (b for b in PYTHON if b.page == page):
        code = compile(block.text, block.id, "exec")
        for node in ast.walk(ast.parse(block.text)):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    importlib.import_module(alias.name)
            elif isinstance(node, ast.ImportFrom):
                module = importlib.import_module(node.module)
                for alias in node.names:
                    assert hasattr(module, alias.name), f"{block.id}: {node.module} has no {alias.name}"
        if block.mark == "slow":
            continue
        with contextlib.redirect_stdout(io.StringIO()):
            exec(code, namespace)


DOCTESTS = [b for b in all_blocks("text") if ">>> " in b.text]


@pytest.mark.parametrize("block", DOCTESTS, ids=lambda b: b.id)
def test_shown_refusals_are_the_api_s(block):
    """A ``text`` block of ``>>>`` calls, each followed by the ``InputError: …`` line it shows."""
    import infsup_contact as ic
    from infsup_contact.errors import InputError

    lines = block.text.splitlines()
    calls = [(line[4:], lines[i + 1]) for i, line in enumerate(lines) if line.startswith(">>> ")]
    assert calls
    for call, shown in calls:
        assert shown.startswith("InputError: "), f"{block.id}: {call} shows {shown!r}"
        with pytest.raises(InputError) as err:
            eval(call, {"ic": ic})
        assert str(err.value) == shown[len("InputError: "):], f"{block.id}: {call}"
