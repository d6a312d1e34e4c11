"""One β_h batch: every pair of the batch × seed × case × multiplier mesh × c pair × norm.

A row gets the series it belongs to (``series``: matching, ratio3-2, plus1, sqrt2, …; a
pair of two series is computed once and written once per series) and, on perturbed
meshes, its ``seed`` (empty on the deterministic families). The rows come from the one
study path of every model (:func:`infsup_contact.study.beta.batch_rows.beta_batch_rows`);
the model is named by the rule (default: the paper's membranes).
"""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

from infsup_contact.discretization.gamma.mesh_series import seeds, series_of_pairs  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.models import DEFAULT_MODEL  # noqa: E402
from infsup_contact.solvers.request import NO_OPTIONS, MeshOptions  # noqa: E402
from infsup_contact.study.beta.batch_rows import beta_batch_rows  # noqa: E402

ic, batch = snakemake.params.ic, snakemake.params.batch  # noqa: F821
model = getattr(snakemake.params, "model", None) or DEFAULT_MODEL.name  # noqa: F821
family, k = batch["family"], int(batch["k"])
perturbed = family == "perturbed"
frame = beta_batch_rows(model, family, k, batch["pairs"], [c for c, klist in ic["cases"].items() if k in klist],
                        ic["multiplier_meshes"], ic["c"], ic["norms"],
                        seeds=seeds(ic) if perturbed else [None], series=series_of_pairs(ic),
                        mesh=MeshOptions(alpha=ic["alpha"]) if perturbed else NO_OPTIONS)
timing = [c for c in frame.columns if c.startswith("t_")]
# timings vary run to run: they live in the benchmark tree, result tables stay deterministic
write_csv_atomic(snakemake.output[0], add_provenance(frame.drop(columns=timing), ic))  # noqa: F821
summary = frame.groupby(["N1", "N2"])[timing].sum()
print(summary.to_string(), file=sys.stderr)
