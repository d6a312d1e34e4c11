"""Round trip: ``export`` of the suite's own systems, then the foreign-system engine, gives the
β_h of ``beta`` to 1e-10 and the verdict of ``verdict --case`` — every registered space,
matching and non-matching meshes, both models, every file format."""
from __future__ import annotations

import io

import numpy as np
import pytest

from infsup_contact.cli import main
from infsup_contact.discretization.spaces.registry import common_ids
from infsup_contact.models.elastic import ELASTIC
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.study.verdict import verdict_rows
from infsup_contact.systems.engine import level_spectrum
from infsup_contact.systems.export import suite_system, write_system
from infsup_contact.systems.levels import system_rows, system_verdict
from infsup_contact.systems.manifest import load_manifest

K = 2  # every registered space is defined for k = 2 (T4, T5 need k >= 2)
NS = (4, 8, 16)
FORMATS = ("mtx", "npz", "petsc")
CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)


def _export(tmp_path, case, offset=0, fmt="mtx", model=None, norm="H"):
    levels = [(1.0 / n,) + suite_system(case, K, n + offset, n, norm=norm, model=model) for n in NS]
    return load_manifest(write_system(tmp_path / f"{case}-{offset}-{fmt}", levels, fmt, case,
                                      norm="given" if norm == "H" else "L2"))


@pytest.mark.parametrize("offset", [0, 1], ids=["matching", "N1=N2+1"])
@pytest.mark.parametrize("case", common_ids(K))
def test_export_then_system_reproduces_beta(tmp_path, case, offset):
    fmt = FORMATS[(common_ids(K).index(case) + offset) % len(FORMATS)]
    rows = system_rows(_export(tmp_path, case, offset, fmt), notes=io.StringIO())
    for n, row in zip(NS, rows):
        ref, = beta_rows("structured", K, n + offset, n, [case], norms=("H",))
        assert row["kernel_dim"] == ref["kernel_dim"], (case, n)
        assert abs(row["beta"] - ref["beta"]) <= 1e-10
        assert abs(row["smallest_nonzero"] - ref["smallest_nonzero"]) <= 1e-10
        assert row["kernel_decision"] == "clear"
        assert row["residual"] < 1e-12


@pytest.mark.parametrize("case", common_ids(K))
def test_export_then_verdict_system_equals_verdict_case(tmp_path, case):
    out, _ = system_verdict(_export(tmp_path, case), **CRITERION, notes=io.StringIO())
    ref = verdict_rows(case, K, "structured", NS, "H", **CRITERION)
    assert out["verdict"] == ref["verdict"]
    assert out["kernel_dim"] == ref["kernel_dim"]
    assert abs(out["beta_min"] - ref["beta_min"]) <= 1e-10
    if np.isfinite(ref["slope"]):
        assert abs(out["slope"] - ref["slope"]) <= 1e-8


def test_elastic_round_trip(tmp_path):
    rows = system_rows(_export(tmp_path, "T3", model=ELASTIC), notes=io.StringIO())
    for n, row in zip(NS, rows):
        ref, = beta_rows("structured", K, n, n, ["T3"], norms=("H",), model=ELASTIC)
        assert abs(row["beta"] - ref["beta"]) <= 1e-10


def test_shift_invert_route_agrees_with_the_gamma_route():
    """Two independent routes: the Γ-last Schur + dense pencil, and shift-invert Lanczos on the
    quasi-definite KKT matrix (no Schur complement, no dense S)."""
    for case in ("T3", "R5.4"):
        A, B, G = suite_system(case, K, 9, 8)
        dense, lanczos = (level_spectrum(A, B, G, route=r) for r in ("gamma-dense", "shift-invert"))
        assert dense.kernel.dim == lanczos.kernel.dim
        assert abs(dense.beta - lanczos.beta) <= 1e-10
        assert abs(dense.smallest_nonzero - lanczos.smallest_nonzero) <= 1e-9


def test_l2_mass_gives_the_l2_verdict_and_says_so(tmp_path, capsys):
    """Remark 3.1: with only the L² mass the stable T3 decays like h^{1/2}: UNSTABLE, and the row
    names it the L² verdict; the h-weighted norm is offered only with its caveat."""
    m = _export(tmp_path, "T3", norm="L2")
    out, _ = system_verdict(m, **CRITERION, notes=io.StringIO())
    assert out["verdict"] == "UNSTABLE" and abs(out["slope"] - 0.5) < 0.15
    assert "L2 verdict" in out["norm_note"] and "Remark 3.1" in out["norm_note"]
    l2 = system_rows(m, notes=io.StringIO())
    m.path.write_text(m.path.read_text().replace("norm: L2", "norm: h-L2"))
    assert main(["beta", "--system", str(m.path)]) == 0
    captured = capsys.readouterr()
    assert "does not prove H^-1/2 stability" in captured.err
    weighted = [line.split(",") for line in captured.out.strip().splitlines()]
    col = weighted[0].index("beta")
    for row, rec in zip(l2, weighted[1:]):  # G -> h G scales beta by h^{-1/2}, exactly
        assert abs(float(rec[col]) - row["beta"] / np.sqrt(row["h"])) <= 1e-10 * float(rec[col])
        assert rec[weighted[0].index("norm")] == "h-L2"


@pytest.mark.parametrize("fmt", FORMATS)
def test_cli_export_then_verdict_system(tmp_path, capsys, fmt):
    assert main(["export", "--case", "R5.4", "--k", "2", "--N", "4", "8", "16", "--format", fmt,
                 "--out", str(tmp_path)]) == 0
    manifest = capsys.readouterr().out.strip()
    assert main(["verdict", "--system", manifest, "--expect", "unstable"]) == 0
    assert main(["verdict", "--system", manifest, "--expect", "stable"]) == 1
    out = capsys.readouterr().out
    assert "UNSTABLE" in out
    assert main(["beta", "--system", manifest]) == 0
    assert len(capsys.readouterr().out.strip().splitlines()) == 1 + len(NS)
