"""The ledger's ``paper_ref`` names what a reader of the ledger can open: a section, equation or
remark of the paper, or for a claim beyond it the docs' section; never an issue number, which
points into a tracker the reader does not have.

A paper_ref is a string of the claims modules (``study/claims/``: their ``REF`` constants and the
literals they pass to ``row``) or of the registry of spaces (``SpaceSpec.paper_ref``), so every
string literal of those modules is read (:mod:`ast`, nothing imported), f-strings' text included,
and every registered space's reference.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

from infsup_contact.discretization.spaces.registry import space_ids, space_spec

CLAIMS = Path(__file__).resolve().parents[2] / "src" / "infsup_contact" / "study" / "claims"
ISSUE = re.compile(r"\bissues?\s*#?\d+|#\d+\b", re.IGNORECASE)


def literals(source: str):
    """(line, text) of every string literal of ``source``, the constant parts of f-strings too."""
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            yield node.lineno, node.value


def issue_mentions(path: Path) -> list:
    return [f"{path.name}:{line}: {text[:100]!r}" for line, text in literals(path.read_text(encoding="utf-8"))
            if ISSUE.search(text)]


def test_the_scanner_reads_constants_and_fstrings():
    source = 'REF = "beyond the paper (issue 28: x)"\ndef f(k):\n    return f"see issue #{k}", "§5"\n'
    assert [line for line, text in literals(source) if ISSUE.search(text)] == [1]
    source = 'def f(k):\n    return f"as in Issue 7 for k = {k}"\n'
    assert [line for line, text in literals(source) if ISSUE.search(text)] == [2]
    assert not ISSUE.search("beyond the paper (the 3D contact face: docs/models.md, 3D bodies with a contact face)")


def test_no_claims_module_names_an_issue_in_its_strings():
    modules = sorted(CLAIMS.glob("*.py"))
    assert len(modules) > 3  # the claims modules are where this test looks
    hits = [hit for path in modules for hit in issue_mentions(path)]
    assert not hits, "ledger strings naming an issue (name the paper's or the docs' section):\n" + "\n".join(hits)


def test_no_registered_space_refers_to_an_issue():
    refs = {case: space_spec(case).paper_ref for case in space_ids(gamma_dim=None)}
    assert refs
    assert not {case: ref for case, ref in refs.items() if ISSUE.search(ref)}
