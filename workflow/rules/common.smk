# Config validation and input functions shared by every stage.
from pathlib import Path

from snakemake.utils import validate

validate(config, schema="../schemas/config.schema.yaml")

# Source edits must trigger reruns: every compute rule lists the package as input.
PACKAGE_SOURCES = sorted(str(p) for p in Path("src/infsup_contact").glob("*.py"))

def beta_jobs():
    """(family, k, N1, N2) of every β_h job: matching pairs N×N plus the non-matching pairs."""
    ic = config["infsup"]
    ks = sorted({k for klist in ic["cases"].values() for k in klist})
    pairs = [(n, n) for n in ic["N"]] + [tuple(p) for p in ic.get("nonmatching", [])]
    return [(f, k, n1, n2) for f in ic["families"] for k in ks for n1, n2 in pairs]


def beta_tables(wildcards=None):
    return [f"results/tables/beta/{f}_k{k}_{n1}x{n2}.csv" for f, k, n1, n2 in beta_jobs()]
