"""results/figures/census_modes.{pdf,png}: the worst modes of the census' UNSTABLE spaces (report/figures/census.py)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821

from infsup_contact.report.figures.census import plot_census_modes  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821
panels = plot_census_modes(read_table(inp.census, "census"), read_table(inp.modes, "producer_modes", allow_empty=True),
                           out.pdf, out.png)
print(f"census_modes: {len(panels)} panels: {panels}", file=sys.stderr)
