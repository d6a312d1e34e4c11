# Config validation and input functions shared by every stage.
from pathlib import Path

from snakemake.utils import validate

from infsup_contact.discretization.registry import SPACES



def _check_before_schema(cfg):
    """Errors whose reason the schema cannot print; each names its key and the rule."""
    ints = {}
    for stage in ("infsup", "contact"):
        sc = cfg.get(stage) or {}
        cases = sc.get("cases") or {}
        unknown = [c for c in cases if c not in SPACES] if isinstance(cases, dict) else []
        if unknown:
            raise ValueError(f"config key {stage}.cases: {unknown[0]!r} was unexpected; expected registered "
                             f"spaces: {', '.join(SPACES)}")
        for case, spec in SPACES.items():  # degrees each space allows (k < 1: the schema says it)
            ks = cases.get(case) or []
            if isinstance(ks, list) and any(isinstance(k, (int, float)) and 1 <= k < spec.min_k for k in ks):
                raise ValueError(f"config key {stage}.cases.{case}: {case} needs k >= {spec.min_k} "
                                 f"({spec.paper_ref}); got {ks}")
        ints[f"{stage}.N"] = sc.get("N") or []
        ints.update({f"{stage}.cases.{c}": v for c, v in cases.items() if isinstance(v, list)})
    pairs = (cfg.get("infsup") or {}).get("nonmatching") or []
    ints["infsup.nonmatching"] = [v for p in pairs if isinstance(p, list) for v in p]
    for key, values in ints.items():
        bad = [v for v in values if isinstance(v, float) or isinstance(v, bool)]
        if bad:
            raise ValueError(f"config key {key}: expected integers, got {bad}")


def _load_user_spaces(cfg):
    """Register the user-defined spaces (config key ``spaces``) before any case key is checked."""
    from infsup_contact.discretization.user_spaces import load_user_space
    from infsup_contact.errors import InputError

    refs = cfg.get("spaces") or []
    if not isinstance(refs, list) or not all(isinstance(r, str) for r in refs):
        raise ValueError(f"config key spaces: expected a list of FILE.py:FUNC or module:FUNC strings; got {refs!r}")
    for i, ref in enumerate(refs):
        try:
            load_user_space(ref)
        except InputError as err:
            raise ValueError(f"config key spaces[{i}]: {err}") from None
    return [r.rpartition(":")[0] for r in refs if r.rpartition(":")[0].endswith(".py")]


USER_SPACE_FILES = _load_user_spaces(config)
_check_before_schema(config)
validate(config, schema="../schemas/config.schema.yaml")

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
