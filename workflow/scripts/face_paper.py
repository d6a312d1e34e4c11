"""results/paper/face_*.tex: the face section's macros, β_h table and the three study tables
(report/face.py, report/face_studies.py),
checked against paper/face.tex (every \\face… macro and \\input it uses is produced)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import fail, log_to, read_table  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821

from pathlib import Path  # noqa: E402

from infsup_contact.io import write_atomic  # noqa: E402
from infsup_contact.report.face import check_face_tex, face_paper_files  # noqa: E402
from infsup_contact.report.texformat import PaperTexError  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821
try:
    files = face_paper_files(read_table(inp.beta, "face_beta"), read_table(inp.claims, "claims"),
                             read_table(inp.patch, "face_patch"), read_table(inp.alpha, "face_alpha"),
                             read_table(inp.edge, "face_edge"), read_table(inp.study_claims, "claims"))
    check_face_tex(Path(inp.tex).read_text(), files)
except PaperTexError as err:
    fail(f"face_paper: {err}")
write_atomic(out.macros, files["face_macros.tex"])
write_atomic(out.beta, files["face_beta_table.tex"])
for key in ("patch", "alpha", "edge"):  # the face studies' tables (report/face_studies.py)
    write_atomic(out[key], files[f"face_{key}_table.tex"])
