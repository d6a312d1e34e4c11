"""results/benchmarks/elastic_beta.csv: the elastic β_h against the limit (bench/elastic_beta.py)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(1)  # single-thread ratios, as the membranes' benchmarks
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.bench.elastic_beta import bench_elastic_beta  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402

ec = snakemake.params.ec  # noqa: F821
frame = pd.DataFrame(bench_elastic_beta(ec["bench_N"], ec["bench_k"], repeats=3, nu=ec["nu"],
                                        cases=snakemake.params.cases))  # noqa: F821
write_csv_atomic(snakemake.output[0], frame)  # noqa: F821
print(frame.drop(columns=["includes"]).to_string(), file=sys.stderr)
