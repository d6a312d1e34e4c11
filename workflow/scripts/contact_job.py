"""One contact job: every configured case on one (scene, family, k, N), structured reference."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.scenes import scene as make_scene  # noqa: E402
from infsup_contact.study.contact_rows import contact_row, reference_solution  # noqa: E402

wc, cc = snakemake.wildcards, snakemake.params.cc  # noqa: F821
k, n = int(wc.k), int(wc.n)
spec = cc["scenes"][wc.scene]
kind, params = spec["kind"], {key: v for key, v in spec.items() if key not in ("kind", "N")}
c1, c2 = cc["c"]
ref = None
if kind == "membranes":
    ref = reference_solution(make_scene(kind, c1=c1, c2=c2, **params), k, cc["reference_N"])
rows = [contact_row(kind, case, k, wc.family, n, n, c1, c2, reference=ref,
                    scene_params=params, time_floor=False)
        for case, klist in cc["cases"].items() if k in klist]
frame = pd.DataFrame(rows).assign(scene=wc.scene, scene_kind=kind)
timing = [c for c in frame.columns if c.startswith("t_")]
write_csv_atomic(snakemake.output[0], add_provenance(frame.drop(columns=timing), cc))  # noqa: F821
print(frame[["case", "energy_error", "iterations", *timing]].to_string(), file=sys.stderr)
