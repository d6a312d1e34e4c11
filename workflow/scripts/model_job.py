"""One job of a model study (rule model_job): the plan's table for this {model}/{job}
(src/infsup_contact/plans/), written atomically with provenance columns."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, register_user_spaces  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import time  # noqa: E402

from infsup_contact.io import write_csv_atomic  # noqa: E402
from infsup_contact.plans import study_of  # noqa: E402

t0 = time.perf_counter()
job = study_of(snakemake.config, snakemake.wildcards.model).jobs()[snakemake.wildcards.job]  # noqa: F821
frame = job.run()
write_csv_atomic(snakemake.output[0], add_provenance(frame, job.provenance))  # noqa: F821
print(frame[list(job.shown) or list(frame.columns)].to_string(), file=sys.stderr)
print(f"{len(frame)} rows, {time.perf_counter() - t0:.1f} s", file=sys.stderr)
