"""Every subcommand from the clean venv (conftest: the wheel built from the tree, its
dependencies from PyPI without the lock), run outside the checkout: exit 0 and sane output.
The reports of issue 50 were ``ModuleNotFoundError`` for yaml (verdict --system, export) and
skfem (--element hex20) from exactly this install."""
from __future__ import annotations

import csv
import io
import math

import pytest

from helpers.wheel_venv import clean_env, run

pytestmark = pytest.mark.package

SMALL = ["--k", "2", "--N1", "2", "--N2", "3"]
BETA = {  # name → argv, the element column expected (None: a 2D model, no such column)
    "2D": (["beta", "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4"], None),
    "arc": (["beta", "--case", "T3", "--k", "2", "--N1", "8", "--N2", "8", "--gamma", "arc", "--radius", "2"], None),
    "hex": (["beta", "--model", "membranes3d", "--element", "hex", "--case", "DUAL-Q9", *SMALL], "hex"),
    "hex20": (["beta", "--model", "membranes3d", "--element", "hex20", "--case", "PGLIN0-Q8", *SMALL], "hex20"),
    "tet": (["beta", "--model", "membranes3d", "--element", "tet", "--case", "PWLIN-T6", *SMALL], "tet"),
}


def cli(venv, *argv, cwd):
    """The venv's console script, in a directory outside the checkout (no PYTHONPATH)."""
    return run([venv / "infsup-contact", *argv], cwd=cwd)


def ok(proc) -> str:
    assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr[-3000:]}"
    assert "Traceback" not in proc.stderr and "Error" not in proc.stderr, proc.stderr
    return proc.stdout


def rows(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


def test_the_venv_runs_the_installed_wheel_not_the_tree(clean_venv, tmp_path):
    proc = run([clean_venv / "python", "-c", "import infsup_contact; print(infsup_contact.__file__)"], cwd=tmp_path)
    assert proc.returncode == 0 and "site-packages" in proc.stdout, proc.stdout + proc.stderr


def test_version(clean_venv, wheel, tmp_path):
    out = ok(cli(clean_venv, "--version", cwd=tmp_path))
    assert out == f"infsup-contact {wheel.name.split('-')[1]}\n"


@pytest.mark.parametrize("name", list(BETA))
def test_beta(clean_venv, tmp_path, name):
    argv, element = BETA[name]
    table = rows(ok(cli(clean_venv, *argv, cwd=tmp_path)))
    assert {r["norm"] for r in table} == {"H", "L2"}  # one row per norm of the one case asked
    for r in table:
        beta = float(r["beta"])
        assert math.isfinite(beta) and 0 < beta <= 1 + 1e-12, r  # an inf-sup constant of a normalized pair
        assert r["kernel_dim"] == "0"
        if element:
            assert r["element"] == element


def test_export_then_verdict_system_and_case(clean_venv, tmp_path):
    """export writes a manifest (yaml), verdict --system reads it: T3, k = 1 is STABLE on
    8, 16, 32 (the paper's stable pair), and verdict --case agrees on the same meshes."""
    out = tmp_path / "exports"
    ok(cli(clean_venv, "export", "--case", "T3", "--k", "1", "--N", "8", "16", "32", "--out", out, cwd=tmp_path))
    assert (out / "levels.yaml").is_file() and len(list(out.glob("*.mtx"))) >= 9
    system = rows(ok(cli(clean_venv, "verdict", "--system", out / "levels.yaml", "--expect", "stable", cwd=tmp_path)))
    case = rows(ok(cli(clean_venv, "verdict", "--case", "T3", "--k", "1", "--N", "8", "16", "32", "--expect", "stable",
                       cwd=tmp_path)))
    assert system[0]["verdict"] == case[0]["verdict"] == "STABLE"
    assert float(system[0]["beta_min"]) == pytest.approx(float(case[0]["beta_min"]), rel=1e-4)  # %.6g printing


def test_verdict_system_of_mm_files(clean_venv, tmp_path):
    """Kratos writes MatrixMarket as ``.mm``: the same exported system renamed to ``.mm`` gets the
    verdict of its ``.mtx`` files from the installed wheel (the reader's extension table ships)."""
    out, mm = tmp_path / "exports", tmp_path / "mm"
    ok(cli(clean_venv, "export", "--case", "R5.4", "--k", "1", "--N", "8", "16", "32", "--out", out, cwd=tmp_path))
    mm.mkdir()
    for path in out.iterdir():
        name = path.stem + ".mm" if path.suffix == ".mtx" else path.name
        text = path.read_bytes()
        (mm / name).write_bytes(text.replace(b".mtx", b".mm") if path.name == "levels.yaml" else text)
    assert ".mm" in (mm / "levels.yaml").read_text() and not list(mm.glob("*.mtx"))
    got = [rows(ok(cli(clean_venv, "verdict", "--system", d / "levels.yaml", "--expect", "unstable", cwd=tmp_path)))[0]
           for d in (out, mm)]
    assert got[0]["verdict"] == got[1]["verdict"] == "UNSTABLE"  # Remark 5.4: one zero mode
    assert got[0]["kernel_dim"] == got[1]["kernel_dim"] == "1"


def test_verdict_hook(clean_venv, tmp_path):
    out = tmp_path / "exports"
    ok(cli(clean_venv, "export", "--case", "T3", "--k", "1", "--N", "8", "16", "32", "--out", out, cwd=tmp_path))
    assert "STABLE (as expected)" in ok(cli(clean_venv, "verdict-hook", out / "levels.yaml", cwd=tmp_path))


def test_contact(clean_venv, tmp_path):
    table = rows(ok(cli(clean_venv, "contact", "--scene", "manufactured", "--case", "T3", "--k", "2", "--N1", "4",
                        "--N2", "4", cwd=tmp_path)))
    assert len(table) == 1 and table[0]["case"] == "T3"
    assert int(table[0]["iterations"]) >= 1  # PDAS ran
    assert 0 <= float(table[0]["energy_error"]) < 1 and float(table[0]["max_penetration"]) >= 0


def test_contact_rates_from_a_file(clean_venv, tmp_path):
    argv = ["contact", "--scene", "manufactured", "--case", "T3", "--k", "2"]
    tables = [ok(cli(clean_venv, *argv, "--N1", n, "--N2", n, cwd=tmp_path)) for n in ("4", "8", "16")]
    header = tables[0].split("\n", 1)[0]
    assert all(t.split("\n", 1)[0] == header for t in tables)
    (tmp_path / "contact.csv").write_text(tables[0] + "".join(t.split("\n", 1)[1] for t in tables[1:]))
    assert rows(ok(cli(clean_venv, "rates", "contact.csv", cwd=tmp_path)))  # one row of rates at least


def test_bench_dry_run(clean_venv, tmp_path):
    for what in (["--what", "beta"], ["--what", "contact"]):
        out = ok(cli(clean_venv, "bench", *what, "--N", "8", "--k", "2", "--dry-run", cwd=tmp_path))
        assert out.startswith("dry run: valid request") and out.count("\n") == 1


def test_provenance(clean_venv, tmp_path):
    import json

    record = json.loads(ok(cli(clean_venv, "provenance", cwd=tmp_path)))
    assert record  # a JSON object naming the versions


NO_MKL = """
import sys, types
import numpy as np, scipy.sparse as sp
from infsup_contact.la import mkl, pardiso, schur
schur.SOLVES_MAX_WORK = 0  # the large-problem branch on a small face
T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(24, 24))
A = (sp.kron(sp.eye(24), T) + sp.kron(T, sp.eye(24))).tocsc()
ref = schur.gamma_factorization(A, 24, gamma_dim=2)
mkl.glob = types.SimpleNamespace(glob=lambda pattern: [])  # no lib/libmkl_rt.so* (INFSUP_MKL_RT: absent)
mkl.mkl_rt.cache_clear(); pardiso._library.cache_clear()
got = schur.gamma_factorization(A, 24, gamma_dim=2)
print(ref.route, got.route, np.abs(got.schur - ref.schur).max() / np.abs(ref.schur).max())
"""


def test_no_mkl_is_a_note_and_the_scipy_route(clean_venv, tmp_path):
    """The installed wheel where MKL cannot be loaded (as on a platform without the mkl wheel):
    a face's Γ Schur complement by the nested-dissection LU instead of PARDISO, one note, the
    same S."""
    proc = run([clean_venv / "python", "-c", NO_MKL], cwd=tmp_path,
               env=clean_env(INFSUP_MKL_RT=str(tmp_path / "absent.so")))
    assert proc.returncode == 0, proc.stderr
    assert len(proc.stderr.splitlines()) == 1 and "scipy routes run" in proc.stderr, proc.stderr
    ref_route, route, difference = proc.stdout.split()
    assert (ref_route, route) == ("pardiso", "nested") and float(difference) <= 1e-12
