"""Concatenate per-job tables (in the given order) into one tidy table, atomically."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
import pandas as pd  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402

frames = [pd.read_csv(p) for p in snakemake.input if p.endswith(".csv")]  # noqa: F821
write_csv_atomic(snakemake.output[0], pd.concat(frames, ignore_index=True))  # noqa: F821
