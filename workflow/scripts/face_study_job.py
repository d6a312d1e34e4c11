"""One face study table (rules/face_studies.smk, config ``face.<study>``): the 3D patch test
(study/patch/face.py), the α sweep of the transformed dual bases (study/face/alpha.py) or edge
dropping (study/face/edge_dropping.py), chosen by the rule's ``params.study`` among
study/face/tables.py's FACE_STUDIES, written atomically with provenance columns."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import time  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.face.tables import FACE_STUDIES  # noqa: E402

study, fc = snakemake.params.study, snakemake.params.fc  # noqa: F821
t0 = time.perf_counter()
frame = FACE_STUDIES[study](fc)
frame = frame.drop(columns=[c for c in ("seconds",) if c in frame.columns])  # timings: the benchmark tree
write_csv_atomic(snakemake.output[0], add_provenance(frame, fc[study]))  # noqa: F821
print(frame.to_string(), file=sys.stderr)
print(f"{study}: {len(frame)} rows, {time.perf_counter() - t0:.1f} s", file=sys.stderr)
