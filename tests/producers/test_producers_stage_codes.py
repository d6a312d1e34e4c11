"""The producers stage's per-code keys (study/producers.py): a code's own ``offsets`` (DOLFINx
ties matching meshes only), a ``version`` probe for a code without package metadata (Debian's
python3-getfem), and the Γ description (``multipliers``, ``traces``) left out of the L² copies."""
from __future__ import annotations

import yaml

from infsup_contact.study.producers import norm_copy, producers_table
from test_producers_stage import _cfg


def test_a_code_runs_its_own_offsets(tmp_path):
    cfg = _cfg(tmp_path)
    cfg["codes"]["fake"]["offsets"] = [0]
    table = producers_table(cfg, tmp_path / "work")
    assert set(table.offset) == {0} and len(table) == 3


def test_version_probe(tmp_path):
    cfg = _cfg(tmp_path, distribution="no-such-dist-xyz")
    cfg["codes"]["fake"]["version"] = "print('5.4.2')"
    table = producers_table(cfg, tmp_path / "work")
    assert set(table.version) == {"5.4.2"} and (table.status != "not installed").all()
    cfg["codes"]["fake"]["version"] = "import no_such_module_xyz"
    table = producers_table(cfg, tmp_path / "work")
    assert len(table) == 1 and table.status.iloc[0] == "not installed"


def test_norm_copy_drops_traces(tmp_path):
    manifest = tmp_path / "levels.yaml"
    level = {"h": 0.25, "A": "A.mtx", "B": "B.mtx", "G": "G.mtx", "multipliers": {"basis": "discontinuous"},
             "traces": [{"basis": "lagrange", "columns": [0]}]}
    manifest.write_text(yaml.safe_dump({"norm": "H", "gamma": {"shape": "segment"}, "levels": [level]}))
    data = yaml.safe_load(norm_copy(manifest, "L2").read_text())
    assert data["norm"] == "L2" and "gamma" not in data
    assert all("traces" not in lv and "multipliers" not in lv for lv in data["levels"])
