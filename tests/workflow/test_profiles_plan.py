"""Every profile plans every user-facing target: ``snakemake -n`` resolves the DAG, the rules'
resources and the Slurm profile's group resources without an error.

Snakemake merges the resources of a group's jobs when it plans them (``GroupResources.
basic_layered``, reached by a plain ``-n``; not by ``-n --quiet``, which skips the job listing):
a string resource such as ``slurm_extra`` must then be the same for every job of the group, a
rule without it counting as 0. ``profiles/slurm`` once grouped ``elastic_bench`` (``slurm_extra:
--exclusive``) into ``report`` and every ``snakemake -n reproduce-all --profile profiles/slurm``
failed with "Resource slurm_extra is a string but not all jobs in group require the same value".
The static test below makes that impossible by construction; the dry runs check the whole plan.
"""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent
PROFILES = sorted(p.name for p in (ROOT / "profiles").iterdir() if (p / "profile.yaml").exists())
TARGETS = ("reproduce-all", "verify-claims", "paper", "verify-machines")
"""The targets README and docs/workflow.md tell a user to run."""


def _slurm_profile() -> dict:
    return yaml.safe_load((ROOT / "profiles" / "slurm" / "profile.yaml").read_text())


def _groups(prof: dict) -> dict:
    """Group name → its member rules."""
    groups: dict = {}
    for entry in prof.get("groups", []):
        rule, group = entry.split("=")
        groups.setdefault(group.strip(), []).append(rule.strip())
    return groups


def test_profiles_found():
    assert {"default", "ci", "slurm"} <= set(PROFILES)


def test_group_members_agree_on_every_string_resource():
    prof = _slurm_profile()
    per_rule = prof.get("set-resources", {})
    for group, members in _groups(prof).items():
        keys = {key for rule in members for key, value in (per_rule.get(rule) or {}).items()
                if isinstance(value, str)}
        for key in sorted(keys):
            # Snakemake counts a member without the resource as 0, which differs from any string
            values = {rule: (per_rule.get(rule) or {}).get(key, 0) for rule in members}
            assert len(set(values.values())) == 1, (
                f"group {group!r}: its rules ask for different {key}: {values}")


def test_exclusive_rules_are_in_no_group():
    # --exclusive (the node to itself, one core: set-threads) is a property of one timed job; in a
    # group it would either break the group's resource merge or make every member exclusive
    prof = _slurm_profile()
    grouped = {rule for members in _groups(prof).values() for rule in members}
    exclusive = {rule for rule, res in prof.get("set-resources", {}).items()
                 if "--exclusive" in str((res or {}).get("slurm_extra", ""))}
    assert exclusive, "the speed stage is expected to ask for --exclusive"
    assert not exclusive & grouped, f"rules with --exclusive in a group: {sorted(exclusive & grouped)}"
    assert not set(prof.get("set-threads", {})) & grouped, "a rule with its own threads is in a group"


def _dry_run(profile: str) -> str:
    """``snakemake -n --forceall`` of every target at once (as from a clean clone: every job planned)."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env["PATH"] = f"{BIN}:{env.get('PATH', '')}"
    run = subprocess.run([str(BIN / "snakemake"), "-n", "--forceall", "--nolock", *TARGETS,
                          "--profile", f"profiles/{profile}"],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    out = run.stdout + run.stderr
    assert run.returncode == 0, f"snakemake -n {' '.join(TARGETS)} --profile profiles/{profile}:\n{out[-3000:]}"
    return out


def _job_counts(out: str) -> dict:
    """Rule → job count of the dry run's job table."""
    table = out.split("Job stats:", 1)[1]
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"^(\S+)\s+(\d+)\s*$", table, re.M)}


@pytest.mark.slow
@pytest.mark.parametrize("profile", PROFILES)
def test_every_target_plans(profile):
    # One process per profile plans the union of the targets: each target's DAG is part of it
    # (same jobs, same edges) and a string resource consistent on a group's jobs is consistent
    # on any subset of them (the static test above covers any grouping of those jobs); one
    # planning is ~4 s of CPU, 12 separate ones would be ~45 s.
    out = _dry_run(profile)
    counts = _job_counts(out)
    for target in TARGETS:
        assert counts.get(target) == 1, f"{target} not planned under profiles/{profile}"
    if profile == "slurm":
        assert "slurm_extra=--exclusive" in out  # the profile's set-resources were applied
    if profile == "default":
        # docs/workflow.md ("Running on a cluster", Grouping) states the full study's batch counts
        doc = (ROOT / "docs" / "workflow.md").read_text()
        m = re.search(r"the (\d+) β_h batches and (\d+) contact jobs \(\+ (\d+) membranes references\)", doc)
        assert m, "docs/workflow.md no longer states the full study's batch counts"
        stated = tuple(int(x) for x in m.groups())
        planned = (counts["beta_job"], counts["contact_job"], counts["membranes_reference"])
        assert stated == planned, f"docs/workflow.md says {stated} (β batches, contact, references), the DAG has {planned}"
