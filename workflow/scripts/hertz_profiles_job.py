"""Figure data of the elastic Hertz scene (rule elastic_hertz_profiles; study/contact/hertz.py):
λ_h on Γ, stable vs unstable, for the (case, k) pairs and the mesh of figures.elastic_profiles."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.contact.hertz import profile_rows  # noqa: E402

ec, fig = snakemake.params.ec, snakemake.params.fig  # noqa: F821
hz = ec["hertz"]
frame = pd.DataFrame(profile_rows([tuple(p) for p in fig["pairs"]], fig["N"], hz["R"], hz["d"], ec["nu"], tuple(ec["E"])))
frame = frame.drop(columns=["seconds"], errors="ignore")  # timings: benchmark files, not tables
write_csv_atomic(snakemake.output[0], add_provenance(frame, ec))  # noqa: F821
print(frame.to_string(), file=sys.stderr)
