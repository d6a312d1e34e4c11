"""Fail unless the ledgers of every core type that ran have byte-identical `verdict` columns;
write their verdicts side by side (results/machines/verdicts.csv) and say which were skipped."""
import json
import sys

import pandas as pd

sys.path.insert(0, "workflow/scripts")
from _glue import fail, log_to, read_table  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
runs = [json.loads(open(p).read()) for p in snakemake.input]  # noqa: F821
ran = [r for r in runs if r["ran"]]
for r in runs:
    if not r["ran"]:
        print(f"verify-machines: {r['core']} skipped: {r['reason']}", file=sys.__stderr__)
ledgers = {r["core"]: read_table(r["ledger"], "claims") for r in ran}
if not ledgers:
    fail("verify-machines: no core type could run on this CPU")
first = next(iter(ledgers.values()))
table = first[["claim_id"]].copy()
for core, ledger in ledgers.items():
    if ledger.claim_id.tolist() != first.claim_id.tolist():
        fail(f"verify-machines: the ledger under {core} lists other claims than under {ran[0]['core']}")
    table[core] = ledger.verdict.to_numpy()
same = table[list(ledgers)].nunique(axis=1) == 1
write_csv_atomic(snakemake.output[0], table.assign(identical=same))  # noqa: F821
columns = {core: "\n".join(ledger.verdict.astype(str)).encode() for core, ledger in ledgers.items()}
if len(set(columns.values())) > 1 or not same.all():
    fail(f"verify-machines: {int((~same).sum())} claim(s) change verdict with the core type: "
         + ", ".join(table.claim_id[~same].head(8)))
kernels = {core: r["openblas"].get("scipy", "?") for core, r in zip(ledgers, ran)}
print(f"verify-machines: {len(first)} verdicts byte-identical under "
      + ", ".join(f"{c} ({k})" for c, k in kernels.items()), file=sys.__stderr__)
