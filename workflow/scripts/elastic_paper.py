"""results/paper/elastic_*.tex: the elastic section's macros and tables (report/elastic.py),
checked against paper/elastic.tex (every \\elastic… macro and \\input it uses is produced)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import fail, log_to, read_table, register_user_spaces  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821 (the patch macros ask each space for 1 ∈ M_h)

from pathlib import Path  # noqa: E402

from infsup_contact.io import write_atomic  # noqa: E402
from infsup_contact.report.elastic import check_elastic_tex, elastic_paper_files  # noqa: E402
from infsup_contact.report.texformat import PaperTexError  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821
try:
    files = elastic_paper_files(read_table(inp.beta, "elastic_beta"), read_table(inp.sweep, "elastic_beta"),
                                read_table(inp.patch, "elastic_patch"), read_table(inp.hertz, "elastic_hertz"),
                                read_table(inp.claims, "claims"), read_table(inp.speed, "bench"),
                                nu_slope_cases=snakemake.params.nu_slope_cases)  # noqa: F821
    check_elastic_tex(Path(inp.tex).read_text(), files)
except PaperTexError as err:
    fail(f"elastic_paper: {err}")
for key, name in (("macros", "elastic_macros.tex"), ("beta", "elastic_beta_table.tex"),
                  ("patch", "elastic_patch_table.tex"), ("hertz", "elastic_hertz_table.tex")):
    write_atomic(getattr(out, key), files[name])
