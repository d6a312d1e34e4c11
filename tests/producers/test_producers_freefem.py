"""The FreeFEM producer (examples/producers/freefem/export.py): run by the suite's interpreter,
it drives Debian's FreeFem++ (``make producers-freefem``) on the shipped mortar tutorial and on
the paper's membranes. Checked against the specification and the mathematics: FreeFEM's matrix
text read as FreeFEM solved it (the tutorial's own system M rebuilt from the exported blocks),
B's rows integrate the multipliers against constants (cell lengths), the membranes' B is the
exact mortar coupling, and FreeFEM's tgv rows are the certifier's penalty rows."""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import yaml

import helpers.producers as P

PYTHON = sys.executable
SCRIPT = P.ROOT / "examples" / "producers" / "freefem" / "export.py"
TUTORIAL = Path("/usr/share/doc/freefem++/examples/tutorial/mortar-DN-4.edp")
if shutil.which("FreeFem++") is None or not TUTORIAL.is_file() or not Path("/usr/lib/freefem++/msh3.so").is_file():
    pytest.skip("FreeFEM is not installed (FreeFem++, libfreefem++'s plugins, freefem++-doc's tutorial): run "
                "`make producers-freefem` (Debian, as root)", allow_module_level=True)

TGV = 1e30
"""FreeFEM's default penalty (``tgv``), the tutorial's and membranes.edp's."""
NS = (8, 16)
"""(At N = 4, P1, 24 of 50 dofs are tgv rows: the median diagonal the certifier compares
penalties with is then nearly a penalty itself, and A is refused as singular.)"""
@pytest.fixture(scope="module")
def export(tmp_path_factory):
    """The manifest of one space and offset on NS, exported once per module run."""
    return P.export_once(tmp_path_factory, PYTHON, SCRIPT, NS)


def _mats(manifest: Path, i: int, keys=("A", "B", "G")):
    lv = yaml.safe_load(manifest.read_text())["levels"][i]
    return lv, [scipy.io.mmread(manifest.parent / lv[k]).tocsr() for k in keys]


def test_list_spaces():
    code, out, err = P.run_cli(PYTHON, SCRIPT, "--list-spaces")
    assert code == 0 and err == ""
    ids = [line.split("\t")[0] for line in out.splitlines()]
    assert {"tutorial", "tutorial-split1", "T3-k1", "T5-k2"} <= set(ids)


@pytest.mark.parametrize("args, names", [
    (("--out", "OUT", "--space", "tutorial", "--N", "4", "--offset", "2"), "--offset 2"),
    (("--out", "OUT", "--space", "Q9", "--N", "4"), "--space 'Q9'"),
    (("--out", "OUT", "--space", "tutorial", "--N", "1", "4"), "--N 1"),
    (("--out", "OUT", "--space", "tutorial-coarse2", "--N", "4", "5"), "even N"),
    (("--out", "OUT", "--space", "T3-k1", "--N", "8", "4"), "increasing"),
    (("--out", "FILE", "--space", "T3-k1", "--N", "4"), "not a directory"),
])
def test_bad_arguments_one_line_exit_2(tmp_path, args, names):
    P.check_refused(PYTHON, SCRIPT, tmp_path, args, names)


@pytest.mark.parametrize("space", ["tutorial-labels", "tutorial-split1"])
def test_tutorial_blocks_are_the_system_freefem_solves(tmp_path, space):
    """The tutorial's own M (FreeFEM's block matrix it factorizes) equals [[A, Bᵀ], [B, C]]
    rebuilt from the exported files: the reader's layout, 0/1-based indices and block order;
    A symmetric, C = 1e-10 × G (the tutorial's vDD), and B's rows integrate each P0 multiplier
    against the quarters' constants: per quarter ±|cell| (eps_sd = ±1), summing to 0 (the jump)."""
    ff = P.load_script(SCRIPT, "freefem_export")

    lv = ff.tutorial_level(NS[0], space, 0, tmp_path)
    A, B, C, G, M = (lv[k] for k in ("A", "B", "C", "G", "M"))
    import scipy.sparse as sp
    rebuilt = sp.bmat([[A, B.T], [B, C]]).tocsr()
    assert M.shape == rebuilt.shape and abs(M - rebuilt).max() == 0.0
    assert abs(A - A.T).max() <= P.ROUNDOFF * abs(A).max()
    assert abs(C - 1e-10 * G).max() <= P.ROUNDOFF * 1e-10 * abs(G).max()
    cells = G.diagonal()  # P0 mass: diagonal, the cells' lengths
    assert abs(G - sp.diags(cells)).max() == 0.0 and cells.sum() == pytest.approx(4.0, rel=P.ROUNDOFF)  # four radii
    quarters = np.cumsum([0] + [lv_.shape[0] for lv_ in _quarter_blocks(A)])
    sums = np.column_stack([np.asarray(B[:, a:b].sum(axis=1)).ravel() for a, b in zip(quarters[:-1], quarters[1:])])
    assert np.abs(sums.sum(axis=1)).max() <= P.ROUNDOFF * cells.max()
    touched = np.abs(sums) > 0.5 * cells[:, None]
    assert (touched.sum(axis=1) == 2).all()  # each cell on a radius between two quarters
    assert np.abs(np.abs(sums[touched]) - np.repeat(cells, 2)).max() <= P.ROUNDOFF * cells.max()


def _quarter_blocks(A):
    """A's diagonal blocks (the quarters: no coupling between them)."""
    import scipy.sparse.csgraph as cg

    _, labels = cg.connected_components(abs(A) > 0, directed=False)
    starts = [0] + [i for i in range(1, A.shape[0]) if labels[i] != labels[i - 1]] + [A.shape[0]]
    assert len(starts) == 5, "A is not four blocks"
    return [A[a:b, a:b] for a, b in zip(starts[:-1], starts[1:])]


def test_tutorial_as_shipped_has_no_coupling(export):
    """As Debian's FreeFEM runs the shipped tutorial, its skeleton's cells carry label 0 and its
    int1d(Thm, 1) integrals are empty: B = 0 (the fix, tutorial-labels, couples every cell)."""
    for i in range(len(NS)):
        lv, (A, B, G) = _mats(export("tutorial"), i)
        assert B.nnz == 0 or abs(B).max() == 0.0
        assert lv["C"] == f"C{NS[i]}.mtx" and B.shape[0] == 16 * NS[i] == G.shape[0]
        _, (B2,) = _mats(export("tutorial-labels"), i, ("B",))
        assert (np.asarray(abs(B2).sum(axis=1)).ravel() > 0).all()


@pytest.mark.parametrize("space, offset", [("T3-k1", 0), ("T3-k2", 1), ("T4-k2", 1), ("R5.4-k1", 1)])
def test_membranes_B_exact_G_mass(export, space, offset):
    """The membranes: B = the exact mortar coupling of the described basis (FreeFEM integrates on
    a meshL holding both partitions' breakpoints), also at offset 1; G the described L² mass
    (T3: its end rows constrained, B's zero and G's unit)."""
    k = int(space[-1])
    for i, n in enumerate(NS):
        lv, (A, B, G) = _mats(export(space, offset), i)
        coords, n1 = P.body_coordinates(PYTHON, SCRIPT, n, space, offset, ns=NS)
        exact, _ = P.exact_coupling(lv["multipliers"], coords, n1, k)
        fixed = P.constrained_rows(B, G)
        assert len(fixed) == (2 if space.startswith("T3") else 0)
        exact[fixed] = 0.0
        # offset 1: FreeFEM finds the integration points in Ω1's triangles by point location, whose
        # barycentric round-off (a few ε per cell, ~1e-14 relative measured) is ours to allow; an
        # integration that missed a kink would be off by 1e-3 or more (GetFEM's slave rule)
        tol = P.ROUNDOFF if offset == 0 else 1e-12
        assert np.abs(B.toarray() - exact).max() <= tol * np.abs(exact).max()
        assert P.mass_mismatch(G, lv["multipliers"], fixed) <= P.ROUNDOFF


def test_tgv_rows_are_the_dirichlet_dofs_and_the_certifiers_penalty_rows(export):
    """FreeFEM's on(..., u=0) with tgv = 1e30 puts 1e30 on the diagonal of exactly the dofs on
    ∂Ω_i \\ Γ (from the dofs' coordinates) and leaves B's columns there; the certifier removes
    exactly those rows (its penalty-row rule) and gives the suite's β for T3-k1 matching."""
    space = "T3-k1"
    manifest = export(space, 0)
    rows = P.beta_rows(manifest)
    for i, n in enumerate(NS):
        _, (A, B, G) = _mats(manifest, i)
        coords, n1 = P.body_coordinates(PYTHON, SCRIPT, n, space, 0, ns=NS)
        x, y = coords[:, 0], coords[:, 1]
        boundary = np.isclose(x, 0) | np.isclose(x, 1) | np.isclose(y, 0) | np.isclose(y, 2)
        boundary |= np.isclose(y, 1) & (np.isclose(x, 0) | np.isclose(x, 1))
        assert np.array_equal(np.flatnonzero(A.diagonal() == TGV), np.flatnonzero(boundary))
        assert int(rows[i]["removed_dofs"]) == int(boundary.sum())
        suite = P.suite_beta("T3", 1, n, n, norm="H")
        assert float(rows[i]["beta"]) == pytest.approx(float(suite["beta"]), rel=1e-8)


def test_certificate_on_non_matching_meshes_is_the_suites_exact_coupling(export):
    """Offset 1: the certifier's own distance to the exact mortar coupling (from the manifest's
    ``traces``, B's columns at Γ's tgv ends included) is round-off, and β_h in H is that of
    ``beta --case --N1 N+1`` (the same triangles, the same exact coupling)."""
    for n, row in zip(NS, P.beta_rows(export("T3-k2", 1))):
        assert float(row["coupling_distance"]) <= 1e-12
        suite = P.suite_beta("T3", 2, n + 1, n, norm="H")
        assert float(row["beta"]) == pytest.approx(float(suite["beta"]), rel=1e-8)
