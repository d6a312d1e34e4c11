"""The code blocks of README.md and docs/*.md, and the commands in them (tests/docs/).

A fenced block may be preceded by an HTML comment saying how it is checked (docs/testing.md,
"Docs that are true by construction"):

* no comment: it runs (a ``bash`` block's ``infsup-contact`` commands in this process, a
  ``python`` block with the page's earlier python blocks, like a notebook);
* ``<!-- slow -->``: its commands are validated as a real run validates them first (the parser
  and the subcommand's checks through ``--dry-run``; a study module's parser and checks), its
  python compiled and its imports resolved; nothing is computed;
* ``<!-- synopsis -->``: a usage template (``[--flag a|b]``, ``ID``, ``...``): every flag must be
  one of its subcommand's and every listed value one of the flag's choices.
"""
from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
MARKS = ("slow", "synopsis")
_FENCE = re.compile(r"^```(\w*)\s*$")
_MARK = re.compile(r"^<!--\s*(\w+)\b.*-->\s*$")


@dataclass(frozen=True)
class Block:
    page: Path
    line: int  # of the opening fence, 1-based
    lang: str
    text: str
    mark: str | None  # None (runs), "slow" or "synopsis"

    @property
    def id(self) -> str:
        return f"{self.page.name}:{self.line}"


def blocks(page: Path) -> list[Block]:
    """The fenced blocks of ``page`` with the mark on the line before each (if any)."""
    out, lines = [], page.read_text(encoding="utf-8").splitlines()
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        j = i + 1
        while not lines[j].startswith("```"):
            j += 1
        before = lines[i - 1].strip() if i else ""
        mark = _MARK.match(before)
        out.append(Block(page, i + 1, m.group(1), "\n".join(lines[i + 1:j]), mark.group(1) if mark else None))
        i = j + 1
    return out


def all_blocks(lang: str | None = None) -> list[Block]:
    return [b for p in PAGES for b in blocks(p) if lang is None or b.lang == lang]


@dataclass(frozen=True)
class Command:
    argv: tuple  # the words after the program: infsup-contact / python / snakemake / make
    program: str
    output: tuple  # the lines a `$ ` prompt block shows after the command


_OPERATORS = {"|", "||", "&&", ";"}
_ALT = "\x00"
_REDIRECTS = {">", ">>", "<", "2>", "&>"}


def logical_lines(text: str) -> list[tuple[str, list[str]]]:
    """(command line, output lines): backslash continuations joined; in a block with ``$ `` prompts
    only the prompted lines are commands and the others their output."""
    joined, acc = [], ""
    for raw in text.splitlines():
        if raw.rstrip().endswith("\\"):
            acc += raw.rstrip()[:-1] + " "
            continue
        joined.append(acc + raw)
        acc = ""
    prompts = any(line.startswith("$ ") for line in joined)
    out: list[tuple[str, list[str]]] = []
    for line in joined:
        if prompts and not line.startswith("$ "):
            if out and line.strip():
                out[-1][1].append(line)
            continue
        line = line[2:] if prompts else line
        if line.strip() and not line.lstrip().startswith("#"):
            out.append((line, []))
    return out


def commands(block: Block) -> list[Command]:
    """The simple commands of a bash block (pipes, ``||``, redirections split off)."""
    found = []
    for line, output in logical_lines(block.text):
        if block.mark == "synopsis":  # a template: whitespace words, comment dropped
            words = line.split("  #")[0].split()
            found.append(Command(tuple(words[1:]), words[0], tuple(output)))
            continue
        # an alternative inside an optional group, [--element hex|tet], is not a pipe
        line = re.sub(r"\[[^\[\]]*\]", lambda m: m.group(0).replace("|", _ALT), line)
        lex = shlex.shlex(line, posix=True, punctuation_chars=True)
        lex.whitespace_split, lex.commenters = True, "#"
        words, segment, skip = [w.replace(_ALT, "|") for w in lex], [], False
        for word in words + [";"]:
            if skip:
                skip = False
            elif word in _REDIRECTS:
                skip = True
            elif word in _OPERATORS:
                if segment:
                    found.append(Command(tuple(segment[1:]), segment[0], tuple(output)))
                segment = []
            else:
                segment.append(word)
    return found


def variants(argv: tuple) -> list[list[str]]:
    """A command line with optional ``[...]`` groups: without them, and with them (the first of
    each ``a|b`` alternative); one variant when there is no group."""
    text = " ".join(argv)
    if "[" not in text:
        return [list(argv)]
    bare = text
    while re.search(r"\[[^\[\]]*\]", bare):
        bare = re.sub(r"\[[^\[\]]*\]", " ", bare)
    if "[" in bare or "]" in bare:
        raise ValueError(f"unbalanced [ ] in {text!r}")
    full = re.sub(r"(\S+)\|\S+", r"\1", text.replace("[", " ").replace("]", " "))
    return [bare.split(), full.split()]
