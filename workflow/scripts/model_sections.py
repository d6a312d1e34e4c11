"""results/paper/model_sections.tex (rule model_sections): one \\input per generated model
subsection (report/sections/model_section.py), written atomically. A script, not a `run:` block: a `run:`
job executes inside Snakemake's own process, and its imports held the scheduler."""
from infsup_contact.io import write_atomic
from infsup_contact.report.sections.model_section import sections_index_tex

write_atomic(snakemake.output[0], sections_index_tex(snakemake.params.names))  # noqa: F821
