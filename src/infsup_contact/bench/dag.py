"""Where a workflow run spends its time: per rule, the job count and wall time from the
``benchmark:`` files of the rules (results/benchmarks/rules/RULE.tsv or RULE/JOB.tsv)."""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..io import read_table

DAG_COLUMNS = ["rule", "jobs", "wall_s_sum", "wall_s_max", "cpu_s_sum", "max_rss_mb"]


def rule_of(tsv: Path, root: Path) -> str:
    """``beta_job`` for root/beta_job/structured_k1_0.tsv, ``claims`` for root/claims.tsv."""
    rel = tsv.relative_to(root)
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


def dag_table(root) -> pd.DataFrame:
    """One row per rule (jobs, summed and largest wall time ``s``, summed ``cpu_time``, largest
    ``max_rss``) and a last row ``all`` over every job; sorted by summed wall time."""
    root = Path(root)
    rows = []
    for tsv in sorted(root.rglob("*.tsv")):
        b = read_table(tsv, "rule_benchmark")  # a damaged benchmark file: one line naming it
        rss = pd.to_numeric(b.get("max_rss", pd.Series([float("nan")])), errors="coerce")
        cpu = pd.to_numeric(b.get("cpu_time", pd.Series([float("nan")])), errors="coerce")
        rows.append(dict(rule=rule_of(tsv, root), s=float(b.s.iloc[-1]), cpu=float(cpu.iloc[-1]),
                         rss=float(rss.iloc[-1])))
    jobs = pd.DataFrame(rows, columns=["rule", "s", "cpu", "rss"])
    table = (jobs.groupby("rule").agg(jobs=("s", "size"), wall_s_sum=("s", "sum"), wall_s_max=("s", "max"),
                                      cpu_s_sum=("cpu", "sum"), max_rss_mb=("rss", "max"))
             .reset_index().sort_values("wall_s_sum", ascending=False))
    total = dict(rule="all", jobs=len(jobs), wall_s_sum=jobs.s.sum(), wall_s_max=jobs.s.max(),
                 cpu_s_sum=jobs.cpu.sum(), max_rss_mb=jobs.rss.max())
    return pd.concat([table, pd.DataFrame([total])], ignore_index=True)[DAG_COLUMNS]
