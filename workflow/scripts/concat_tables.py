"""Concatenate per-job tables (in the given order) into one tidy table, atomically.

Each job table is read through the checked reader (``params.kind``: its schema in
``infsup_contact.table_schemas.SCHEMAS``), so a truncated, emptied or duplicated job table stops the
join with one line naming the file and the row instead of being joined as NaN or garbage."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import fail, log_to, read_table  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
from infsup_contact.io import TableError, concat_tables, write_csv_atomic  # noqa: E402

kind = snakemake.params.kind  # noqa: F821
frames = [read_table(p, kind) for p in snakemake.input if p.endswith(".csv")]  # noqa: F821
try:  # two jobs must not write the same key either
    joined = concat_tables(frames, kind, snakemake.output[0])  # noqa: F821
except TableError as err:
    fail(f"concat_tables.py: {err}")
write_csv_atomic(snakemake.output[0], joined)  # noqa: F821
