"""The elastic scene's ledger claims (study/claims/elastic.py) from the elastic tables."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table, register_user_spaces, write_claims  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.study.claims.elastic import elastic_claims, hertz_claims, patch_claims  # noqa: E402

inp = snakemake.input  # noqa: F821
table = pd.concat([elastic_claims(read_table(inp.beta, "elastic_beta"), read_table(inp.sweep, "elastic_beta"),
                                  snakemake.params.cfg),  # noqa: F821
                   patch_claims(read_table(inp.patch, "elastic_patch")),
                   hertz_claims(read_table(inp.hertz, "elastic_hertz"))], ignore_index=True)
write_claims(snakemake.output[0], table)  # noqa: F821
