"""The face section's figures, one job: fig10_face_beta (β_h against h per space on hexahedra,
tetrahedra and HEX20 bodies' QUAD8 faces, where their table is an input) and fig11_face_studies (edge dropping: β_h
and cond₂(S) against θ; the transformed duals' β_h against α; the tetrahedra's T4 worst mode on Γ).
Drawn from tables only: src/infsup_contact/report/figures/face.py."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import limit_threads, log_to, read_table, register_user_spaces  # noqa: E402

limit_threads(1)
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

from infsup_contact.report.figures.face import plot_face_beta, plot_face_studies  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821
hex20 = read_table(inp.hex20[0], "model_beta") if inp.hex20 else None  # the HEX20 beta study's table, where run
plot_face_beta(read_table(inp.beta, "face_beta"), out.beta_pdf, out.beta_png, hex20=hex20)
plot_face_studies(read_table(inp.edge, "face_edge"), read_table(inp.alpha, "face_alpha"),
                  read_table(inp.modes, "worst_mode"), out.studies_pdf, out.studies_png)
