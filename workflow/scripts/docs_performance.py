"""docs/performance.md's tables, generated from results/benchmarks/*.csv (rule ``docs``).

    python workflow/scripts/docs_performance.py docs/performance.md [--root .]

Each table lives between two marker comments naming its source,

    <!-- generated: results/benchmarks/beta.csv -->
    ...
    <!-- end generated -->

each marker a line of its own, and only those blocks are rewritten; every other byte of the page stays as it is. A missing or
damaged benchmark table (read through the package's checked reader, ``io.read_table``), an
unknown source or an unclosed marker is refused with one line on stderr and exit code 2, the
page untouched.
"""
from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path

from infsup_contact.io import TableError, read_table, write_atomic

# a marker is a line of its own (one quoted inside a sentence is text)
BLOCK = re.compile(r"^(<!-- generated: (?P<source>\S+) -->\n)(?P<body>.*?)^(<!-- end generated -->)$", re.S | re.M)
OPEN = re.compile(r"^<!-- generated: \S+ -->$", re.M)
CLOSE = re.compile(r"^<!-- end generated -->$", re.M)

ROUTE_TABLES = {"beta.csv", "contact.csv", "elastic_beta.csv", "face.csv"}
"""Sources written by ``infsup-contact bench`` (``--what beta``, ``contact``, ``face``, ``elastic``): one row per route, k, N."""


class DocsError(ValueError):
    """A page or a source the generator cannot use: one line."""


def number(x) -> str:
    """Three significant digits; an empty cell (NaN) as a dash."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    if isinstance(x, float):
        return f"{x:.3g}"
    return str(x)


def markdown(header: list, rows: list) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(number(v) for v in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def route_table(frame) -> str:
    """Per (what, k, N): the median seconds of ``ours`` and every other route's time over it."""
    routes = list(dict.fromkeys(frame["route"]))
    others = [r for r in routes if r != "ours"]
    header = ["what", "k", "N", "ours (s, median)", *[f"{r} / ours" for r in others]]
    rows = []
    for (what, k, n), group in frame.groupby(["what", "k", "N"], sort=False):
        by_route = group.set_index("route")
        ours = by_route["seconds_median"].get("ours", float("nan"))
        rows.append([what, k, n, float(ours),
                     *[float(by_route["seconds_median"][r] / ours) if r in by_route.index and ours > 0
                       else float("nan") for r in others]])
    return markdown(header, rows)


def dag_table(frame) -> str:
    """Per rule of the last run: jobs, wall and CPU seconds, peak memory (as dag.csv lists them)."""
    columns = ["rule", "jobs", "wall_s_sum", "wall_s_max", "cpu_s_sum", "max_rss_mb"]
    return markdown(columns, frame[columns].itertuples(index=False, name=None))


def estimates_table(frame) -> str:
    """Per documented request: ``--dry-run``'s estimate beside the measured max RSS and CPU time
    (user + sys: a one-thread run's time, not inflated by other work on the machine as its wall
    time is), their ratios, the wall time and the load average around the run."""
    header = ["example", "command", "estimate (MiB)", "max RSS (MiB)", "memory: estimate / measured",
              "estimate (s)", "CPU (s, user+sys)", "time: estimate / CPU", "wall (s)", "load (1 min)"]
    rows = [[r.example, f"`{r.command}`", round(r.est_mib), round(r.rss_mib), float(r.mem_ratio), float(r.est_s),
             float(r.cpu_s), float(r.time_ratio), float(r.wall_s), f"{r.load_before:.1f} → {r.load_after:.1f}"]
            for r in frame.itertuples(index=False)]
    return markdown(header, rows)


def phases_table(frame) -> str:
    """Per (what, element, k, N) and phase: CPU and wall seconds, CPU % (above 100: more than one
    core busy), the phase's share of the run's CPU and how far it raised the peak resident memory,
    as ``bench --phases`` wrote them."""
    header = ["what", "element", "k", "N", "phase", "CPU (s)", "wall (s)", "CPU %", "share of CPU",
              "peak memory added (MiB)"]
    rows = [[r.what, r.element if isinstance(r.element, str) else "", r.k, r.N, r.phase, float(r.cpu_s),
             float(r.wall_s), f"{r.cpu_percent:.0f} %", f"{100 * r.share:.1f} %", round(r.peak_added_mib)]
            for r in frame.itertuples(index=False)]
    return markdown(header, rows)


def render(source: str, root: Path) -> str:
    """The Markdown table of one source file."""
    name = Path(source).name
    if name in ROUTE_TABLES:
        return route_table(read_table(root / source, "bench"))
    if name == "dag.csv":
        return dag_table(read_table(root / source, "dag"))
    if name == "estimates.csv":
        return estimates_table(read_table(root / source, "estimates"))
    if name == "face_phases.csv":
        return phases_table(read_table(root / source, "phases"))
    raise DocsError(f"{source}: no table is generated from this file (known: "
                    f"{', '.join(sorted(ROUTE_TABLES | {'dag.csv', 'estimates.csv', 'face_phases.csv'}))} "
                    "under results/benchmarks/)")


def regenerate(page: str, root: Path) -> str:
    """``page`` with every generated block rewritten from its source under ``root``."""
    opened, closed = len(OPEN.findall(page)), len(CLOSE.findall(page))
    if opened != closed or len(BLOCK.findall(page)) != opened:
        raise DocsError(f"unbalanced markers: {opened} '<!-- generated: … -->' and {closed} "
                        "'<!-- end generated -->' (each block opens and closes once)")
    return BLOCK.sub(lambda m: m.group(1) + render(m.group("source"), root) + m.group(4), page)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("page", help="the Markdown page (docs/performance.md)")
    parser.add_argument("--root", default=".", help="the directory the sources are relative to (default .)")
    args = parser.parse_args(argv)
    try:
        page = Path(args.page).read_text(encoding="utf-8")
        new = regenerate(page, Path(args.root))
    except (DocsError, TableError, OSError) as err:
        print(f"docs_performance: error: {' '.join(str(err).split())}", file=sys.stderr)
        return 2
    if new != page:
        write_atomic(args.page, new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
