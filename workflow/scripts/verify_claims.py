"""Fail unless every claim of the paper has the verdict the paper predicts; print the ledger."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import read_table  # noqa: E402

ledger = read_table(snakemake.input[0], "claims")  # noqa: F821
checked = ledger[ledger.predicted.isin(["PASS", "FAIL"])]
wrong = checked[checked.verdict != checked.predicted]
with open(snakemake.log[0], "w") as log:  # noqa: F821
    log.write(ledger.to_string() + "\n")
print(ledger[["claim_id", "verdict", "predicted"]].to_string(), file=sys.stderr)
if len(wrong):
    sys.exit(f"{len(wrong)} claim(s) differ from the paper's prediction: {', '.join(wrong.claim_id)}")
print(f"verify-claims: {len(checked)} claims as predicted, {len(ledger) - len(checked)} findings listed",
      file=sys.stderr)
