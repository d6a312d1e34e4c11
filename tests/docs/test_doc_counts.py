"""Counts the docs state that drift with the code are recomputed here: the keys and flags
`tests/cli/test_bad_input.py` mutates (docs/refusals.md) and the architecture caps
(docs/package.md). (The workflow's job counts: tests/workflow/.)"""
from __future__ import annotations

import argparse
import re

import yaml
from helpers.doc_blocks import ROOT


def _key_paths(node, path=()):
    """Every key of the config, as test_bad_input walks it (a list's first element for all)."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield (*path, key)
            yield from _key_paths(value, (*path, key))
    elif isinstance(node, list) and node:
        yield (*path, 0)
        yield from _key_paths(node[0], (*path, 0))


def _flags_per_subcommand() -> dict:
    """Flags and positionals (not --help) of each subcommand that has any, as test_bad_input mutates them."""
    from infsup_contact.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    counts = {name: sum(not isinstance(a, argparse._HelpAction) for a in p._actions) for name, p in sub.choices.items()}
    return {name: n for name, n in counts.items() if n}


def test_refusals_counts_are_the_mutated_keys_and_flags():
    text = " ".join((ROOT / "docs" / "refusals.md").read_text(encoding="utf-8").split())
    keys = len(list(_key_paths(yaml.safe_load((ROOT / "config" / "config.yaml").read_text()))))
    flags = _flags_per_subcommand()
    assert f"`config/config.yaml` ({keys} keys:" in text, f"refusals.md: config/config.yaml has {keys} keys"
    assert f"({sum(flags.values())} over {len(flags)} subcommands:" in text, \
        f"refusals.md: {sum(flags.values())} flags over {len(flags)} subcommands"


def test_package_states_the_architecture_caps():
    arch = (ROOT / "tests" / "test_architecture.py").read_text(encoding="utf-8")
    modules = re.search(r"^MAX_MODULES = (\d+)", arch, re.M).group(1)
    lines = re.search(r"^MAX_LINES = (\d+)", arch, re.M).group(1)
    text = " ".join((ROOT / "docs" / "package.md").read_text(encoding="utf-8").split())
    assert f"caps a folder at {modules} modules and a module at {lines} lines" in text


def test_foreign_systems_states_the_inline_limit():
    from infsup_contact.systems.export import INLINE_MAX

    text = " ".join((ROOT / "docs" / "foreign-systems.md").read_text(encoding="utf-8").split())
    assert f"longer than {INLINE_MAX} numbers a `.npy` file" in text
