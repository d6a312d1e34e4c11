"""Workflow configuration: bad configs fail at validation, before any job, naming the key.

Every test works in a temporary copy of the workflow (Snakefile, workflow/, config/,
profiles/ and a symlink src -> the package sources) and only dry-runs it (`-n`), except
one up-to-date check in which Snakemake finds nothing to do; no job ever runs.
"""
from __future__ import annotations

import copy
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from helpers.once import once, shared_root

ROOT = Path(__file__).resolve().parents[2]
SNAKEMAKE = Path(sys.prefix) / "bin" / "snakemake"
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
CI_CONFIG = yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())


def copy_workflow(dest: Path) -> Path:
    shutil.copy2(ROOT / "Snakefile", dest / "Snakefile")
    for d in ("workflow", "config", "profiles", "paper", "examples"):
        shutil.copytree(ROOT / d, dest / d, ignore=shutil.ignore_patterns("__pycache__"))
    (dest / "src").symlink_to(ROOT / "src", target_is_directory=True)
    return dest


@pytest.fixture
def workdir(tmp_path: Path) -> Path:
    return copy_workflow(tmp_path)


def snakemake(workdir: Path, *args: str) -> tuple[int, str]:
    assert SNAKEMAKE.is_file(), f"snakemake not installed at {SNAKEMAKE}"
    proc = subprocess.run([str(SNAKEMAKE), *args], cwd=workdir, env=ENV, capture_output=True,
                          text=True, timeout=120)
    return proc.returncode, proc.stdout + proc.stderr


def config_error_lines(out: str) -> list[str]:
    """Snakemake's output without its profile notice: on a bad config, the one error line."""
    return [line for line in out.splitlines()
            if line.strip() and not line.startswith("Using workflow specific profile")]


def produced_tables(workdir: Path) -> list[Path]:
    return sorted((workdir / "results").rglob("*")) if (workdir / "results").exists() else []


# --------------------------------------------------------------- bad configs

def _set(*path, value):
    def mutate(cfg):
        node = cfg
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value
    return mutate


def _rename_top(cfg):
    cfg["infsupp"] = cfg.pop("infsup")


def _typo_top(cfg):
    cfg["infsup_typo"] = copy.deepcopy(cfg["infsup"])


def _typo_nested(cfg):
    cfg["infsup"]["familes"] = cfg["infsup"].pop("families")


# id: (mutation of config/ci.yaml, substrings that must all appear in the output).
# The JSON-schema instance path ("instance['infsup'][...]") names the offending key.
BAD_CONFIGS = {
    "unknown-case": (_set("infsup", "cases", value={"T9": [1]}),
                     ["'T9' was unexpected", "config key infsup.cases"]),
    "unknown-case-added": (_set("infsup", "cases", "T9", value=[2]),
                           ["'T9' was unexpected", "config key infsup.cases"]),
    "k-above-4": (_set("infsup", "cases", value={"T3": [5]}),
                  ["config key infsup.cases.T3", "maximum of 4"]),
    "k-zero": (_set("infsup", "cases", value={"T3": [0]}),
               ["config key infsup.cases.T3", "minimum of 1"]),
    "T4-k1": (_set("infsup", "cases", value={"T4": [1]}),
              ["config key infsup.cases.T4", "k >= 2 (Thm 4)"]),
    "T4-k1-among-valid": (_set("infsup", "cases", "T4", value=[2, 1]),
                          ["config key infsup.cases.T4", "k >= 2 (Thm 4)"]),
    "T5-k1": (_set("infsup", "cases", value={"T5": [1]}),
              ["config key infsup.cases.T5", "k >= 2 (Thm 5)"]),
    "c-zero": (_set("infsup", "c", value=[[0, 1]]), ["config key infsup.c"]),
    "c-negative": (_set("infsup", "c", value=[[1, -2]]), ["config key infsup.c", "-2"]),
    "N-empty": (_set("infsup", "N", value=[]), ["config key infsup.N", "non-empty"]),
    "N-float": (_set("infsup", "N", value=[4, 8.5]),
                ["config key infsup.N", "not of type 'integer'"]),
    "N-whole-float": (_set("infsup", "N", value=[4.0]),  # JSON Schema calls 4.0 an integer
                      ["config key infsup.N", "not of type 'integer'"]),
    "k-whole-float": (_set("infsup", "cases", "T3", value=[2.0]),
                      ["config key infsup.cases.T3", "not of type 'integer'"]),
    "N-duplicate": (_set("infsup", "N", value=[4, 4]),
                    ["config key infsup.N", "non-unique"]),
    "N-string": (_set("infsup", "N", value=["a"]),
                 ["config key infsup.N", "'a' is not of type 'integer'"]),
    "unknown-family": (_set("infsup", "families", value=["structured", "hexagonal"]),
                       ["config key infsup.families", "'hexagonal'"]),
    "unknown-multiplier-mesh": (_set("infsup", "multiplier_meshes", value=["omega3"]),
                                ["config key infsup.multiplier_meshes", "'omega3'"]),
    "unknown-norm": (_set("infsup", "norms", value=["H", "H1"]),
                     ["config key infsup.norms", "'H1'"]),
    "top-level-typo": (_typo_top, ["config key infsup_typo", "'infsup_typo' was unexpected"]),
    "top-level-renamed": (_rename_top, ["config key infsupp", "'infsupp' was unexpected"]),
    "nested-typo": (_typo_nested, ["config key infsup.familes", "'familes' was unexpected"]),
    # issue 17: what used to pass and fail in (or silently spoil) the jobs
    "seed-negative": (_set("infsup", "seed", value=-1), ["config key infsup.seed", "got -1", "integer >= 0"]),
    "reference-coarser": (_set("contact", "reference_N", value=8),   # ci.yaml: membranes N up to 16
                          ["config key contact.reference_N", "got 8", "allowed reference_N >= 32"]),
    "rate-window-9": (_set("contact", "rate_window", value=9),
                      ["config key contact.rate_window", "got 9", "allowed 2..3", "scene membranes"]),
    "c-nan": (_set("contact", "c", value=[float("nan"), 1.0]), ["config key contact.c[0]", "got nan", "finite"]),
    "c-inf": (_set("infsup", "c", value=[[float("inf"), 1.0]]), ["config key infsup.c[0][0]", "got inf"]),
    "nonmatching-equal": (_set("infsup", "nonmatching", value=[[8, 8]]),
                          ["config key infsup.nonmatching[0]", "N1 != N2"]),
    "membranes-with-p": (_set("contact", "scenes", "membranes", "p", value=3.0),
                         ["config key contact.scenes.membranes.p", "allowed the keys kind, N"]),
    "job-larger-than-machine": (_set("infsup", "N", value=[4, 8, 12, 1000000]),
                                ["config key infsup.N", "more than this machine's", "1000000x1000000"]),
}


def checked_as_the_workflow_does(path: Path) -> str:
    """The checks workflow/rules/common.smk runs while Snakemake parses the workflow, on the one
    config file ``--configfile`` names (the Snakefile loads no other then): the file's YAML,
    :func:`check_config` with the workflow's schema and, a local run, the job-memory check. The
    one line a bad config gets (common.smk prints it and exits 1 before any DAG), or "" if accepted."""
    from infsup_contact import resources
    from infsup_contact.config.checks import ConfigError, check_config
    from infsup_contact.config.memory import check_job_memory
    from infsup_contact.config.strict_yaml import check_config_files

    try:
        check_config_files([path])
        check_config(yaml.safe_load(path.read_text()), ROOT / "workflow" / "schemas" / "config.schema.yaml")
        check_job_memory(yaml.safe_load(path.read_text()), resources.total_bytes())
    except ConfigError as err:
        return str(err)
    return ""


def _write_bad(folder: Path, mutate) -> Path:
    cfg = copy.deepcopy(CI_CONFIG)
    mutate(cfg)
    path = folder / "bad.yaml"
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return path


@pytest.mark.parametrize("mutate, needles", list(BAD_CONFIGS.values()), ids=list(BAD_CONFIGS))
def test_bad_config_is_refused_in_one_line_naming_the_key(tmp_path, mutate, needles):
    """In process, the checks the workflow runs (the Snakemake run below shows it prints this line)."""
    line = checked_as_the_workflow_does(_write_bad(tmp_path, mutate))
    assert line.startswith("config key ") and "\n" not in line, line
    for needle in needles:
        assert needle in line, f"{needle!r} not in the message: {line}"


@pytest.mark.parametrize("name", ["T4-k1", "job-larger-than-machine"])
def test_bad_config_fails_before_any_job(workdir, name):
    """The real thing for two of the cases above (a registry rule, the memory check): Snakemake
    exits 1 with exactly the line of the in-process check, before building a DAG or writing a table."""
    expected = checked_as_the_workflow_does(_write_bad(workdir, BAD_CONFIGS[name][0]))

    rc, out = snakemake(workdir, "-n", "reproduce-all", "--cores", "1",
                        "--configfile", "bad.yaml")

    assert rc == 1, f"bad config accepted (exit {rc}):\n{out}"
    # one line naming the key (config.checks.check_config, run by common.smk), nothing else
    assert config_error_lines(out) == [expected], out
    # validation runs while the Snakefile is parsed: no DAG, so no job, was ever built
    assert "Building DAG of jobs" not in out, out
    assert produced_tables(workdir) == [], "results/ written for a bad config"


# --------------------------------------------------------------- good configs

@pytest.fixture
def ci_dry_run(tmp_path_factory) -> tuple[Path, int, str]:
    """`snakemake -n reproduce-all` on config/ci.yaml, once per run for the two tests reading it
    (on whichever xdist workers they land: :func:`helpers.once.once`); the copy it ran in, its
    exit code and output."""
    def run(folder):
        return snakemake(copy_workflow(folder), "-n", "reproduce-all", "--cores", "1",
                         "--configfile", "config/ci.yaml")

    rc, out = once(tmp_path_factory, "ci_dry_run", run)
    return shared_root(tmp_path_factory) / "ci_dry_run", rc, out


def test_ci_config_dry_run_lists_beta_jobs(ci_dry_run):
    workdir, rc, out = ci_dry_run
    assert rc == 0, out
    assert "rule beta_job:" in out
    assert "beta_job" in out.split("Job stats:")[1].split("total")[0]
    assert "This was a dry-run" in out
    assert produced_tables(workdir) == []


def test_fit_window_shrink_is_logged_and_mem_mb_follows_the_estimate(ci_dry_run):
    """ci.yaml has 4 odd N and fit_window 5: accepted, with the shrink said in one line; each
    β/contact job asks for mem_mb from resources.py (larger meshes, more memory)."""
    from infsup_contact import resources

    _, rc, out = ci_dry_run
    assert rc == 0, out
    assert "config key claims.fit_window = 5: the odd-N β series has 4 meshes" in out, out
    assert "shrunk explicitly" in out
    mem = {}
    for block in out.split("\nrule ")[1:]:
        name = block.split(":", 1)[0]
        output = next((line.split(": ", 1)[1] for line in block.splitlines() if line.strip().startswith("output:")), "")
        found = [line for line in block.splitlines() if "mem_mb=" in line]
        if name in ("beta_job", "contact_job") and found:
            mem[output.strip()] = int(found[0].split("mem_mb=")[1].split(",")[0])
    from infsup_contact.study.beta.batches import beta_batches

    ic = CI_CONFIG["infsup"]
    batches = beta_batches(ic)  # a β job is a batch of pairs: it asks for its largest pair's estimate
    small = next(f"results/tables/beta/{b}.csv" for b, v in batches.items()
                 if v["family"] == "structured" and v["k"] == 1 and (4, 4) in v["pairs"])
    big = next(f"results/tables/beta/{b}.csv" for b, v in batches.items()
               if v["family"] == "unstructured" and v["k"] == 2 and (64, 64) in v["pairs"])
    assert mem[small] < mem[big], mem
    assert mem[big] == resources.job_mem_mb(resources.beta_estimate(
        "unstructured", 2, 64, 64, ic["multiplier_meshes"], ic["norms"]))
    cc = CI_CONFIG["contact"]
    ref = "results/tables/contact/membranes_structured_k2.csv"  # every N of the scene: the largest, 16
    assert mem[ref] == resources.job_mem_mb(resources.contact_estimate(
        "structured", 2, 16, 16, cc["reference_N"], len(cc["cases"])))


def test_benchmarks_stage_dry_run(workdir):
    rc, out = snakemake(workdir, "-n", "-p", "benchmarks", "--cores", "1", "--configfile", "config/ci.yaml")
    assert rc == 0, out
    stats = out.split("Job stats:")[1].split("total")[0]
    for rule in ("bench_beta", "bench_contact", "speed_accuracy", "fig7_speed_accuracy"):
        assert rule in stats, f"{rule} not in the benchmarks stage:\n{stats}"
    assert "--peers osqp clarabel" in out and "--eigsh-max-N 16" in out   # config → command


def test_unknown_target_fails_with_snakemake_message(workdir):
    rc, out = snakemake(workdir, "-n", "no-such-target", "--cores", "1",
                        "--configfile", "config/ci.yaml")
    assert rc != 0
    assert "MissingRuleException" in out, out
    assert "No rule to produce no-such-target" in out, out


def test_bare_dry_run_uses_default_profile(workdir):
    rc, out = snakemake(workdir, "-n", "reproduce-all")
    assert rc == 0, out
    assert "Using workflow specific profile profiles/default" in out, out
    assert "beta_job" in out


def test_default_profile_provides_cores(workdir):
    """A dry run needs no cores in Snakemake 9, so check a real (no-op) invocation.

    With its only output present and newer than its inputs, `results/provenance.json`
    is up to date: Snakemake exits 0 with nothing to do if cores come from the profile,
    and refuses to start without the profile.
    """
    out_file = workdir / "results" / "provenance.json"
    out_file.parent.mkdir()
    out_file.write_text("{}\n")
    newest = max(p.stat().st_mtime for p in (ROOT / "src" / "infsup_contact").glob("*.py"))
    stamp = max(time.time(), newest + 1)
    os.utime(out_file, (stamp, stamp))

    rc, out = snakemake(workdir, "results/provenance.json")
    assert rc == 0, out
    assert "Nothing to be done" in out, out
    assert out_file.read_text() == "{}\n", "the provenance job must not have run"

    rc, out = snakemake(workdir, "results/provenance.json", "--workflow-profile", "none")
    assert rc != 0
    # Snakemake words it either way, depending on whether a rule sizes threads by cores
    assert "cores have to be specified" in out or "requires a total number of cores" in out, out


# --------------------------------------------------------------- the CI gate (issue 39, item 5)

# what the ledger is made of on config/ci.yaml (workflow/rules/claims.smk: GATE_STAGES), oldest first
GATE_FILES = ["results/tables/contact.csv",
              *(f"results/tables/{t}.csv" for t in ("beta", "rates", "claims_extra", "elastic_claims", "membranes3d_claims",
                                                   "elastic3d_claims")),
              "results/claims.csv",
              "results/benchmarks/rules/verify_claims.tsv"]  # an earlier gate's benchmark file


def _jobs(out: str) -> set:
    """The rule names of a dry run's job stats."""
    stats = out.split("Job stats:")[1].split("total")[0]
    return {line.split()[0] for line in stats.splitlines()[3:] if line.strip()}


def test_verify_claims_gate_always_runs_and_needs_every_table(workdir):
    """The gate has no output (and no benchmark file): it always runs, and its inputs are the
    ledger and the tables it is made of. Before, with its benchmark file present it could say
    "Nothing to be done" after results/claims.csv was deleted, and with the ledger present a
    rates table removed by a failed rerun was never rebuilt: the stale ledger passed."""
    newest = max(p.stat().st_mtime for p in (ROOT / "src" / "infsup_contact").rglob("*.py"))
    stamp = max(time.time(), newest + 1)
    for i, rel in enumerate(GATE_FILES):
        path = workdir / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("")
        os.utime(path, (stamp + i, stamp + i))
    rc, out = snakemake(workdir, "-n", "verify-claims", "--profile", "profiles/ci")
    assert rc == 0, out
    assert _jobs(out) == {"verify-claims"}, out          # up to date: only the gate, and it does run
    (workdir / "results" / "tables" / "rates.csv").unlink()  # a failed rerun removed it
    rc, out = snakemake(workdir, "-n", "verify-claims", "--profile", "profiles/ci")
    assert rc == 0, out
    assert {"rates", "claims", "verify-claims"} <= _jobs(out), out


def test_face_figures_are_part_of_reproduce_all(ci_dry_run):
    """With the face study in the model table the face section's figures are outputs of a full run:
    one job draws both (face_figures), one small job writes the worst mode."""
    _, rc, out = ci_dry_run
    assert rc == 0, out
    stats = dict(line.split()[:2] for line in out.split("Job stats:")[1].split("total")[0].splitlines()[3:]
                 if len(line.split()) == 2)
    assert stats.get("face_figures") == "1" and stats.get("face_worst_mode") == "1"
    assert "face_hex20_beta" not in stats  # the HEX20 panel reads a model-table beta study's table, if any
    assert "results/figures/fig11_face_studies.pdf" in out and "results/figures/fig10_face_beta.pdf" in out
