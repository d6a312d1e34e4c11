# Config validation and input functions shared by every stage.
import sys
from pathlib import Path

from snakemake.logging import logger
from snakemake.utils import validate

from infsup_contact import resources
from infsup_contact.config.checks import ConfigError, check_config, speed_accuracy_scene
from infsup_contact.config.face import face_pairs, l2_only_sizes
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
REPORT_SOURCES = sorted(str(p) for p in (_PKG / "report").glob("*.py"))
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


# the 3D face stage's outputs (rules/face.smk); none without a `face` config section
FACE = config.get("face")
FACE_BENCH = ["results/benchmarks/face.csv"] if config["benchmarks"].get("face_N") else []
FACE_BETA = [f"results/tables/face/beta_{e}_k{k}.csv" for e in FACE["elements"] for k in FACE["k"]] if FACE else []
# the L²-only rows above face.max_N (face.l2_max_N; rule face_l2_job), where an element has them
FACE_BETA += [f"results/tables/face/l2_{e}_k{k}.csv" for e in FACE["elements"] for k in FACE["k"]
              if l2_only_sizes(FACE, e)] if FACE else []
# the face studies (rules/face_studies.smk): their tables, claims and paper tables
FACE_STUDIES = {s: f"results/face/{s}.csv" for s in ("patch", "alpha", "edge_dropping")} if FACE else {}
FACE_CLAIMS = ["results/tables/face_claims.csv", "results/tables/face_study_claims.csv"] if FACE else []
FACE_PAPER = ["results/paper/face_macros.tex", "results/paper/face_beta_table.tex",
              "results/paper/face_patch_table.tex", "results/paper/face_alpha_table.tex",
              "results/paper/face_edge_table.tex"] if FACE else []
# the 3D elastic bodies on the face (rules/face_elastic.smk); none without a `face_elastic` section.
# Their claims join FACE_CLAIMS (the ledger appends every file of it); their subsection of the
# face section needs the face section (paper/face.tex reads it if present)
FACE_ELASTIC = config.get("face_elastic")
FACE_ELASTIC_BETA = [f"results/tables/face_elastic/beta_{e}.csv" for e in FACE_ELASTIC["elements"]] if FACE_ELASTIC else []
FACE_CLAIMS += ["results/tables/face_elastic_claims.csv"] if FACE_ELASTIC else []
FACE_ELASTIC_PAPER = ["results/paper/face_elastic.tex"] if FACE_ELASTIC and FACE else []
