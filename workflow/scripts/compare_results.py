"""Compare two results trees: the ledger and every table, cell by cell, ignoring timing columns.

Usage::

    python workflow/scripts/compare_results.py BASE/results NEW/results [OLD=NEW ...]

Compared: ``claims.csv`` and every ``*.csv`` under ``tables/`` and ``face/`` (the face studies'
tables the ledger is made of), in either tree. Each file is read with the csv module as text,
and every cell is compared character by character, except

* the round-off columns (:data:`infsup_contact.table_schemas.ROUNDOFF_COLUMNS`): columns whose
  numbers are round-off-level by what they measure (the H Gram's error bound, the gap over the
  round-off level, β above a kernel, condition numbers, a passing patch test's errors, ...).
  Their digits follow the route and the machine that computed them while every β_h, kernel and
  verdict stays the same, so each is compared to the error stated there, with its reason;
* columns left out (:data:`IGNORED`): timings, which differ on every run: ``seconds``,
  ``seconds_min``, ``seconds_max``, and the Pareto flags ``pareto_energy`` / ``pareto_lambda``
  of the speed/accuracy table, which are computed from those seconds; provenance, which differs
  on every commit by construction: ``git_commit``, ``config_hash`` (the hash of the config
  section, which changes when keys move while the values a job reads do not) and
  ``package_version``.

The ledger has no round-off column: it states round-off-level quantities against their
tolerance (study/claims/tolerance.py), so it is compared as text, whole.

Prints one line per file: ``identical``, ``identical but round-off columns within their
tolerance`` (per column: the tolerance, the cells that differ, the largest difference and its
ratio to the tolerance), or one line per difference (a numeric cell with its relative
difference); then a summary line. Exit status 0 when the trees agree, 1 when they do not, 2 on
bad usage.
"""
from __future__ import annotations

import csv
import sys
from pathlib import Path

from infsup_contact.table_schemas import ROUNDOFF_COLUMNS

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


def _number(text: str):
    try:
        return float(text)
    except ValueError:
        return None


def _note(name: str, a: str, b: str, ratio) -> str:
    """What a differing cell's line adds: the relative difference of two numbers, and for a
    round-off column beyond its tolerance that tolerance."""
    x, y = _number(a), _number(b)
    parts = []
    if x is not None and y is not None and max(abs(x), abs(y)) not in (0.0, float("inf")):
        parts.append(f"relative {abs(x - y) / max(abs(x), abs(y)):.2g}")
    if ratio is not None:
        parts.append(f"beyond its round-off tolerance {ROUNDOFF_COLUMNS[name].describe()}")
    return f" ({', '.join(parts)})" if parts else ""


def roundoff_within(name: str, a: str, b: str, row_a: dict, row_b: dict):
    """|a − b| / tolerance of a round-off column's cell pair (<= 1: within), or None where the
    column is compared as text (not a round-off column, its rule not holding on the rows, or
    a cell that is not a number)."""
    rule = ROUNDOFF_COLUMNS.get(name)
    x, y = _number(a), _number(b)
    if rule is None or x is None or y is None or not rule.applies(row_a, row_b):
        return None
    diff, tol = abs(x - y), rule.tolerance(x, y, row_a, row_b)
    if diff <= tol:
        return 0.0 if diff == 0 else diff / tol
    return float("inf") if tol == 0 else diff / tol


def compare_file(base: Path, new: Path) -> tuple:
    """(differences as lines of text, round-off columns within their tolerance as
    {column: (cells, max |Δ|, max |Δ|/tolerance)}) of two tables; both empty when identical."""
    (hb, rb), (hn, rn) = read_table(base), read_table(new)
    if hb != hn:
        return [f"columns differ: only in base {sorted(set(hb) - set(hn))}, only in new {sorted(set(hn) - set(hb))}"
                + ("" if set(hb) != set(hn) else " (order differs)")], {}
    out = [] if len(rb) == len(rn) else [f"{len(rb)} rows in base, {len(rn)} in new"]
    cells, within = [], {}
    for i, (a, b) in enumerate(zip(rb, rn)):
        da, db = dict(zip(hb, a)), dict(zip(hb, b))
        for j, name in enumerate(hb):
            if a[j] == b[j]:
                continue
            ratio = roundoff_within(name, a[j], b[j], da, db)
            if ratio is not None and ratio <= 1:
                n, dmax, rmax = within.get(name, (0, 0.0, 0.0))
                within[name] = (n + 1, max(dmax, abs(float(a[j]) - float(b[j]))), max(rmax, ratio))
            else:
                cells.append((i, name, a[j], b[j], _note(name, a[j], b[j], ratio)))
    out += [f"row {i + 2}, {name}: {a!r} -> {b!r}{note}" for i, name, a, b, note in cells[:MAX_CELLS]]
    if len(cells) > MAX_CELLS:
        out.append(f"... {len(cells)} differing cells in all")
    return out, within


def within_text(within: dict) -> str:
    """The round-off columns of a file that agree to their tolerance, as one line."""
    return "; ".join(f"{name} within {ROUNDOFF_COLUMNS[name].describe()} ({n} cells differ, max |Δ| {d:.3g}, "
                     f"max |Δ|/tolerance {r:.2g})" for name, (n, d, r) in sorted(within.items()))


def compare_trees(base: Path, new: Path, moved: dict | None = None, report: dict | None = None) -> list:
    """(relative path, difference) pairs over the ledger and tables of two results trees;
    ``moved`` maps a base path to the new path the same table has in the new tree; ``report``
    (a dict, filled when given) maps each compared file to ``"identical"``, the round-off columns
    within their tolerance (:func:`within_text`) or ``None`` (it differs)."""
    moved = {Path(a): Path(b) for a, b in (moved or {}).items()}
    fb, fn = compared_files(base), compared_files(new)
    pairs = [(p, moved.get(p, p)) for p in sorted(fb)]
    matched = {q for _, q in pairs if q in fn}
    diffs = [(p, "only in base") for p, q in pairs if q not in fn]
    diffs += [(p, "only in new") for p in sorted(fn - matched)]
    for p, q in pairs:
        if q in fn:
            name = p if p == q else Path(f"{p} -> {q}")
            lines, within = compare_file(base / p, new / q)
            diffs += [(name, d) for d in lines]
            if report is not None:
                report[name] = None if lines else (f"identical but round-off columns within their tolerance: "
                                                   f"{within_text(within)}" if within else "identical")
    return diffs


USAGE = ("usage: compare_results.py BASE_RESULTS_DIR NEW_RESULTS_DIR [OLD=NEW ...] (two existing results "
         "trees; OLD=NEW: a table the new tree keeps under another path, relative to the trees)")


def main(argv: list) -> int:
    dirs, moves = [a for a in argv if "=" not in a], [a.split("=", 1) for a in argv if "=" in a]
    if len(dirs) != 2 or not all(Path(a).is_dir() for a in dirs) or any(not a or not b for a, b in moves):
        print(USAGE, file=sys.stderr)
        return 2
    base, new = map(Path, dirs)
    report = {}
    diffs = compare_trees(base, new, dict(moves), report)
    for path, text in report.items():
        if text is not None:
            print(f"{path}: {text}")
    for path, text in diffs:
        print(f"{path}: {text}")
    n = len(compared_files(base) | compared_files(new))
    roundoff = sum(1 for t in report.values() if t and t != "identical")
    print(f"{n} files compared, ignoring columns {', '.join(sorted(IGNORED))}: "
          + (f"identical ({roundoff} with round-off columns within their tolerance)" if not diffs
             else f"{len({p for p, _ in diffs})} differ"))
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
