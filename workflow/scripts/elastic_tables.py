"""Join the elastic jobs' tables: results/tables/elastic_beta.csv and elastic_nu_sweep.csv."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
import pandas as pd  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821
for files, target, kind in ((inp.beta, out.beta, "elastic_beta"), (inp.sweep, out.sweep, "elastic_beta"),
                           (inp.hertz, out.hertz, "elastic_hertz")):
    write_csv_atomic(target, pd.concat([read_table(p, kind) for p in files], ignore_index=True))
