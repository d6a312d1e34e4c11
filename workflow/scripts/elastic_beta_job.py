"""One elastic β_h job: every mesh pair of a (family, k) (rule elastic_beta_job), or the
ν → 1/2 sweep of one k (rule elastic_sweep_job); H norm, G_h = trace of Ω2."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import time  # noqa: E402

from infsup_contact.discretization.spaces.registry import ids_valid_for  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.beta.elastic import elastic_beta_rows, nu_sweep_rows  # noqa: E402

wc, ec = snakemake.wildcards, snakemake.params.ec  # noqa: F821
k = int(wc.k)
cases = ids_valid_for(k, snakemake.params.cases)  # noqa: F821 (infsup.cases, where defined for k)
t0 = time.perf_counter()
if "family" in wc.keys():
    pairs = [(n, n) for n in ec["N"]] + [tuple(p) for p in ec["nonmatching"]]
    frame = elastic_beta_rows(wc.family, k, list(dict.fromkeys(pairs)), ec["nu"], tuple(ec["E"]), cases=cases)
else:
    frame = nu_sweep_rows(k, ec["N"], ec["nu_sweep"], cases=cases)
write_csv_atomic(snakemake.output[0], add_provenance(frame, ec))  # noqa: F821
print(frame[["case", "N1", "N2", "nu", "beta", "kernel_dim", "beta_membranes"]].to_string(), file=sys.stderr)
print(f"{time.perf_counter() - t0:.1f} s", file=sys.stderr)
