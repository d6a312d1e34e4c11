"""Fail unless the CI ledgers of every machine path that ran agree byte for byte: the `verdict`
column and the kernel columns of the tables of machines.LEDGER_TABLES (machines.LEDGER_EXACT).
Writes the verdicts side by side (results/machines/verdicts.csv) and one row per compared
column (results/machines/columns.csv), and says which paths were skipped and why."""
import json
import sys
from pathlib import Path

sys.path.insert(0, "workflow/scripts")
from _glue import fail, log_to  # noqa: E402

from infsup_contact.io import read_table_text, write_csv_atomic  # noqa: E402
from infsup_contact.study.machines.ledgers import ledger_differences  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
runs = [json.loads(Path(p).read_text()) for p in snakemake.input]  # noqa: F821
ran = [r for r in runs if r["ran"]]
for r in runs:
    if not r["ran"]:
        print(f"verify-machines: {r['path']} skipped: {r['reason']}", file=sys.__stderr__)
if len(ran) < 2:
    fail(f"verify-machines: {len(ran)} machine path(s) could run on this CPU: nothing to compare")
missing = [r["path"] for r in ran if not Path(r["ledger"], "results/claims.csv").is_file()]
if missing:
    fail(f"verify-machines: no ledger for {', '.join(missing)} (results/machines/*/ledger): rerun machine_ledger")
ledgers = {r["path"]: Path(r["ledger"]) for r in ran}
summary, problems = ledger_differences(ledgers)
claims = {name: read_table_text(folder / "results/claims.csv", "claims") for name, folder in ledgers.items()}
first = next(iter(claims.values()))
table = first[["claim_id"]].copy()
for name, ledger in claims.items():
    if ledger.claim_id.tolist() == first.claim_id.tolist():
        table[name] = ledger.verdict.to_numpy()
same = table[[c for c in table.columns if c != "claim_id"]].nunique(axis=1) == 1
write_csv_atomic(snakemake.output.verdicts, table.assign(identical=same))  # noqa: F821
write_csv_atomic(snakemake.output.columns, summary)  # noqa: F821
for line in problems:
    print(line, file=sys.stderr)
if problems:
    fail(f"verify-machines: {len(problems)} difference(s) between the paths' ledgers (first: {problems[0]}; "
         f"all in {snakemake.log[0]})")  # noqa: F821
evidence = ", ".join(f"{r['path']} (OpenBLAS {r['openblas'].get('scipy', '?')}, MKL {r['mkl'].get('branch', '-')})"
                     for r in ran)
print(f"verify-machines: {len(summary)} columns of {summary.table.nunique()} tables byte-identical (the ledger's "
      f"{len(first)} verdicts and the kernel columns: results/machines/columns.csv) under {evidence}",
      file=sys.__stderr__)
