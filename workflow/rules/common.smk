# Config validation and input functions shared by every stage.
import sys
from pathlib import Path

from snakemake.logging import logger
from snakemake.utils import validate

from infsup_contact import resources
from infsup_contact.config_checks import ConfigError, check_config, check_job_memory, memory_notes

# Every check a config gets, in one library function (src/infsup_contact/config_checks.py):
# user spaces, non-finite numbers, the schema, the registry's degrees and the cross-key rules.
# A bad value stops here with ONE line naming the key — before the DAG, so no job starts.
try:
    USER_SPACE_FILES, _notes = check_config(config, Path(workflow.current_basedir.get_path_or_uri(secret_free=True)) / ".." / "schemas" / "config.schema.yaml")
    if workflow.local_exec:  # a job must fit in this machine; a cluster job asks for its mem_mb
        check_job_memory(config, resources.total_bytes())
except ConfigError as _err:
    print(_err, file=sys.stderr)
    sys.exit(1)
validate(config, schema="../schemas/config.schema.yaml")  # cannot fail now; fills the defaults
for _note in _notes + memory_notes(config, resources.available_bytes()):
    logger.info(_note)

# Source edits must trigger reruns: every compute rule lists the package as input, except
# the stages that only draw, typeset or time (report/, bench/: their own rules list them).
_PKG = Path("src/infsup_contact")
PRESENTATION_ONLY = ("report", "bench")
PACKAGE_SOURCES = sorted(str(p) for p in _PKG.rglob("*.py") if p.relative_to(_PKG).parts[0] not in PRESENTATION_ONLY)
PACKAGE_SOURCES += USER_SPACE_FILES  # a user's space is code the results depend on
REPORT_SOURCES = sorted(str(p) for p in (_PKG / "report").glob("*.py"))
BENCH_SOURCES = sorted(str(p) for p in (_PKG / "bench").glob("*.py"))

def beta_pairs():
    """(N1, N2) mesh pairs of the β_h study: matching N×N plus the non-matching pairs."""
    ic = config["infsup"]
    pairs = [(n, n) for n in ic["N"]] + [tuple(p) for p in ic.get("nonmatching", [])]
    return list(dict.fromkeys(pairs))  # a pair listed twice is one job


def beta_jobs():
    """(family, k, N1, N2) of every β_h job."""
    ic = config["infsup"]
    ks = sorted({k for klist in ic["cases"].values() for k in klist})
    return [(f, k, n1, n2) for f in ic["families"] for k in ks for n1, n2 in beta_pairs()]


def beta_tables(wildcards=None):
    return [f"results/tables/beta/{f}_k{k}_{n1}x{n2}.csv" for f, k, n1, n2 in beta_jobs()]


def contact_jobs():
    """(scene, family, k, N) of every contact job."""
    cc = config["contact"]
    ks = sorted({k for klist in cc["cases"].values() for k in klist})
    return [(s, f, k, n) for s, spec in cc["scenes"].items() for f in cc["families"] for k in ks
            for n in spec.get("N", cc["N"])]


def contact_tables(wildcards=None):
    return [f"results/tables/contact/{s}_{f}_k{k}_{n}.csv" for s, f, k, n in contact_jobs()]


def beta_mem_mb(wildcards):
    """mem_mb of a β_h job: the estimate of src/infsup_contact/resources.py (+25 %)."""
    ic = config["infsup"]
    return resources.job_mem_mb(resources.beta_estimate(
        wildcards.family, int(wildcards.k), int(wildcards.n1), int(wildcards.n2),
        ic["multiplier_meshes"], ic["norms"]))


def contact_mem_mb(wildcards):
    """mem_mb of a contact job (with the membranes reference where the scene needs one)."""
    cc = config["contact"]
    kind = cc["scenes"][wildcards.scene]["kind"]
    n = int(wildcards.n)
    return resources.job_mem_mb(resources.contact_estimate(
        kind, wildcards.family, int(wildcards.k), n, n, cc["reference_N"], len(cc["cases"])))
