"""The elastic, membranes3d and elastic3d studies are model-table studies like the others, each named
by its model: each reads its scenes from its entry of ``studies`` (no config section of its name), and a
config written with the old top-level sections (``elastic``, ``face``, ``face_elastic``) or the old
study names is refused in one line naming where its keys went."""
import copy
from pathlib import Path

import pytest
import yaml

from infsup_contact.config.checks import ConfigError, check_config
from infsup_contact.plans import model_table, scenes, scenes_of, study_of

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
WINGS = ("elastic", "membranes3d", "elastic3d")
OLD_NAMES = {"elastic": "elastic", "face": "membranes3d", "face_elastic": "elastic3d"}
"""A wing's name before it took its model's → its name now."""

pytestmark = pytest.mark.usefixtures("registry_as_found")  # tests/conftest.py


def _ci():
    return yaml.safe_load((ROOT / "config" / "ci.yaml").read_text())


@pytest.mark.parametrize("old, name", OLD_NAMES.items())
def test_an_old_top_level_section_is_one_line_naming_where_it_moved(old, name):
    cfg = _ci()
    cfg[old] = scenes(cfg["studies"].pop(name))  # the layout before the model table held the scenes
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    text = str(err.value)
    assert err.value.key == old and "\n" not in text and f"studies.{name}" in text and f"study: {name}" in text


@pytest.mark.parametrize("old, name", [(o, n) for o, n in OLD_NAMES.items() if o != n])
def test_an_old_study_name_is_one_line_naming_the_models_name(old, name):
    """``study: face`` (or ``face_elastic``) under its old entry name: refused before the schema's
    enum, naming the model's name the study goes by now."""
    cfg = _ci()
    cfg["studies"] = {(old if n == name else n): (dict(e, study=old) if n == name else e)
                     for n, e in cfg["studies"].items()}
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    text = str(err.value)
    assert err.value.key == f"studies.{old}.study" and "\n" not in text and repr(name) in text


@pytest.mark.parametrize("name", WINGS)
def test_a_wing_study_reads_its_entry_and_nothing_named_after_it(name):
    """Its scenes are the entry without ``study``; a change in the entry is a change of its jobs."""
    cfg = _ci()
    check_config(copy.deepcopy(cfg), SCHEMA)
    assert name not in cfg and cfg["studies"][name]["study"] == name
    study = study_of(cfg, name)
    assert study.cfg == scenes(cfg["studies"][name]) == scenes_of(cfg, name) and "study" not in study.cfg
    jobs = study.jobs()
    assert jobs and all(job.provenance is study.cfg or job.provenance in study.cfg.values() for job in jobs.values())
    if name != "elastic3d":  # its jobs are per element, every k in one
        cfg["studies"][name]["k"] = [1]
        beta = [j for j in study_of(cfg, name).jobs() if j.startswith("beta_")]
        assert beta and all(j.endswith("_k1") for j in beta)


def test_the_old_table_key_is_one_line_naming_the_new():
    """The table under its old key ``models`` (its entries are studies, not all models: arc,
    cylinder and hex20 name a Γ shape or an element): refused before the schema, naming ``studies``."""
    cfg = _ci()
    cfg["models"] = cfg.pop("studies")
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    text = str(err.value)
    assert err.value.key == "models" and "\n" not in text and "'studies'" in text


def test_the_table_is_the_studies_key_only():
    """Without ``studies`` there is no table (the section fallback is gone), and the schema asks for it."""
    cfg = _ci()
    assert list(model_table(cfg)) == list(cfg["studies"]) and model_table({}) == {}
    del cfg["studies"]
    with pytest.raises(ConfigError) as err:
        check_config(cfg, SCHEMA)
    assert err.value.key == "studies"


def test_the_elastic_study_is_required_and_the_paper_names_are_kept():
    cfg = _ci()
    del cfg["studies"]["elastic"]
    with pytest.raises(ConfigError, match="config key studies: no elastic study"):
        check_config(copy.deepcopy(cfg), SCHEMA)
    cfg = _ci()
    cfg["studies"]["membranes_face"] = cfg["studies"].pop("membranes3d")
    with pytest.raises(ConfigError, match=r"config key studies\.membranes_face\.study"):
        check_config(cfg, SCHEMA)
