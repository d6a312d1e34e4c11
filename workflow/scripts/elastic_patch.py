"""The contact patch test of the elastic pair (study/patch/segment.py): every space of infsup.cases
defined for each k of elastic.patch_k, every pair of elastic.patch_pairs."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import pandas as pd  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.study.patch.segment import patch_rows  # noqa: E402

ec = snakemake.params.ec  # noqa: F821
frame = pd.DataFrame(patch_rows(snakemake.params.cases, ec["patch_k"], [tuple(p) for p in ec["patch_pairs"]], ec["nu"], tuple(ec["E"])))
timing = frame.pop("seconds")
write_csv_atomic(snakemake.output[0], add_provenance(frame, ec))  # noqa: F821
print(frame.assign(seconds=timing)[["case", "k", "N1", "N2", "lambda_max_rel_error", "u_max_rel_error", "passes",
                                    "seconds"]].to_string(), file=sys.stderr)
