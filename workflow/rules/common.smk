# Config validation and input functions shared by every stage.
import sys
from pathlib import Path

from snakemake.logging import logger
from snakemake.utils import validate

from infsup_contact import resources
from infsup_contact.config.checks import ConfigError, check_config, speed_accuracy_scene
from infsup_contact.plans import claims_path, job_path, model_table, scenes_of, study_of, table_path
from infsup_contact.config.strict_yaml import check_config_files
from infsup_contact.config.memory import check_job_memory, memory_notes
from infsup_contact.discretization.gamma.mesh_series import seeds, series_of_pairs
from infsup_contact.study.beta.batches import beta_batches
from infsup_contact.study.contact.registry import scene_spec

# Every check a config gets, in one library function (src/infsup_contact/config/checks.py):
# user spaces, non-finite numbers, the schema, the registry's degrees and the cross-key rules.
# A bad value stops here with ONE line naming the key — before the DAG, so no job starts.
# First the files themselves (config/strict_yaml.py): duplicate keys, zero-padded numbers and 1e3-as-a-
# string, which Snakemake's YAML 1.1 loader has already turned into other values without a word.
try:
    check_config_files(workflow.configfiles)
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
REPORT_SOURCES = sorted(str(p) for p in (_PKG / "report").rglob("*.py"))  # sections/, figures/ included
BENCH_SOURCES = sorted(str(p) for p in (_PKG / "bench").glob("*.py"))

def beta_pairs():
    """(N1, N2) mesh pairs of the β_h study: every pair of every series (matching, the
    fixed-ratio pairs, the non-matching families), each once (discretization/gamma/mesh_series.py)."""
    return sorted(series_of_pairs(config["infsup"]), key=lambda p: (max(p), p))


# β_h jobs: one per batch of pairs of one (family, k) (study/beta/batches.py: beta_batches)
BETA_BATCHES = beta_batches(config["infsup"])


def beta_tables(wildcards=None):
    return [f"results/tables/beta/{b}.csv" for b in BETA_BATCHES]


def contact_jobs():
    """(scene, family, k) of every contact job (all N of the scene in one job)."""
    cc = config["contact"]
    ks = sorted({k for klist in cc["cases"].values() for k in klist})
    return [(s, f, k) for s in cc["scenes"] for f in cc["families"] for k in ks]


def contact_ns(scene):
    cc = config["contact"]
    return cc["scenes"][scene].get("N", cc["N"])


def contact_tables(wildcards=None):
    return [f"results/tables/contact/{s}_{f}_k{k}.csv" for s, f, k in contact_jobs()]


def contact_job_config(wildcards):
    """What a contact job reads of ``contact``: its scene, the prestress c and the cases; not the
    other scenes nor the fit window, whose change reruns the rates and what follows, never the solves
    (Snakemake reruns a job whose params change; the reference's reference_N reaches a job as its input)."""
    return _contact_subset(wildcards.scene, ("c", "cases"))


def reference_job_config(wildcards):
    """What the reference solve of a scene reads of ``contact``: the scene, c and reference_N."""
    return _contact_subset(wildcards.scene, ("c", "reference_N"))


def speed_accuracy_config(wildcards):
    """What the speed/accuracy benchmark reads of ``contact`` beside its input table: the timed
    scene (a scene kind is not in contact.scenes) and c."""
    return _contact_subset(speed_accuracy_scene(config), ("c",))


def _contact_subset(scene, keys):
    cc = config["contact"]
    return {"scenes": {name: spec for name, spec in cc["scenes"].items() if name == scene},
            **{key: cc[key] for key in keys}}


def contact_reference(wildcards):
    """The reference solve of this k (rule membranes_reference), for a scene measured against one."""
    if not scene_spec(config["contact"]["scenes"][wildcards.scene]["kind"]).needs_reference:
        return []
    return [f"results/references/{wildcards.scene}_k{wildcards.k}.npz"]


def beta_mem_mb(wildcards):
    """mem_mb of a β_h batch: the largest estimate of src/infsup_contact/resources.py (+25 %)
    over its pairs: one pair is computed at a time, next to the side operators kept for later
    pairs of the batch (solvers/side_cache.py); measured RSS 0.50-0.91 of this on the full config."""
    ic, batch = config["infsup"], BETA_BATCHES[wildcards.batch]
    return max(resources.job_mem_mb(resources.beta_estimate(
        batch["family"], batch["k"], n1, n2, ic["multiplier_meshes"], ic["norms"])) for n1, n2 in batch["pairs"])


def contact_mem_mb(wildcards):
    """mem_mb of a contact job: its largest N (the reference is read, not solved, in the job)."""
    cc = config["contact"]
    n_ref = cc["reference_N"] if scene_spec(cc["scenes"][wildcards.scene]["kind"]).needs_reference else None
    n = max(contact_ns(wildcards.scene))
    return resources.job_mem_mb(resources.contact_estimate(
        wildcards.family, int(wildcards.k), n, n, n_ref, len(cc["cases"])))


def reference_mem_mb(wildcards):
    """mem_mb of the membranes reference job (degree k + 1 on reference_N × reference_N)."""
    cc = config["contact"]
    return resources.job_mem_mb(resources.contact_estimate(
        "structured", int(wildcards.k), 1, 1, cc["reference_N"], 1))


# the face benchmark (rules/benchmarks.smk), with benchmarks.face_N
FACE_BENCH = ["results/benchmarks/face.csv"] if config["benchmarks"].get("face_N") else []

# The model table (config key `studies`; src/infsup_contact/plans/): each study by name, the {model}
# wildcard of rules/models.smk (jobs, joined tables), claims.smk (model_claims) and paper.smk (model_paper).
MODEL_TABLE = model_table(config)
MODEL_STUDIES = {name: study_of(config, name) for name in MODEL_TABLE}
# longest first: "elastic3d_beta" is {model}=elastic3d, {table}=beta, never a study "elastic3d_x" + "beta"
MODEL_NAMES_RE = "|".join(sorted(MODEL_STUDIES, key=len, reverse=True)) or "(?!)"
MODEL_TABLE_NAMES_RE = "|".join(sorted({t for s in MODEL_STUDIES.values() for t in s.tables()}, key=len,
                                       reverse=True)) or "(?!)"
MODEL_TABLES = [table_path(m, t) for m, s in MODEL_STUDIES.items() for t in s.tables()]
MODEL_CLAIMS = [claims_path(m) for m in MODEL_STUDIES]  # appended to the ledger in this order
MODEL_PAPER = [f"results/paper/{m}" for m, s in MODEL_STUDIES.items() if s.in_paper]
# the generated model subsections (plans/beta.py) paper/paper.tex reads through model_sections.tex
MODEL_SECTIONS = [m for m, s in MODEL_STUDIES.items() if s.in_paper and s.model_section]
