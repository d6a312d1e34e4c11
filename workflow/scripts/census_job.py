"""results/tables/census.csv: the producers table against the config's predictions (study/census.py)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import log_to, read_table  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.census import census_table, prediction_commits  # noqa: E402

cfg = snakemake.params.cfg  # noqa: F821
table = read_table(snakemake.input.table, "producers")  # noqa: F821
claims = read_table(snakemake.input.claims, "claims", allow_empty=True)  # noqa: F821
census = census_table(table, claims, cfg, prediction_commits(cfg["codes"]))
write_csv_atomic(snakemake.output[0], census)  # noqa: F821
print(census[["code", "space", "offset", "verdict", "predicted", "kernel_vs_dim", "claim", "predicted_in"]].to_string(),
      file=sys.stderr)
