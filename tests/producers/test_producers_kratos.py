"""The Kratos producer (examples/producers/kratos): its exports checked against mathematics and
certified. Skipped, with the reason, where Kratos is not installed (``make producers-kratos``).

Kratos' mesh tying couples the slave side (Ω1) by B = s (D | −M), D_ij = ∫ ψ_i φ_j on the slave
trace, M_ij = ∫ ψ_i φ_j^master, ψ the dual P1 basis and s Kratos' scale factor. Checked here by an
independent route: the suite's own dual basis (discretization/segment/dual.py, built from moments) and
Gauss-Legendre on the common refinement of both traces.
"""
from __future__ import annotations

import importlib.util
import io
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.linalg
import scipy.sparse as sp

pytestmark = pytest.mark.skipif(importlib.util.find_spec("KratosMultiphysics") is None,
                                reason="Kratos not installed (make producers-kratos)")

from infsup_contact.discretization.segment.dual import dual_space  # noqa: E402
from infsup_contact.discretization.segment.norms import gram_l2  # noqa: E402
from infsup_contact.study.producers import norm_copy  # noqa: E402
from infsup_contact.systems.levels import system_verdict  # noqa: E402
from infsup_contact.systems.manifest import load_manifest  # noqa: E402
from infsup_contact.systems.readers import SystemFileError  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
EXPORTER = ROOT / "examples" / "producers" / "kratos" / "export.py"
SPACES = ("dual", "dual-unscaled", "dual-ends-fixed")
NS = (4, 8, 16, 32)  # the stage's levels (N = 4, 8, 16 is pre-asymptotic in h-L2: CI [-0.25, 0.40])
CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
ROUND_OFF = 1e-12  # relative: Kratos' NODAL_H and the mortar segmentation (measured ≤ 2e-13)


def _export(out: Path, space: str, offset: int, ns=NS) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(EXPORTER), "--out", str(out), "--space", space, "--N",
                           *map(str, ns), "--offset", str(offset)], capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def exports(tmp_path_factory):
    """Every space, matching and offset 1, N = 4, 8, 16: (space, offset) → levels.yaml."""
    root, out = tmp_path_factory.mktemp("kratos"), {}
    for space in SPACES:
        for offset in (0, 1):
            done = _export(root / f"{space}_{offset}", space, offset)
            assert done.returncode == 0, done.stderr[-500:]
            assert done.stdout == "", "the contract: nothing on stdout"
            out[space, offset] = root / f"{space}_{offset}" / "levels.yaml"
    return out


@pytest.fixture(scope="module")
def kratos_model():
    sys.path.insert(0, str(EXPORTER.parent))
    import kratos_model as km

    return km


def _level(manifest: Path, i: int):
    import yaml

    entry = yaml.safe_load(manifest.read_text())["levels"][i]
    A, B, G = (sp.csr_matrix(scipy.io.mmread(manifest.parent / entry[k])) for k in ("A", "B", "G"))
    return A, B, G, entry["multipliers"]


def _suite_dual(breakpoints, space):
    """The suite's dual P1 basis on the slave nodes (no end modification); without its two end
    functions for ``dual-ends-fixed`` (their multipliers are fixed)."""
    full = dual_space(np.asarray(breakpoints), 1, vanish_at_ends=False)
    keep = slice(1, -1) if space == "dual-ends-fixed" else slice(None)
    return full, keep


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("offset", [0, 1])
def test_A_is_spd_on_its_free_dofs_and_symmetric(exports, space, offset):
    A, B, _, _ = _level(exports[space, offset], 1)
    assert abs(A - A.T).max() == 0.0
    coupled = np.flatnonzero(np.diff((A - sp.diags(A.diagonal())).tocsr().indptr) > 0)
    Af = A[coupled][:, coupled].toarray()
    np.linalg.cholesky(Af)  # SPD: raises otherwise
    if space != "dual-ends-fixed":  # the block builder keeps the Dirichlet dofs, decoupled
        assert A.shape[0] > len(coupled)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("offset", [0, 1])
def test_B_rows_integrate_the_trace_against_the_dual_basis(kratos_model, space, offset):
    """B v = s ∫_Γ ψ_i (v1 − v2) for v1 = x(1 − x)(1 + y), v2 = x²(1 − x)(3 − y) interpolated at
    the nodes: the traces are the P1 interpolants on each side's Γ mesh, integrated exactly by
    2-point Gauss on the common refinement against the suite's dual basis."""
    n = 8
    blk = kratos_model.assembled_blocks(n + offset, n, space)
    B, lm_x, fixed, scale = blk["B"], blk["lm_x"], blk["fixed"], blk["scale"]
    x, y = blk["xy"][:, 0], blk["xy"][:, 1]
    body1 = blk["ids"] <= (n + offset + 1) ** 2  # Ω1's nodes are created first
    v = np.where(body1, x * (1 - x) * (1 + y), x ** 2 * (1 - x) * (3 - y))
    v[fixed] = 0.0  # they vanish there anyway (x = 0, 1 or off Γ)
    slave, master = np.linspace(0, 1, n + offset + 1), np.linspace(0, 1, n + 1)
    cuts = np.union1d(slave, master)
    g, w = np.polynomial.legendre.leggauss(2)
    t = (np.outer(np.diff(cuts), (g + 1) / 2) + cuts[:-1, None]).ravel()
    wt = (np.outer(np.diff(cuts), w / 2)).ravel()
    jump = np.interp(t, slave, slave * (1 - slave) * 2) - np.interp(t, master, master ** 2 * (1 - master) * 2)
    # at y = 1: v1 = 2 x(1 − x), v2 = 2 x²(1 − x), each interpolated on its own side's Γ nodes
    full, keep = _suite_dual(slave, space)
    psi = full.evaluate(t)[:, keep]
    exact = scale * (psi * (wt * jump)[:, None]).sum(axis=0)
    order = np.argsort(lm_x)
    got = (B @ v)[order]
    assert np.max(np.abs(got - exact)) <= ROUND_OFF * np.max(np.abs(B).data) * np.max(np.abs(v))
    if space == "dual":
        assert scale == pytest.approx(n + offset, rel=1e-9) or scale == pytest.approx(n, rel=1e-9)
    else:
        assert scale == 1.0


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("offset", [0, 1])
def test_G_is_the_L2_mass_of_the_described_basis(exports, space, offset):
    for i in range(len(NS)):
        _, B, G, mult = _level(exports[space, offset], i)
        if "basis" in mult:  # the helper form: dual P1 on the slave nodes, ends kept
            bp, keep = mult["breakpoints"], slice(None)
        else:  # the general form: the interior dual functions, ends fixed
            bp, keep = mult["breakpoints"], slice(1, -1)
        full = dual_space(np.asarray(bp), 1, vanish_at_ends=False)
        M = gram_l2(full)[keep, keep]
        rows = np.asarray(mult.get("rows", np.arange(M.shape[0])))
        assert B.shape[0] == M.shape[0] == G.shape[0]
        P = G.toarray()[np.ix_(rows, rows)]  # rows[j] = row of B of the j-th function left to right
        assert np.max(np.abs(P - M)) <= 1e-14 * np.max(np.abs(M))


@pytest.mark.parametrize("offset", [0, 1])
def test_end_multipliers_of_the_dual_space_couple_to_nothing(exports, offset):
    """The end functions pair only with fixed dofs (biorthogonality): their rows of B are zero
    up to Kratos' round-off, so Bᵀ has a kernel of dimension exactly 2 (a gap of many decades)."""
    for i in range(len(NS)):
        A, B, G, mult = _level(exports["dual", offset], i)
        Bd = np.abs(B.toarray())
        ends = [0, B.shape[0] - 1]
        assert Bd[ends].max() <= ROUND_OFF * Bd.max()
        s = scipy.linalg.svdvals(Bd * np.sign(B.toarray()))
        assert s[-1] <= ROUND_OFF * s[0] and s[-2] <= ROUND_OFF * s[0] and s[-3] >= 1e-3 * s[0]


def test_unscaled_is_the_default_divided_by_the_scale_factor(exports):
    for offset in (0, 1):
        for i, n in enumerate(NS):
            _, Bs, _, _ = _level(exports["dual", offset], i)
            _, Bu, _, _ = _level(exports["dual-unscaled", offset], i)
            ratio = Bs.toarray()[np.abs(Bu.toarray()) > 1e-3] / Bu.toarray()[np.abs(Bu.toarray()) > 1e-3]
            assert np.allclose(ratio, ratio[0], rtol=1e-10, atol=0)
            # YOUNG_MODULUS / NODAL_H: 1/h of one of the two sides (measured: the master's), to Kratos' round-off
            assert n * (1 - 1e-9) <= ratio[0] <= (n + offset) * (1 + 1e-9)


@pytest.mark.parametrize("norm", ["L2", "h-L2"])
@pytest.mark.parametrize("offset", [0, 1])
def test_verdicts_ends_fixed(exports, norm, offset):
    """Stable space: STABLE in h-L2; in L2 UNSTABLE with slope 1/2 (Remark 3.1)."""
    out, rows = system_verdict(load_manifest(norm_copy(exports["dual-ends-fixed", offset], norm)), **CRITERION,
                               notes=io.StringIO())
    assert all(r["kernel_detected"] == 0 for r in rows)
    if norm == "h-L2":
        assert out["verdict"] == "STABLE", out["evidence"]
    else:
        assert out["verdict"] == "UNSTABLE" and 0.35 <= out["slope"] <= 0.65, out["evidence"]


@pytest.mark.parametrize("space", ["dual", "dual-unscaled"])
def test_verdicts_ends_kept_never_stable(exports, space):
    """A kernel of dimension 2 (zero rows up to round-off): never STABLE; UNSTABLE once the
    producer's round-off is taken into account, INCONCLUSIVE (a close kernel decision) before."""
    for offset in (0, 1):
        for norm in ("L2", "h-L2"):
            out, _ = system_verdict(load_manifest(norm_copy(exports[space, offset], norm)), **CRITERION,
                                    notes=io.StringIO())
            assert out["verdict"] in ("UNSTABLE", "INCONCLUSIVE"), out["evidence"]
            if out["verdict"] == "INCONCLUSIVE":
                assert "kernel decision" in out["evidence"]


@pytest.mark.parametrize("space", SPACES)
def test_norm_H_manifest(exports, space):
    """The manifest as written (norm: H): accepted and certified from the multiplier description (STABLE for the ends-fixed space, never STABLE with the ends kept)."""
    manifest = load_manifest(exports[space, 0])
    out, _ = system_verdict(manifest, **CRITERION, notes=io.StringIO())
    if space == "dual-ends-fixed":
        assert out["verdict"] == "STABLE", out["evidence"]
    else:
        assert out["verdict"] != "STABLE", out["evidence"]


def test_list_spaces_and_bad_arguments(tmp_path):
    done = subprocess.run([sys.executable, str(EXPORTER), "--list-spaces"], capture_output=True, text=True)
    assert done.returncode == 0 and [line.split("\t")[0] for line in done.stdout.splitlines()] == list(SPACES)
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "levels.yaml").write_text("levels: []\n")
    bad = [["--space", "standard", "--N", "4", "8", "16"], ["--space", "dual", "--N", "8", "4", "16"],
           ["--space", "dual", "--N", "4", "8", "100000"], ["--space", "dual", "--N", "4", "8", "16", "--offset", "-1"],
           ["--space", "dual", "--N", "four"], ["--space", "dual"]]
    for args in bad:
        done = subprocess.run([sys.executable, str(EXPORTER), "--out", str(tmp_path / "new"), *args],
                              capture_output=True, text=True)
        assert done.returncode == 2 and done.stdout == "" and len(done.stderr.strip().splitlines()) == 1, args
    done = _export(tmp_path / "full", "dual", 0)
    assert done.returncode == 2 and "holds a system already" in done.stderr
    assert not (tmp_path / "new").exists()
