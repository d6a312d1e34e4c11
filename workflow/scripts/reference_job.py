"""The membranes reference of one (scene, k): structured reference_N × reference_N, degree
k + 1, solved once and written atomically for every contact job of that k."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import limit_threads, log_to  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821

from infsup_contact.study.contact.rows import reference_solution, save_reference  # noqa: E402
from infsup_contact.study.contact.scenes import scene as make_scene  # noqa: E402

wc, cc = snakemake.wildcards, snakemake.params.cc  # noqa: F821
spec = cc["scenes"][wc.scene]
params = {key: v for key, v in spec.items() if key not in ("kind", "N")}
c1, c2 = cc["c"]
ref = reference_solution(make_scene(spec["kind"], c1=c1, c2=c2, **params), int(wc.k), cc["reference_N"])
save_reference(snakemake.output[0], ref)  # noqa: F821
print(f"reference {wc.scene} k={wc.k} N_ref={cc['reference_N']}: dim M = {ref.space.dim}", file=sys.stderr)
