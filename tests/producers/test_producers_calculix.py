"""The CalculiX producer (examples/producers/calculix/): Debian's ccx 2.20 rebuilt with our dump of
its mortar coupling (``make producers-calculix``), the decks of the 3D membranes on HEX20 bodies,
and export.py. Checked against the mathematics and against the suite's own model of the same
spaces (LINMORTAR = ``LINDUAL-Q8``, PGLINMORTAR's constraint rows = ``T5`` on QUAD8 faces, and
LINMORTAR with the slave's boundary vertices in one-node MPCs = ``LINDUAL0-Q8``): the
Schur complements B A⁻¹ Bᵀ agree to CalculiX's entry accuracy (its master projection, the
manifest's ``entry_rtol``), which no row order or dof order can hide. Skipped without the
patched ccx; a few seconds (N ≤ 3)."""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp
import scipy.sparse.linalg as sla
import yaml

import helpers.producers as P

HERE = P.ROOT / "examples" / "producers" / "calculix"
SCRIPT = HERE / "export.py"
PYTHON = sys.executable
CCX = os.environ.get("INFSUP_CCX", str(P.ROOT / ".calculix" / "bin" / "ccx_infsup"))
if not os.access(CCX, os.X_OK):
    pytest.skip(f"CalculiX's patched ccx is not built ({CCX}): run `make producers-calculix` (root)",
                allow_module_level=True)
ccx_export = P.load_script(SCRIPT, "calculix_export")
import decks  # noqa: E402  (its folder is on sys.path now: load_script put it there)

SUITE_CASE = {"LINMORTAR": "LINDUAL-Q8", "PGLINMORTAR": "T5", "LINMORTAR-MPC": "LINDUAL0-Q8"}
NS = (2, 3)


def _run_contact(tmp_path, mortar: str, n: int, dump: bool):
    """The contact deck on n³ + n³ bricks, run by the patched ccx; the dump directory."""
    m = decks.mesh(n, n)
    out = tmp_path / "dump"
    ccx_export.run_ccx(tmp_path, "contact", decks.contact_deck(m, mortar, clamped=False), dump=out if dump else None)
    return m, out


def test_dump_appears_only_when_asked(tmp_path):
    """INFSUP_CCX_DUMP set: Bd, Dd, islavact, info written; unset: ccx runs as Debian's (no files)."""
    _, out = _run_contact(tmp_path, "LINMORTAR", 1, dump=True)
    assert {p.name for p in out.iterdir()} == {"Bd.mtx", "Dd.mtx", "islavact.txt", "info.txt"}
    plain = tmp_path / "plain"
    plain.mkdir()
    _run_contact(plain, "LINMORTAR", 1, dump=False)
    assert not (plain / "dump").exists() and not list(plain.glob("*.mtx"))


@pytest.mark.parametrize("mortar, slave, master", [("LINMORTAR", "Dd", "Bd"), ("PGLINMORTAR", "Dpgd", "Bpgd")])
def test_dumped_rows_integrate_the_vertex_weights(tmp_path, mortar, slave, master):
    """Matching meshes, n = 2: each multiplier row p paired with the constant 1 (Σ_q of the slave
    block: the QUAD8 basis sums to 1) gives ∫ψ_p = ∫φ_p^{Q1} = (h/2)² × its cells (biorthogonality,
    or the hat itself for the PG test functions), exactly; the master block, the same constant
    seen from the other side, gives −∫ψ_p to CalculiX's projection accuracy."""
    n = 2
    m, out = _run_contact(tmp_path, mortar, n, dump=True)
    rows = ccx_export.multiplier_rows(m, out, n)
    D = ccx_export.read_node_matrix(out / f"{slave}.mtx")[rows - 1]
    M = ccx_export.read_node_matrix(out / f"{master}.mtx")[rows - 1]
    xy = m["coords"][rows - 1, :2] * n
    cells = np.where(np.isclose(xy % n, 0), 1, 2).prod(axis=1)  # 1 at Γ's corners, 2 on edges, 4 inside
    weight = cells * (0.5 / n) ** 2
    assert np.abs(np.asarray(D.sum(axis=1)).ravel() - weight).max() <= P.ROUNDOFF
    assert np.abs(np.asarray(M.sum(axis=1)).ravel() + weight).max() <= ccx_export.ENTRY_RTOL * weight.max()


@pytest.fixture(scope="module")
def exports(tmp_path_factory):
    out = {}
    for space, case in SUITE_CASE.items():
        ours = P.run_export(PYTHON, SCRIPT, tmp_path_factory.mktemp(space), space, NS)
        ref = tmp_path_factory.mktemp(case) / "ref"
        done = subprocess.run([sys.executable, "-m", "infsup_contact", "export", "--model", "membranes3d",
                               "--element", "hex20", "--case", case, "--k", "2", "--N", *map(str, NS),
                               "--out", str(ref), "--quiet"], capture_output=True, text=True, env=P._env())
        assert done.returncode == 0, done.stderr[-1000:]
        out[space] = (ours, ref / "levels.yaml")
    return out


def _level(manifest, i):
    """(A, B, G) of level i as scipy CSR (the suite writes a dense G in MatrixMarket's array form)."""
    lv = yaml.safe_load(manifest.read_text())["levels"][i]
    return [sp.csr_matrix(scipy.io.mmread(manifest.parent / lv[key])) for key in ("A", "B", "G")]


def _schur(manifest, i):
    """(A, B A⁻¹ Bᵀ dense, G) of level i."""
    A, B, G = _level(manifest, i)
    return A, B @ sla.splu(A.tocsc()).solve(B.T.toarray()), G


@pytest.mark.parametrize("space", SUITE_CASE)
def test_export_is_the_suites_space(exports, space):
    """A SPD with the spectrum of the suite's stiffness (the same exact 27-point assembly, written by
    ccx with 14 significant digits: 1e-12), G the described L² mass (= the suite's), and B A⁻¹ Bᵀ the
    suite's to 10 entry_rtol (Bd's entries are CalculiX's master projection's, ~5e-7)."""
    ours, ref = exports[space]
    assert yaml.safe_load(ours.read_text())["entry_rtol"] == ccx_export.ENTRY_RTOL
    for i in range(len(NS)):
        A, S, G = _schur(ours, i)
        A_ref, S_ref, G_ref = _schur(ref, i)
        P.check_spd(A)
        ev, ev_ref = (np.linalg.eigvalsh(M.toarray()) for M in (A, A_ref))
        assert np.abs(ev - ev_ref).max() <= 1e-12 * ev_ref.max()
        assert abs(G - G_ref).max() <= P.ROUNDOFF * np.abs(G_ref).max()
        assert np.abs(S - S_ref).max() <= 10 * ccx_export.ENTRY_RTOL * np.abs(S_ref).max()


def test_conduction_matrix_holds_the_free_nodes(tmp_path):
    """CalculiX's conduction matrix has one equation per node off ∂Ω_i∖Γ (its ``.dof``), no other."""
    n = 2
    m = decks.mesh(n, n)
    ccx_export.run_ccx(tmp_path, "heat", decks.heat_deck(m))
    A, nodes = ccx_export.conduction_matrix(tmp_path, "heat")
    fixed = set(decks.boundary_nodes(m, clamped=True).tolist())
    assert sorted(nodes.tolist()) == sorted(set(m["ids"].tolist()) - fixed) and A.shape == (len(nodes),) * 2


def test_bad_arguments_one_line_exit_2(tmp_path):
    P.check_refused(PYTHON, SCRIPT, tmp_path, ("--out", "OUT", "--space", "LINMORTAR", "--N", "2", "--offset", "2"),
                    "--offset 2")
    P.check_refused(PYTHON, SCRIPT, tmp_path, ("--out", "OUT", "--space", "MORTAR", "--N", "2"), "--space 'MORTAR'")


def test_missing_ccx_one_line_exit_2(tmp_path):
    env = dict(P._env(), INFSUP_CCX=str(tmp_path / "no-ccx"))
    res = subprocess.run([PYTHON, str(SCRIPT), "--out", str(tmp_path / "o"), "--space", "LINMORTAR", "--N", "2"],
                         capture_output=True, text=True, env=env)
    assert res.returncode == 2 and res.stdout == "" and len(res.stderr.strip().splitlines()) == 1
    assert "make producers-calculix" in res.stderr


def test_petrov_galerkin_pair_is_the_suites_PGLIN_Q8(exports):
    """PGLINMORTAR as CalculiX solves it: trial λ in the duals (its Dd/Bd, LINMORTAR's export) and
    constraint tested with the hats (Dpgd/Bpgd, PGLINMORTAR's); the stability constant of the pair,
    γ_h = σ_min(L_N⁻¹ B_N A⁻¹ B_Mᵀ L_M⁻ᵀ) in L², is the suite's PGLIN-Q8 row (``beta`` = sqrt γ_h):
    on matching meshes four singular values at CalculiX's entry accuracy (the corner modes) and
    the next one the suite's smallest nonzero."""
    import csv
    import io

    import scipy.linalg as sl

    from helpers.cli import run_in_process

    trial, test = exports["LINMORTAR"][0], exports["PGLINMORTAR"][0]
    for i, n in enumerate(NS):
        A, B_M, G_M = _level(trial, i)
        _, B_N, G_N = _level(test, i)
        S = B_N @ sla.splu(A.tocsc()).solve(B_M.T.toarray())
        L_M, L_N = (np.linalg.cholesky(G.toarray()) for G in (G_M, G_N))
        K = sl.solve_triangular(L_N, sl.solve_triangular(L_M, S.T, lower=True).T, lower=True)
        s = np.linalg.svd(K, compute_uv=False)[::-1]
        code, out, err = run_in_process(["beta", "--model", "membranes3d", "--element", "hex20", "--case", "PGLIN-Q8",
                                         "--k", "2", "--N1", str(n), "--N2", str(n), "--norm", "L2"])
        assert code == 0, err[-1000:]
        row = next(csv.DictReader(io.StringIO(out)))
        assert int(row["kernel_dim"]) == 4 and (s[:4] <= 10 * ccx_export.ENTRY_RTOL * s[-1]).all()
        assert abs(np.sqrt(s[4]) - float(row["smallest_nonzero"])) <= 10 * ccx_export.ENTRY_RTOL * np.sqrt(s[4])


def test_pg_trial_side_is_linmortars(tmp_path):
    """PGLINMORTAR's trial coupling (its Dd, Bd) is LINMORTAR's, entry for entry (n = 2): the PG
    pair's trial rows may be taken from LINMORTAR's export."""
    (tmp_path / "lin").mkdir()
    (tmp_path / "pg").mkdir()
    _, lin = _run_contact(tmp_path / "lin", "LINMORTAR", 2, dump=True)
    _, pg = _run_contact(tmp_path / "pg", "PGLINMORTAR", 2, dump=True)
    for name in ("Dd.mtx", "Bd.mtx"):
        a, b = (ccx_export.read_node_matrix(d / name) for d in (lin, pg))
        assert abs(a - b).max() == 0.0
