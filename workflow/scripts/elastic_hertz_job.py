"""One Hertz job (study/contact/hertz.py): the discretization study of one k (every space of infsup.cases,
the meshes of elastic.hertz.N against the reference N_ref), or the modeling study vs Hertz."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.discretization.spaces.registry import REFERENCE_SPACE  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.contact.hertz import discretization_rows, modeling_rows  # noqa: E402

ec = snakemake.params.ec  # noqa: F821
study = snakemake.wildcards.get("study", "profiles")  # noqa: F821
hz, E = ec["hertz"], tuple(ec["E"])
if study == "profiles":
    from infsup_contact.study.contact.hertz import profile_rows

    fig = snakemake.params.fig  # noqa: F821
    rows = profile_rows([tuple(p) for p in fig["pairs"]], fig["N"], hz["R"], hz["d"], ec["nu"], E)
elif study == "modeling":
    rows = modeling_rows(REFERENCE_SPACE, 2, hz["modeling_N"], hz["R"], hz["modeling_d"], ec["nu"], E)
else:
    rows = discretization_rows(snakemake.params.cases, [int(study[1:])], hz["N"], hz["N_ref"], hz["R"], hz["d"], ec["nu"], E)
frame = pd.DataFrame(rows)
frame = frame.drop(columns=["seconds"], errors="ignore")  # timings: benchmark files, not tables
write_csv_atomic(snakemake.output[0], add_provenance(frame, ec))  # noqa: F821
print(frame.to_string(), file=sys.stderr)
