"""One face β_h job (rule face_beta_job): every matching N and non-matching pair of one
(element, k) of the 3D model (config ``face``), every case of ``face.cases`` defined for k,
both norms, G_h = trace of Ω2, through the one β batch path of every model
(:func:`infsup_contact.study.beta.batch_rows.beta_batch_rows`). With ``params.l2_only`` (rule
face_l2_job): the matching N of ``face.l2_max_N`` above ``face.max_N``, the L²(Γ) norm alone
(:func:`infsup_contact.config.face.l2_only_sizes`)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import time  # noqa: E402

from infsup_contact.config.face import face_pairs, l2_only_sizes  # noqa: E402
from infsup_contact.discretization.spaces.registry import SPACES, ids_valid_for  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.beta.batch_rows import beta_batch_rows  # noqa: E402
from infsup_contact.study.claims.membranes3d import element_interfaces  # noqa: E402

wc, fc = snakemake.wildcards, snakemake.params.fc  # noqa: F821
k = int(wc.k)
l2_only = bool(snakemake.params.get("l2_only", False))  # noqa: F821
pairs = [(n, n) for n in l2_only_sizes(fc, wc.element)] if l2_only else face_pairs(fc, wc.element)
norms = ("L2",) if l2_only else tuple(fc["norms"])
gamma = element_interfaces(fc["model"], [wc.element])[wc.element]
cases = [c for c in ids_valid_for(k, fc["cases"]) if gamma.builds(SPACES[c])]  # e.g. QUAD9 spaces: rectangles
t0 = time.perf_counter()
frame = beta_batch_rows(fc["model"], "structured", k, pairs, cases, ("omega2",),
                        norms=norms, element=wc.element)
frame = frame.drop(columns=[c for c in frame.columns if c.startswith("t_")])  # timings: benchmark tree
frame.insert(0, "element", wc.element)
frame.insert(0, "model", fc["model"])
write_csv_atomic(snakemake.output[0], add_provenance(frame, fc))  # noqa: F821
print(frame[["case", "N1", "N2", "norm", "beta", "kernel_dim", "structural_kernel_dim"]].to_string(), file=sys.stderr)
print(f"{time.perf_counter() - t0:.1f} s", file=sys.stderr)
