"""Join the elastic jobs' tables: results/tables/elastic_beta.csv and elastic_nu_sweep.csv."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import fail, log_to, read_table  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
from infsup_contact.io import TableError, concat_tables, write_csv_atomic  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821
for files, target, kind in ((inp.beta, out.beta, "elastic_beta"), (inp.sweep, out.sweep, "elastic_beta"),
                           (inp.hertz, out.hertz, "elastic_hertz")):
    try:  # checked per file, then across files (no key written by two jobs)
        joined = concat_tables([read_table(p, kind) for p in files], kind, target)
    except TableError as err:
        fail(f"elastic_tables.py: {err}")
    write_csv_atomic(target, joined)
