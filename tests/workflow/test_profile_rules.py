"""profiles/slurm/profile.yaml names only rules the workflow has, and groups every computing rule."""
import re
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]


def workflow_rules() -> set:
    """Rule names of workflow/ (``rule x:`` or its ``name: "y"``)."""
    names = set()
    for f in [ROOT / "workflow" / "Snakefile", *sorted((ROOT / "workflow" / "rules").glob("*.smk"))]:
        for block in re.split(r"(?m)^(?=rule )", f.read_text()):
            m = re.match(r"rule (\w+):", block)
            if m:
                alias = re.search(r'^\s+name:\s*"([^"]+)"', block, re.M)
                names.add(alias.group(1) if alias else m.group(1))
    return names


def test_profile_names_existing_rules():
    prof = yaml.safe_load((ROOT / "profiles" / "slurm" / "profile.yaml").read_text())
    rules = workflow_rules()
    grouped = {g.split("=")[0] for g in prof["groups"]}
    named = grouped | set(prof["set-resources"]) | set(prof.get("set-threads", {}))
    assert named <= rules, f"profile names unknown rules: {sorted(named - rules)}"
    # every rule with a benchmark file except the targets and the speed stage runs in a group
    assert {"beta_job", "contact_job", "membranes_reference", "dag_benchmarks"} <= grouped
    comps = {c.split("=")[0] for c in prof["group-components"]}
    assert comps <= {g.split("=")[1] for g in prof["groups"]}
