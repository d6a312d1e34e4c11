"""One contact job: every configured case and every N of one (scene, family, k); the
membranes reference is read from its own job's output (rule membranes_reference)."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, fail, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.contact.rows import contact_rows, load_reference  # noqa: E402

wc, cc = snakemake.wildcards, snakemake.params.cc  # noqa: F821
k = int(wc.k)
spec = cc["scenes"][wc.scene]
kind, params = spec["kind"], {key: v for key, v in spec.items() if key not in ("kind", "N")}
c1, c2 = cc["c"]
from infsup_contact.errors import InputError  # noqa: E402

try:  # an .npz of plain arrays, read without pickle: a planted or damaged file is one line
    ref = load_reference(snakemake.input.reference[0]) if snakemake.input.reference else None  # noqa: F821
except InputError as err:
    fail(f"contact_job.py: {err}")
cases = [case for case, klist in cc["cases"].items() if k in klist]
# one mesh pair (meshes, factorized sides, loads) per N, shared by every case
rows = [row for n in snakemake.params.ns  # noqa: F821
        for row in contact_rows(kind, cases, k, wc.family, n, n, c1, c2, reference=ref,
                                scene_params=params, time_floor=False)]
frame = pd.DataFrame(rows).assign(scene=wc.scene, scene_kind=kind)
timing = [c for c in frame.columns if c.startswith("t_")]
write_csv_atomic(snakemake.output[0], add_provenance(frame.drop(columns=timing), cc))  # noqa: F821
print(frame[["case", "energy_error", "iterations", *timing]].to_string(), file=sys.stderr)
