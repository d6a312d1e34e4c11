"""results/benchmarks/elastic_beta.csv: the elastic β_h against the limit (``bench --what elastic``,
bench/beta_models.py)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(1)  # single-thread ratios, as the membranes' benchmarks
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.bench import bench_beta, bench_for  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402

ec = snakemake.params.ec  # noqa: F821
# every route repeated 3 times, whatever its time (no budget): the table's repeats column
frame = pd.DataFrame(bench_beta(bench_for("elastic", nu=ec["nu"]), ec["bench_N"], ec["bench_k"], repeats=3,
                                budget=float("inf"), cases=snakemake.params.cases))  # noqa: F821
write_csv_atomic(snakemake.output[0], frame)  # noqa: F821
print(frame.drop(columns=["includes"]).to_string(), file=sys.stderr)
