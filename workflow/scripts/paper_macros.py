"""Generate results/paper/*.tex (macros and tables) from the result tables, atomically.

Every number, table and verdict of paper/paper.tex comes from these files
(infsup_contact.report, pure functions). Before writing anything, the script checks that
paper.tex uses only macros and \\input files that the tables provide, so a config without a
case the text discusses fails here with one line instead of deep inside pdflatex.
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table, register_user_spaces  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

from infsup_contact.io import write_atomic  # noqa: E402
from infsup_contact.report.paper import PaperTexError, check_paper, paper_files  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821


def read(path, kind):
    if not Path(path).exists():  # Snakemake checks inputs; this guards direct calls
        sys.exit(f"paper_macros: {path} is missing (it is written by another stage of the workflow)")
    return read_table(path, kind)


try:
    files = paper_files(read(inp.beta, "beta"), read(inp.contact, "contact"), read(inp.rates, "rates"),
                        read(inp.claims, "claims"), read(inp.speed, "speed_accuracy"),
                        read(inp.bench_beta, "bench"), read(inp.bench_contact, "bench"),
                        snakemake.params.cfg, json.loads(Path(inp.provenance).read_text()))  # noqa: F821
    check_paper(Path(inp.tex).read_text(), files)
except PaperTexError as err:
    print(f"paper_macros: {err}", file=sys.stderr)
    sys.__stderr__.write(f"paper_macros: {err}\n")
    sys.exit(1)

for name, text in files.items():
    write_atomic(Path(out.macros).parent / name, text)
    print(f"wrote {name}: {len(text.splitlines())} lines", file=sys.stderr)
