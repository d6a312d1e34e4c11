"""results/paper/face_elastic.tex: the elastic bodies' generated subsection of the face section
(report/face_elastic.py), read by paper/face.tex with \\InputIfFileExists."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import fail, log_to, read_table  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821

from infsup_contact.io import write_atomic  # noqa: E402
from infsup_contact.report.face_elastic import face_elastic_tex  # noqa: E402
from infsup_contact.report.texformat import PaperTexError  # noqa: E402

inp = snakemake.input  # noqa: F821
try:
    text = face_elastic_tex(read_table(inp.beta, "face_elastic_beta"), read_table(inp.patch, "face_elastic_patch"),
                            read_table(inp.claims, "claims"), snakemake.params.fe)  # noqa: F821
except PaperTexError as err:
    fail(f"face_elastic_paper: {err}")
write_atomic(snakemake.output[0], text)  # noqa: F821
