"""The CI gate: fail unless the ledger is there, built from the current, valid tables, and every
claim of the paper has the verdict the paper predicts (study/claims/gate.py); print the ledger."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import fail  # noqa: E402

from infsup_contact.io import TableError  # noqa: E402
from infsup_contact.study.claims.gate import GateError, gate  # noqa: E402

try:
    ledger, summary = gate(snakemake.input.ledger, snakemake.params.stages)  # noqa: F821
except (GateError, TableError) as err:
    with open(snakemake.log[0], "w") as log:  # noqa: F821
        log.write(f"{err}\n")
    fail(f"verify-claims: {err}")
with open(snakemake.log[0], "w") as log:  # noqa: F821
    log.write(ledger.to_string() + "\n")
print(ledger[["claim_id", "verdict", "predicted"]].to_string(), file=sys.stderr)
print(summary, file=sys.stderr)
