"""The curved segment's figure fig12_curved, one job: β_h against h on the arc and the flat segment,
the patch test's λ error on the arc, the projection's lifted DUAL-ALL mode. Drawn from tables only:
src/infsup_contact/report/figures/curved.py."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import limit_threads, log_to, read_table  # noqa: E402

limit_threads(1)
log_to(snakemake.log[0])  # noqa: F821

from infsup_contact.report.figures.curved import plot_curved  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821
plot_curved(read_table(inp.beta, "arc_beta"), read_table(inp.patch, "arc_patch"), read_table(inp.modes, "worst_mode"),
            out.pdf, out.png)
