"""Text that stays true whatever the verdict: render the paper's text from its macros and find
sentences that state an outcome their own verdict contradicts.

A sentence that states an outcome is chosen by the verdict it rests on (``\\byverdict`` in
``paper.tex``); the check here is what makes that a rule: :func:`render` expands the generated
macros and resolves every ``\\byverdict``, :func:`contradictions` reads the clause in front of
each verdict tag and flags a success phrase before FAIL or INCONCLUSIVE, a failure phrase
before PASS or INCONCLUSIVE, and an undecided phrase before PASS or FAIL. ``tests/report/test_paper.py``
renders the text under flipped ledgers (every verdict swapped, all INCONCLUSIVE, …).
"""
from __future__ import annotations

import re

UNDECIDED = ("undecided", "not decided", "cannot decide")
FAILURE = ("not bounded", "does not", "do not", "not always", "not every", "not the reversed", "not confirm",
           "but not")
SUCCESS = ("has exactly", "exactly the kernels", "is reversed", "looks unstable", "converge at the expected", "bounded", "holds",
           "as the dimension counts predict")
"""Phrases (lower case) that state an outcome; each list is searched after the ones before it
have been removed, so "not bounded" is a failure and not a success."""
_TAG = re.compile(r"\\verdictfmt\{(PASS|FAIL|INCONCLUSIVE)\}")
_ALLOWED = {"PASS": ("success",), "FAIL": ("failure",), "INCONCLUSIVE": ("undecided",)}


def _group(text: str, start: int) -> tuple[str, int]:
    """The brace group opening at ``text[start] == '{'``: its content and the index after it."""
    depth = 0
    for i in range(start, len(text)):
        depth += {"{": 1, "}": -1}.get(text[i], 0)
        if depth == 0:
            return text[start + 1:i], i + 1
    raise ValueError(f"unbalanced braces from offset {start}")


def expand(tex: str, values: dict) -> str:
    """Replace every ``\\name`` (and ``\\name{}``) whose name is in ``values`` until none is left."""
    pattern = re.compile(r"\\([A-Za-z]+)(\{\})?")
    for _ in range(10):
        new = pattern.sub(lambda m: values[m.group(1)] if m.group(1) in values else m.group(0), tex)
        if new == tex:
            return new
        tex = new
    return tex


def resolve_byverdict(text: str) -> str:
    """``\\byverdict{V}{pass}{fail}{inconclusive}`` → the branch V selects (innermost first)."""
    while (i := text.rfind("\\byverdict{")) >= 0:
        pos, parts = i + len("\\byverdict"), []
        for _ in range(4):
            while text[pos].isspace():
                pos += 1
            part, pos = _group(text, pos)
            parts.append(part)
        verdict = parts[0].strip()
        if verdict not in ("PASS", "FAIL", "INCONCLUSIVE"):
            raise ValueError(f"\\byverdict on {verdict!r}: not a verdict word")
        text = text[:i] + parts[{"PASS": 1, "FAIL": 2, "INCONCLUSIVE": 3}[verdict]] + text[pos:]
    return text


def render(tex: str, macros) -> str:
    """The paper's body (after ``\\begin{document}``) with comments dropped, generated macros
    expanded, ``\\byverdict`` resolved (``macros``: :class:`~infsup_contact.report.texnames.Macro` objects)."""
    body = re.sub(r"(?<!\\)%.*", "", tex)
    body = body.split("\\begin{document}", 1)[-1]  # the preamble defines, the body states
    # verdict words typed in the text (the criteria's definitions) are not outcomes: only the
    # tags that macros generate are checked
    body = body.replace("\\verdictfmt{", "\\verdictword{")
    return resolve_byverdict(expand(body, {m.name: m.tex for m in macros}))


def _kind(clause: str) -> str | None:
    text = " ".join(clause.lower().split())
    for kind, phrases in (("undecided", UNDECIDED), ("failure", FAILURE), ("success", SUCCESS)):
        hit = [p for p in phrases if p in text]
        if hit:
            return kind
        for p in phrases:
            text = text.replace(p, " ")
    return None


def contradictions(text: str) -> list:
    """Clauses whose outcome phrase contradicts the verdict tags right after them.

    A clause runs from the end of the previous sentence (a full stop, semicolon or blank line)
    or the previous verdict tag up to a group of tags separated only by punctuation; the
    first outcome phrase found decides its kind. Returns one line per contradiction."""
    out, tags = [], list(_TAG.finditer(text))
    i = 0
    while i < len(tags):
        j = i
        while j + 1 < len(tags) and re.fullmatch(r"[\s,;()]*", text[tags[j].end():tags[j + 1].start()]):
            j += 1
        start = tags[i - 1].end() if i else 0
        bounds = [m.end() for m in re.finditer(r"(\.\s|;|\n\s*\n)", text[start:tags[i].start()])]
        clause = text[start + (bounds[-1] if bounds else 0):tags[i].start()]
        kind = _kind(clause)
        for tag in tags[i:j + 1]:
            if kind is not None and kind not in _ALLOWED[tag.group(1)]:
                out.append(f"{tag.group(1)} after a {kind} phrase: …{' '.join(clause.split())[-160:]}")
        i = j + 1
    return out
