"""The face studies' ledger claims (study/claims/membranes3d_studies.py) from results/face/*.csv."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table, register_user_spaces, write_claims  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

from infsup_contact.study.claims.membranes3d import element_interfaces  # noqa: E402
from infsup_contact.study.claims.membranes3d_studies import face_study_claims  # noqa: E402

inp, fc = snakemake.input, snakemake.params.fc  # noqa: F821
table = face_study_claims(read_table(inp.patch, "face_patch"), read_table(inp.alpha, "face_alpha"),
                          read_table(inp.edge, "face_edge"), snakemake.params.cfg,  # noqa: F821
                          element_interfaces(fc["model"], fc["patch"]["elements"]),
                          fc["edge_dropping"]["fit_theta_max"])
write_claims(snakemake.output[0], table)  # noqa: F821
