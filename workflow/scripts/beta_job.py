"""One β_h batch: every pair of the batch × seed × case × multiplier mesh × c pair × norm.

A row gets the series it belongs to (``series``: matching, ratio3-2, plus1, sqrt2, …; a
pair of two series is computed once and written once per series) and, on perturbed
meshes, its ``seed`` (empty on the deterministic families).
"""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from infsup_contact.discretization.series import seeds, series_of_pairs  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.models.membranes import MEMBRANES  # noqa: E402
from infsup_contact.models.side_cache import SideCache  # noqa: E402
from infsup_contact.solvers.infsup import beta_rows_all  # noqa: E402

ic, batch = snakemake.params.ic, snakemake.params.batch  # noqa: F821
family, k = batch["family"], int(batch["k"])
cases = [c for c, klist in ic["cases"].items() if k in klist]
member = series_of_pairs(ic)
mesh_kwargs = {seed: ({} if seed is None else {"seed": seed, "alpha": ic["alpha"]})
               for seed in (seeds(ic) if family == "perturbed" else [None])}
# pairs of a batch share sides ((16, 16), (17, 16), (24, 16): Ω2's): each is factorized once
sides = SideCache()
for kw in mesh_kwargs.values():
    sides.expect(MEMBRANES, family, k, batch["pairs"], **kw)
frames = []
for n1, n2 in batch["pairs"]:
    for seed, kw in mesh_kwargs.items():
        rows = pd.DataFrame(beta_rows_all(family, k, n1, n2, cases, ic["multiplier_meshes"],
                                          [tuple(c) for c in ic["c"]], ic["norms"],
                                          side_cache=sides, **kw))
        rows["seed"] = np.nan if seed is None else seed
        for name in member[(n1, n2)]:
            frames.append(rows.assign(series=name))
frame = pd.concat(frames, ignore_index=True)
timing = [c for c in frame.columns if c.startswith("t_")]
# timings vary run to run: they live in the benchmark tree, result tables stay deterministic
write_csv_atomic(snakemake.output[0], add_provenance(frame.drop(columns=timing), ic))  # noqa: F821
summary = frame.groupby(["N1", "N2"])[timing].sum()
print(summary.to_string(), file=sys.stderr)
