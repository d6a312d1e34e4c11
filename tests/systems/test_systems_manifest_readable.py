"""``export``'s levels.yaml is for people too: block style, short lines, the long arrays of a
level's description in .npy files beside the matrices; the reader takes them as it takes the
inline lists (a manifest with every array inline, the old layout, gets the same verdict)."""
from __future__ import annotations

import numpy as np
import yaml

from helpers.cli import run_in_process
from infsup_contact.systems.export import INLINE_MAX


def _inline(value, base):
    """``value`` with every .npy file name replaced by its array as nested lists."""
    if isinstance(value, dict):
        return {k: _inline(v, base) for k, v in value.items()}
    if isinstance(value, list):
        return [_inline(v, base) for v in value]
    if isinstance(value, str) and value.endswith(".npy"):
        return np.load(base / value).tolist()
    return value


def test_the_manifest_reads_and_its_arrays_are_side_files_with_the_same_verdict(tmp_path):
    out = tmp_path / "sys"
    code, _, err = run_in_process(["export", "--case", "T3", "--k", "2", "--N", "8", "16", "32", "--out", str(out)])
    assert code == 0, err
    text = (out / "levels.yaml").read_text()
    assert max(map(len, text.splitlines())) <= 100
    data = yaml.safe_load(text)
    side = sorted(p.name for p in out.glob("*.npy"))
    assert side, "the finer levels' breakpoints, dofs, coefficients and columns are longer than INLINE_MAX"
    named = [v for v in _strings(data) if v.endswith(".npy")]
    assert sorted(named) == side  # every side file is named by the manifest, and only those exist
    assert all(np.load(out / name).size > INLINE_MAX for name in side)
    # the same system with every array inline (the layout before side files)
    (out / "inline.yaml").write_text(yaml.safe_dump(_inline(data, out), sort_keys=False, default_flow_style=True,
                                                    width=float("inf")))
    rows = []
    for manifest in ("levels.yaml", "inline.yaml"):
        code, csv, err = run_in_process(["verdict", "--system", str(out / manifest)])
        assert code == 0, err
        header, row = csv.splitlines()[:2]
        rows.append(dict(zip(header.split(","), row.split(","))))
    for row in rows:
        row.pop("seconds")
    assert rows[0] == rows[1] and rows[0]["verdict"] == "STABLE"


def _strings(value):
    if isinstance(value, dict):
        for v in value.values():
            yield from _strings(v)
    elif isinstance(value, list):
        for v in value:
            yield from _strings(v)
    elif isinstance(value, str):
        yield value
