"""Compare two results trees: the ledger and every table, cell by cell, ignoring timing columns.

Usage::

    python workflow/scripts/compare_results.py BASE/results NEW/results [OLD=NEW ...]

Compared: ``claims.csv`` and every ``*.csv`` under ``tables/`` and ``face/`` (the face studies'
tables the ledger is made of), in either tree. Each file is
read with the csv module as text, so "identical" means the same characters in every compared
cell, not numbers equal to a tolerance. Columns left out (:data:`IGNORED`):

* timings, which differ on every run: ``seconds``, ``seconds_min``, ``seconds_max``, and the
  Pareto flags ``pareto_energy`` / ``pareto_lambda`` of the speed/accuracy table, which are
  computed from those seconds;
* provenance, which differs on every commit by construction: ``git_commit``,
  ``config_hash`` (the hash of the config section, which changes when keys move while the
  values a job reads do not) and ``package_version``.

Prints one line per difference (file, then what differs) and a summary line; exit status 0
when the trees agree, 1 when they do not, 2 on bad usage.
"""
from __future__ import annotations

import csv
import sys
from pathlib import Path

TIMING = ("seconds", "seconds_min", "seconds_max", "pareto_energy", "pareto_lambda")
PROVENANCE = ("git_commit", "config_hash", "package_version")
IGNORED = frozenset(TIMING + PROVENANCE)
MAX_CELLS = 5
"""Differing cells printed per file (the count is always printed)."""


TABLE_DIRS = ("tables", "face")
"""The folders of a results tree whose ``*.csv`` files are compared (with ``claims.csv``)."""


def compared_files(root: Path) -> set:
    """The ledger and the tables of a results tree, as paths relative to it."""
    files = {p.relative_to(root) for d in TABLE_DIRS for p in (root / d).rglob("*.csv")}
    return files | ({Path("claims.csv")} if (root / "claims.csv").is_file() else set())


def read_table(path: Path) -> tuple:
    """(header, rows) of a csv file with the ignored columns removed; rows as lists of text."""
    with open(path, newline="", encoding="utf-8") as fh:
        lines = list(csv.reader(fh))
    if not lines:
        return [], []
    keep = [i for i, name in enumerate(lines[0]) if name not in IGNORED]
    return [lines[0][i] for i in keep], [[r[i] if i < len(r) else "" for i in keep] for r in lines[1:]]


def compare_file(base: Path, new: Path) -> list:
    """The differences between two tables as lines of text (empty when they agree)."""
    (hb, rb), (hn, rn) = read_table(base), read_table(new)
    if hb != hn:
        return [f"columns differ: only in base {sorted(set(hb) - set(hn))}, only in new {sorted(set(hn) - set(hb))}"
                + ("" if set(hb) != set(hn) else " (order differs)")]
    out = [] if len(rb) == len(rn) else [f"{len(rb)} rows in base, {len(rn)} in new"]
    cells = [(i, name, a[j], b[j]) for i, (a, b) in enumerate(zip(rb, rn))
             for j, name in enumerate(hb) if a[j] != b[j]]
    out += [f"row {i + 2}, {name}: {a!r} -> {b!r}" for i, name, a, b in cells[:MAX_CELLS]]
    if len(cells) > MAX_CELLS:
        out.append(f"... {len(cells)} differing cells in all")
    return out


def compare_trees(base: Path, new: Path, moved: dict | None = None) -> list:
    """(relative path, difference) pairs over the ledger and tables of two results trees;
    ``moved`` maps a base path to the new path the same table has in the new tree."""
    moved = {Path(a): Path(b) for a, b in (moved or {}).items()}
    fb, fn = compared_files(base), compared_files(new)
    pairs = [(p, moved.get(p, p)) for p in sorted(fb)]
    matched = {q for _, q in pairs if q in fn}
    diffs = [(p, "only in base") for p, q in pairs if q not in fn]
    diffs += [(p, "only in new") for p in sorted(fn - matched)]
    for p, q in pairs:
        if q in fn:
            diffs += [(p if p == q else Path(f"{p} -> {q}"), d) for d in compare_file(base / p, new / q)]
    return diffs


USAGE = ("usage: compare_results.py BASE_RESULTS_DIR NEW_RESULTS_DIR [OLD=NEW ...] (two existing results "
         "trees; OLD=NEW: a table the new tree keeps under another path, relative to the trees)")


def main(argv: list) -> int:
    dirs, moves = [a for a in argv if "=" not in a], [a.split("=", 1) for a in argv if "=" in a]
    if len(dirs) != 2 or not all(Path(a).is_dir() for a in dirs) or any(not a or not b for a, b in moves):
        print(USAGE, file=sys.stderr)
        return 2
    base, new = map(Path, dirs)
    diffs = compare_trees(base, new, dict(moves))
    for path, text in diffs:
        print(f"{path}: {text}")
    n = len(compared_files(base) | compared_files(new))
    print(f"{n} files compared, ignoring columns {', '.join(sorted(IGNORED))}: "
          + ("identical" if not diffs else f"{len({p for p, _ in diffs})} differ"))
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
