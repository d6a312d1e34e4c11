"""The 3D face's ledger claims (study/claims/membranes3d.py) from results/tables/face_beta.csv."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table, register_user_spaces, write_claims  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

from infsup_contact.study.claims.membranes3d import element_interfaces, face_claims  # noqa: E402

fc = snakemake.params.fc  # noqa: F821
table = face_claims(read_table(snakemake.input.beta, "face_beta"), snakemake.params.cfg,  # noqa: F821
                    element_interfaces(fc["model"], fc["elements"]))
write_claims(snakemake.output[0], table)  # noqa: F821
