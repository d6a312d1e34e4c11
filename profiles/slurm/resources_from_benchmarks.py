"""Per-rule Slurm resources from Snakemake's benchmark files (how profiles/slurm's were set).

    python profiles/slurm/resources_from_benchmarks.py [results/benchmarks/rules]

reads every ``benchmark:`` TSV under the directory (one per job: ``RULE.tsv`` or
``RULE/WILDCARDS.tsv``), takes per rule the largest max RSS and wall time over its jobs and
prints ``set-resources`` entries with the margin used in profiles/slurm/profile.yaml:

* mem_mb  = 1.5 × max RSS + 500 MB (the two Snakemake processes around each Slurm job),
  rounded up to 100 MB, at least 1000;
* runtime = 3 × max wall time, rounded up to whole minutes, at least 10 (Slurm minutes).

Run it after a full-config run (``snakemake reproduce-all``) on hardware like the cluster's.
"""
import csv
import math
import sys
from pathlib import Path

MEM_FACTOR, MEM_OVERHEAD_MB, MEM_MIN_MB = 1.5, 500, 1000
TIME_FACTOR, TIME_MIN_MIN = 3, 10


def measured(root: Path):
    """rule → (jobs, max RSS in MB, max wall seconds) over the benchmark files under root."""
    per_rule = {}
    for tsv in sorted(root.rglob("*.tsv")):
        rule = tsv.stem if tsv.parent == root else tsv.relative_to(root).parts[0]
        with tsv.open() as fh:
            rows = list(csv.DictReader(fh, delimiter="\t"))
        if not rows:
            raise SystemExit(f"error: {tsv} has no measurement row")
        rss = max(float(r["max_rss"]) if r["max_rss"] not in ("", "NA", "-") else 0.0 for r in rows)
        secs = max(float(r["s"]) for r in rows)
        n, r0, s0 = per_rule.get(rule, (0, 0.0, 0.0))
        per_rule[rule] = (n + 1, max(r0, rss), max(s0, secs))
    return per_rule


def resources(rss_mb: float, seconds: float):
    mem = max(MEM_MIN_MB, math.ceil((MEM_FACTOR * rss_mb + MEM_OVERHEAD_MB) / 100) * 100)
    runtime = max(TIME_MIN_MIN, math.ceil(TIME_FACTOR * seconds / 60))
    return mem, runtime


def main(argv):
    root = Path(argv[1] if len(argv) > 1 else "results/benchmarks/rules")
    if not root.is_dir():
        raise SystemExit(f"error: {root} is not a directory of benchmark files (run the workflow first)")
    per_rule = measured(root)
    if not per_rule:
        raise SystemExit(f"error: no benchmark files under {root}")
    print("set-resources:")
    for rule, (n, rss, secs) in sorted(per_rule.items()):
        mem, runtime = resources(rss, secs)
        print(f"  {rule}:  # {n} job(s): max RSS {rss:.0f} MB, max wall {secs:.1f} s")
        print(f"    mem_mb: {mem}")
        print(f"    runtime: {runtime}")


if __name__ == "__main__":
    main(sys.argv)
