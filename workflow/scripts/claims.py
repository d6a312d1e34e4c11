"""Assemble the claims ledger results/claims.csv from the tables."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table, register_user_spaces, write_claims  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

from infsup_contact.study.claims.membranes import ledger  # noqa: E402

inp = snakemake.input  # noqa: F821
table = ledger(read_table(inp.beta, "beta"), read_table(inp.rates, "rates"), read_table(inp.extra, "claims"),
               snakemake.params.cfg, snakemake.params.rate_scene)  # noqa: F821
# the model table's studies' claims (rule model_claims) follow the membranes' ones, in the table's order
import pandas as pd  # noqa: E402

table = pd.concat([table] + [read_table(p, "claims") for p in inp.models]
                  + [read_table(p, "claims", allow_empty=True) for p in inp.producers],  # rules/producers.smk:
                  ignore_index=True)  # no rows where no code has predictions (a not-installed one's are NOT RUN)
write_claims(snakemake.output[0], table)  # noqa: F821
