"""The elastic face stage's ledger claims (study/claims/elastic3d.py) from
results/tables/face_elastic_beta.csv, results/face/elastic_patch.csv and, for the kernel
comparison, the membranes' results/tables/face_beta.csv when the face stage computed it."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table, register_user_spaces, write_claims  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

from infsup_contact.study.claims.membranes3d import element_interfaces  # noqa: E402
from infsup_contact.study.claims.elastic3d import face_elastic_claims  # noqa: E402

inp, fe = snakemake.input, snakemake.params.fe  # noqa: F821
membranes = read_table(inp.membranes[0], "face_beta") if len(inp.membranes) else None
elements = sorted(set(fe["elements"]) | set(fe["patch"]["elements"]))
table = face_elastic_claims(read_table(inp.beta, "face_elastic_beta"), read_table(inp.patch, "face_elastic_patch"),
                            snakemake.params.cfg, fe, element_interfaces(fe["model"], elements), membranes)  # noqa: F821
write_claims(snakemake.output[0], table)  # noqa: F821
