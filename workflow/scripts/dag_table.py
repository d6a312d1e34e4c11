"""results/benchmarks/dag.csv: per rule, jobs and wall time of this run (benchmark: files)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import fail, log_to  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821

from infsup_contact.bench.dag import dag_table  # noqa: E402
from infsup_contact.io import TableError, write_csv_atomic  # noqa: E402

try:  # a damaged benchmark file: one line naming it
    table = dag_table(snakemake.params.root)  # noqa: F821
except TableError as err:
    fail(f"dag_table.py: {err}")
write_csv_atomic(snakemake.output[0], table)  # noqa: F821
print(table.to_string(), file=sys.stderr)
