"""results/paper/producers.tex: the section "Certifying production codes" (report/sections/producers.py)."""
import sys
from pathlib import Path

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821

from infsup_contact.io import write_atomic  # noqa: E402
from infsup_contact.report.figures.census import unstable_panels  # noqa: E402
from infsup_contact.report.sections.producers import producers_tex  # noqa: E402

inp = snakemake.input  # noqa: F821
table = read_table(inp.table, "producers")
claims = read_table(inp.claims, "claims", allow_empty=True)
paragraphs = {}
for name in table.producer.unique():
    path = Path("examples/producers") / name / "paper.tex"  # the producer's own paragraph
    if path.is_file():
        paragraphs[name] = path.read_text()
census = read_table(inp.census, "census")
panels = unstable_panels(census, read_table(inp.modes, "producer_modes", allow_empty=True))  # those rule census_modes draws
write_atomic(snakemake.output[0], producers_tex(table, claims, paragraphs, census, panels))  # noqa: F821
