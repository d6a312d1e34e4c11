"""One face study table (rules/face_studies.smk, config ``face.<study>``): the 3D patch test
(study/face_patch.py), the α sweep of the transformed dual bases (study/face_alpha.py) or edge
dropping (study/edge_dropping.py), chosen by the rule's ``params.study``; the pure table
function of that module, written atomically with provenance columns."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import time  # noqa: E402

import pandas as pd  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402

study, fc = snakemake.params.study, snakemake.params.fc  # noqa: F821
sc = fc[study]
t0 = time.perf_counter()
if study == "patch":
    from infsup_contact.study.face_patch import face_patch_table

    frame = pd.DataFrame(face_patch_table(fc["cases"], sc["k"], [tuple(p) for p in sc["pairs"]], sc["elements"],
                                          fc["model"]))
elif study == "alpha":
    from infsup_contact.study.face_alpha import sweep

    frame = pd.DataFrame(sweep(tuple(sc["N"]), tuple(sc["alphas"]), tuple(sc["elements"]), norms=tuple(fc["norms"]),
                               model=fc["model"]))
elif study == "edge_dropping":
    from infsup_contact.study.edge_dropping import COLUMNS, edge_table

    frame = pd.DataFrame(edge_table(tuple(sc["k"]), tuple(sc["N"]), tuple(sc["theta"]), cases=fc["cases"],
                                  n2_factor=sc["n2_factor"]))
    frame = frame[[c for c in COLUMNS if c in frame.columns]].assign(fit_theta_max=sc["fit_theta_max"])
else:
    raise SystemExit(f"face_study_job: unknown study {study!r} (patch, alpha, edge_dropping)")
frame = frame.drop(columns=[c for c in ("seconds",) if c in frame.columns])  # timings: the benchmark tree
write_csv_atomic(snakemake.output[0], add_provenance(frame, sc))  # noqa: F821
print(frame.to_string(), file=sys.stderr)
print(f"{study}: {len(frame)} rows, {time.perf_counter() - t0:.1f} s", file=sys.stderr)
