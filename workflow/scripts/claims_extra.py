"""Claims that need a small computation of their own: the (3.13) sign and Rem 5.5."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import limit_threads, log_to  # noqa: E402

limit_threads(snakemake.threads)  # noqa: F821
log_to(snakemake.log[0])  # noqa: F821

from infsup_contact.study.claims.membranes import extra_claims  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402

write_csv_atomic(snakemake.output[0], extra_claims(snakemake.params.cfg))  # noqa: F821
