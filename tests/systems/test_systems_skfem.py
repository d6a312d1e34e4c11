"""A producer this suite did not write: Stokes pairs assembled by scikit-fem, exported as
MatrixMarket files with a manifest, certified by ``verdict --system``. The verdicts must be
the textbook's (Boffi–Brezzi–Fortin): Taylor–Hood P2–P1, MINI and P2–P0 stable; P1–P1 and
Q1–P0 (checkerboard) unstable."""
from __future__ import annotations

import io

import numpy as np
import pytest

pytest.importorskip("skfem")

import importlib.util  # noqa: E402
from pathlib import Path  # noqa: E402

_spec = importlib.util.spec_from_file_location(
    "stokes_skfem", Path(__file__).resolve().parents[2] / "examples" / "stokes_skfem.py")
_producer = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_producer)
PAIRS, stokes_system = _producer.PAIRS, _producer.stokes_system

from infsup_contact.cli import main  # noqa: E402
from infsup_contact.systems.engine import level_spectrum  # noqa: E402
from infsup_contact.systems.export import write_system  # noqa: E402
from infsup_contact.systems.levels import system_verdict  # noqa: E402
from infsup_contact.systems.manifest import load_manifest  # noqa: E402

LEVELS = {"P2-P0": (8, 16, 32)}  # P2–P0 is pre-asymptotic on 4 × 4 (β 0.54 → 0.51 → 0.49)
DEFAULT_LEVELS = (4, 8, 16)
CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)


def _manifest(tmp_path, pair):
    ns = LEVELS.get(pair, DEFAULT_LEVELS)
    levels = [(1.0 / n,) + stokes_system(pair, n) for n in ns]
    return write_system(tmp_path / pair, levels, "mtx", f"{pair} (scikit-fem)", known_kernel=1)


@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_textbook_verdict(tmp_path, pair):
    out, rows = system_verdict(load_manifest(_manifest(tmp_path, pair)), **CRITERION, notes=io.StringIO())
    assert out["verdict"] == PAIRS[pair][3].upper(), out["evidence"]
    assert all(r["kernel_decision"] == "clear" for r in rows)
    if out["verdict"] == "STABLE":
        assert all(r["kernel_dim"] == 1 for r in rows)  # the constant pressure, nothing else
        assert out["slope_lo"] > -0.15 and out["slope_hi"] < 0.15


def test_cli_verdict_with_expect(tmp_path, capsys):
    manifest = str(_manifest(tmp_path, "P2-P1"))
    assert main(["verdict", "--system", manifest, "--expect", "stable"]) == 0
    assert main(["verdict", "--system", manifest, "--dry-run"]) == 0
    assert "dry run: valid request" in capsys.readouterr().out


def test_declared_kernel_is_the_constant_pressure():
    """∫ div v = 0 for v ∈ H¹₀: Bᵀ 1 = 0 for every pair (what ``known_kernel: 1`` declares)."""
    for pair in PAIRS:
        A, B, G = stokes_system(pair, 4)
        assert np.abs(B.T @ np.ones(B.shape[0])).max() <= 1e-13 * abs(B).max()


def test_q1p0_checkerboard_is_the_extra_kernel():
    """Q1–P0 on structured quads: the checkerboard (−1)^{i+j} is in the kernel of Bᵀ (exactly,
    up to round-off), so the kernel is 2 = constant + checkerboard, and β_h = 0."""
    n = 8
    A, B, G = stokes_system("Q1-P0", n)
    import skfem

    x = np.linspace(0.0, 1.0, n + 1)
    mesh = skfem.MeshQuad.init_tensor(x, x)
    centers = mesh.p[:, mesh.t].mean(axis=1)
    i, j = (np.floor(c * n).astype(int) for c in centers)
    checker = (-1.0) ** (i + j)
    assert np.abs(B.T @ checker).max() <= 1e-13 * abs(B).max()
    res = level_spectrum(A, B, G, known_kernel=1)
    assert res.kernel.dim == 2 and res.kernel.detected == 1 and res.beta == 0.0


@pytest.mark.parametrize("pair", ["P2-P1", "P1-P1"])
def test_dense_and_shift_invert_routes_agree(pair):
    A, B, G = stokes_system(pair, 8)
    dense, lanczos = (level_spectrum(A, B, G, 1, r) for r in ("solves-dense", "shift-invert"))
    assert dense.kernel.dim == lanczos.kernel.dim
    assert abs(dense.smallest_nonzero - lanczos.smallest_nonzero) <= 1e-10
    assert np.allclose(dense.bottom[dense.kernel.dim:dense.kernel.dim + 3],
                       lanczos.bottom[lanczos.kernel.dim:lanczos.kernel.dim + 3], rtol=1e-9, atol=0)


def test_a_close_kernel_decision_is_inconclusive(tmp_path):
    """A B with one extra multiplier nearly dependent on another (a copy of a row of B,
    perturbed relatively so that its singular value lands at 2η): within a decade of η on at
    least one level (checked: the test fails if the construction decides clearly everywhere),
    and one close decision makes the verdict INCONCLUSIVE, never STABLE or UNSTABLE by the
    luck of the rounding. The copied row is a boundary pressure's, whose entries do not sum to
    0: a copy of an interior row, perturbed, would sum to 0 within 1e-12 and read as entry
    round-off (systems/roundoff.py), raising η with the perturbation."""
    import scipy.sparse as sp

    def nearly_dependent(B, G, i, t):
        row = B.getrow(i)
        extra = row.multiply(1.0 + t * np.arange(row.shape[1]) / row.shape[1])
        return sp.vstack([B, extra], format="csr"), sp.block_diag([G, G[i, i] * sp.identity(1)], format="csr")

    levels = []
    for n in DEFAULT_LEVELS:
        A, B, G = stokes_system("P2-P1", n)
        i = int(np.argmax(np.abs(np.asarray(B.sum(axis=1)).ravel()) / np.asarray(abs(B).sum(axis=1)).ravel()))
        k = level_spectrum(A, *nearly_dependent(B, G, i, 1e-10), known_kernel=1).kernel
        t = 1e-10 * 2.0 * k.tol / k.singular[1]  # σ is linear in t: σ(t) = 2η
        levels.append((1.0 / n, A) + nearly_dependent(B, G, i, t))
    manifest = load_manifest(write_system(tmp_path, levels, "mtx", "nearly dependent", known_kernel=1))
    out, rows = system_verdict(manifest, **CRITERION, notes=io.StringIO())
    margins = [r["kernel_margin_decades"] for r in rows]
    if all(r["kernel_decision"] == "clear" for r in rows):
        pytest.fail(f"the constructed near-dependence was decided clearly: margins {margins}")
    # the nearly dependent mode has β ~ 2η: UNSTABLE counted either way (said so); under a floor
    # below it the count decides the verdict, and it is open: INCONCLUSIVE
    close = [r for r in rows if r["kernel_decision"] == "close"]
    assert all(r["beta_uncertain"] < CRITERION["floor"] for r in close)
    assert out["verdict"] == "UNSTABLE" and "whichever way it is counted" in out["evidence"], out["evidence"]
    floor = min(r["beta_uncertain"] for r in close) / 10.0
    out, rows = system_verdict(manifest, **dict(CRITERION, floor=floor), notes=io.StringIO())
    assert out["verdict"] == "INCONCLUSIVE", out["evidence"]
