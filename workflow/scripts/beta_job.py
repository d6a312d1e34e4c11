"""One β_h job: every case × multiplier mesh × c pair × norm on one mesh pair."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.solvers.infsup import beta_rows  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402

wc, ic = snakemake.wildcards, snakemake.params.ic  # noqa: F821
k, n1, n2 = int(wc.k), int(wc.n1), int(wc.n2)
cases = [c for c, klist in ic["cases"].items() if k in klist]
rows = []
for mm in ic["multiplier_meshes"]:
    for c1, c2 in ic["c"]:
        rows += beta_rows(wc.family, k, n1, n2, cases, mm, c1, c2, ic["norms"],
                          **({"seed": ic["seed"], "alpha": ic["alpha"]} if wc.family == "perturbed" else {}))
frame = pd.DataFrame(rows)
timing = [c for c in frame.columns if c.startswith("t_")]
# timings vary run to run: they live in the benchmark tree, result tables stay deterministic
write_csv_atomic(snakemake.output[0], add_provenance(frame.drop(columns=timing), ic))  # noqa: F821
print(frame[["case", "norm", "multiplier_mesh", "beta", "kernel_dim", *timing]].to_string(), file=sys.stderr)
