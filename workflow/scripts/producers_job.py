"""The producers stage: results/tables/producers.csv and its claims (study/producers.py)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import limit_threads, log_to  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.progress import reporting  # noqa: E402
from infsup_contact.study.producers import producers_claims, producers_modes, producers_table  # noqa: E402

cfg = snakemake.params.cfg  # noqa: F821
with reporting("producers", delay=0):  # plain lines in the log: each code, space, offset, norm, its time
    table = producers_table(cfg, snakemake.params.workdir)  # noqa: F821
write_csv_atomic(snakemake.output.table, table)  # noqa: F821
claims = producers_claims(table, cfg)
write_csv_atomic(snakemake.output.claims, claims)  # noqa: F821
write_csv_atomic(snakemake.output.modes, producers_modes(table, snakemake.params.workdir))  # noqa: F821
print(table[["producer", "space", "offset", "norm", "status", "verdict", "kernel_levels", "beta_levels"]].to_string(),
      file=sys.stderr)
print(claims[["claim_id", "verdict", "evidence"]].to_string(), file=sys.stderr)
