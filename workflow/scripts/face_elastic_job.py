"""One job of the elastic face stage (rules/face_elastic.smk, config ``face_elastic``): the β_H
rows of one element (rule face_elastic_beta_job, :func:`infsup_contact.study.face.elastic.beta_frame`)
or the elastic face patch test (rule face_elastic_patch, :func:`~infsup_contact.study.face.elastic.patch_frame`),
written atomically with provenance columns."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import time  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.face.elastic import beta_frame, patch_frame  # noqa: E402

fe, t0 = snakemake.params.fe, time.perf_counter()  # noqa: F821
if snakemake.rule == "face_elastic_patch":  # noqa: F821
    frame = patch_frame(fe)
    shown = ["element", "case", "k", "N1", "N2", "lambda_max_rel_error", "u_max_rel_error", "kernel_dim", "passes"]
else:
    frame = beta_frame(fe, snakemake.wildcards.element)  # noqa: F821
    shown = ["k", "case", "N1", "N2", "nu", "beta", "kernel_dim", "structural_kernel_dim"]
write_csv_atomic(snakemake.output[0], add_provenance(frame, fe))  # noqa: F821
print(frame[shown].to_string(), file=sys.stderr)
print(f"{len(frame)} rows, {time.perf_counter() - t0:.1f} s", file=sys.stderr)
