"""A model study's ledger claims (rule model_claims): the plan's claims from its tables
(src/infsup_contact/plans/), appended to results/claims.csv in the model table's order."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table, register_user_spaces, write_claims  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

from infsup_contact.plans import study_of  # noqa: E402

study = study_of(snakemake.config, snakemake.wildcards.model)  # noqa: F821
frames = {name: read_table(path, kind) for name, (path, kind) in study.claim_inputs().files.items()}
write_claims(snakemake.output[0], study.claims(frames, snakemake.params.cfg))  # noqa: F821
