"""The Petrov–Galerkin pair (trial M ≠ test N, CalculiX's PGLINMORTAR) and the linear dual space on
QUAD8 faces (LINMORTAR): biorthogonality, N = M as a second route to β_h, the kernel of S_PG, and
the one-line refusals."""
import io
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from helpers.cli import run_in_process
from infsup_contact.discretization.face.shapes.serendipity import SERENDIPITY
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.discretization.gamma.quadrature import gauss_legendre
from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.discretization.spaces.spec import SpaceSpec
from infsup_contact.errors import InputError
from infsup_contact.models.membranes3d import MEMBRANES3D
from infsup_contact.solvers.infsup import beta_rows_all, beta_table
from infsup_contact.solvers.request import BetaRequest, MeshOptions

HEX20 = MeshOptions(element="hex20")
EPS = np.finfo(float).eps


def _exact_rule(partition):
    """Points and weights of a Gauss rule exact for Q_5 on every rectangle (products of two Q1 pieces)."""
    t, w = gauss_legendre(3)
    pts, wts = [], []
    for g in (np.asarray(partition.xs), np.asarray(partition.ys)):
        a, b = g[:-1, None], g[1:, None]
        pts.append((0.5 * (a + b) + 0.5 * (b - a) * t).ravel())
        wts.append((0.5 * (b - a) * w).ravel())
    X, Y = np.meshgrid(*pts, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel()]), np.outer(*wts).ravel()


@pytest.mark.parametrize("dual,hats", [("LINDUAL0-Q8", "LIN0-Q8"), ("LINDUAL-Q8", "T5")])
def test_linear_dual_is_biorthogonal_to_the_q1_hats(dual, hats):
    """∫ψ_j φ_k = δ_jk ∫φ_k on a non-uniform grid (the mass stencil is not diagonal, so this is the
    dual construction, not a coincidence), and Σ ψ_j = 1 (constants kept, as DUAL does)."""
    part = TensorPartition(np.array([0.0, 0.1, 0.35, 0.5, 0.8, 1.0]), np.array([0.0, 0.3, 0.45, 0.7, 1.0]))
    psi, phi = (SERENDIPITY.space(SPACES[c], 2, part) for c in (dual, hats))
    assert psi.dim == phi.dim
    x, w = _exact_rule(part)
    P, F = psi.evaluate(x), phi.evaluate(x)
    assert np.allclose((P * w[:, None]).T @ F, np.diag(w @ F), rtol=0, atol=1e-14)
    x = np.random.default_rng(0).random((200, 2))
    assert np.allclose(psi.evaluate(x).sum(axis=1), 1.0, rtol=0, atol=1e-13)


@pytest.mark.parametrize("case,model,mesh,n1,n2", [
    ("LIN0-Q8", MEMBRANES3D, HEX20, 4, 5),   # no kernel, non-matching
    ("T5", MEMBRANES3D, HEX20, 4, 4),        # the four corner modes
    ("T3", None, MeshOptions(), 8, 9),       # the paper's segment
    ("R5.4", None, MeshOptions(), 8, 8),     # one zero mode on the segment
])
def test_a_pair_with_n_equal_m_is_the_symmetric_beta(case, model, mesh, n1, n2):
    """γ_h = σ_min(L⁻¹ S L⁻ᵀ) = λ_min(S, G) = β_h² for N = M: an SVD of the unsymmetrized S against the
    symmetric pencil's eigensolver. |β_PG² − β_h²| <= 10 η, η = dim M ε s_max the round-off level of the
    reduced matrix (= β²/gap of the row); the kernels agree."""
    pair = replace(SPACES[case], id=f"PG-{case}", trial_space=case, test_space=case)
    rows = beta_rows_all("structured", 2, n1, n2, [case, pair], c_pairs=((1.0, 1.0), (1.0, 10.0)), mesh=mesh,
                         **({} if model is None else {"model": model}))
    sym, pg = [r for r in rows if r["case"] == case], [r for r in rows if r["case"] == pair.id]
    assert len(sym) == len(pg) == 4
    for a, b in zip(sym, pg):
        assert (a["norm"], a["c2"]) == (b["norm"], b["c2"])
        assert a["kernel_dim"] == b["kernel_dim"] == b["structural_kernel_dim"] and b["kernel_decision"] == "clear"
        first = b["beta"] if b["kernel_dim"] == 0 else b["smallest_nonzero"]     # the first value above the kernel
        eta = first ** 2 / b["gap_over_roundoff"]
        assert abs(a["beta"] ** 2 - b["beta"] ** 2) <= 10 * eta
        assert abs(a["smallest_nonzero"] ** 2 - b["smallest_nonzero"] ** 2) <= 10 * eta


def test_pglin0_is_invertible_and_pglin_has_the_corner_modes_of_its_trial_space():
    """Matching N = 4: PGLIN0-Q8 has no kernel (γ_h > 0, decided clearly); PGLIN-Q8 has exactly the 4
    proven modes, and its worst mode lies in ker B_Mᵀ of the trial space: the corner products of the 1D
    end duals, supported on the four corner cells (coefficients elsewhere at round-off)."""
    modes = []
    request = BetaRequest("structured", 2, 4, 4, ("PGLIN0-Q8", "PGLIN-Q8"), model=MEMBRANES3D, mesh=HEX20)
    rows = pd.DataFrame(beta_table(request, modes=modes)).set_index(["case", "norm"])
    assert (rows.kernel_decision == "clear").all() and (rows.kernel_margin_decades > 6).all()
    assert (rows.loc["PGLIN0-Q8"].kernel_dim == 0).all() and (rows.loc["PGLIN0-Q8"].beta > 0.1).all()
    assert (rows.loc["PGLIN-Q8"].kernel_dim == 4).all() and (rows.loc["PGLIN-Q8"].structural_kernel_dim == 4).all()
    assert (rows.loc["PGLIN-Q8"].beta == 0).all()
    worst = [m for m in modes if m.keys["case"] == "PGLIN-Q8"]
    assert len(worst) == 2 and all(m.in_kernel for m in worst)
    corners = {a * 5 + b for a in (0, 4) for b in (0, 4)}  # LINDUAL-Q8 on 4 × 4: 5 × 5 vertex functions
    for m in worst:
        off = np.delete(m.vector, sorted(corners))
        assert np.linalg.norm(off) < 1e-8 and abs(np.linalg.norm(m.vector) - 1) < 1e-12


def test_pglin0_verdict_and_worst_mode_run_on_the_command_line(tmp_path):
    code, out, err = run_in_process(["verdict", "--model", "membranes3d", "--element", "hex20", "--case", "PGLIN-Q8",
                                     "--k", "2", "--N", "4", "5", "6"])
    assert code == 0, err
    assert pd.read_csv(io.StringIO(out)).verdict.tolist() == ["UNSTABLE"]
    code, out, err = run_in_process(["beta", "--model", "membranes3d", "--element", "hex20", "--case", "PGLIN0-Q8",
                                     "--k", "2", "--N1", "4", "--N2", "5", "--worst-mode", str(tmp_path / "m.csv")])
    assert code == 0, err
    frame, mode = pd.read_csv(io.StringIO(out)), pd.read_csv(tmp_path / "m.csv")
    assert list(frame.norm) == ["H", "L2"] and (frame.kernel_dim == 0).all() and frame.beta.notna().all()
    assert set(mode.case) == {"PGLIN0-Q8"} and np.isclose(mode.mu.abs().max(), 1.0)


@pytest.mark.parametrize("args,key,words", [
    (["--case", "PGLIN0-Q8", "--k", "2"], "case", "HEX20 bodies (element hex20)"),                 # the segment
    (["--model", "membranes3d", "--element", "hex", "--case", "PGLIN0-Q8", "--k", "2"], "case", "element hex20"),
    (["--model", "membranes3d", "--element", "tet", "--case", "PGLIN-Q8", "--k", "2"], "case", "element hex20"),
    (["--model", "membranes3d", "--element", "hex20", "--case", "PGLIN0-Q8", "--k", "1"], "k", "k >= 2"),
    (["--model", "membranes3d", "--element", "hex20", "--case", "PGLIN0-Q8", "--k", "3"], "k", "expected 2"),
])
def test_the_pair_elsewhere_is_refused_in_one_line(args, key, words):
    code, out, err = run_in_process(["beta", *args, "--N1", "4", "--N2", "4"])
    assert code == 2 and f"--{key}" in err and words in err and len(err.strip().splitlines()) == 1, err


def test_a_pair_too_large_for_the_dense_svd_is_refused_naming_n():
    with pytest.raises(InputError) as err:
        BetaRequest("structured", 2, 40, 41, ("PGLIN0-Q8",), model=MEMBRANES3D, mesh=HEX20)
    assert err.value.key == "N2" and "1500" in str(err.value)


def test_consumers_of_one_basis_refuse_the_pair_and_the_spec_needs_both_roles():
    part = TensorPartition(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    with pytest.raises(InputError, match="Petrov–Galerkin pair LINDUAL0-Q8 × LIN0-Q8"):
        registry.case_space("PGLIN0-Q8", 2, part, SERENDIPITY)
    assert registry.case_space("PGLIN0-Q8", 2, part, SERENDIPITY, pair=True).dim == 9
    with pytest.raises(InputError) as err:
        SpaceSpec("X", "x", "x", None, lambda k: 1, gamma_dims=(2,), test_space="T5")
    assert err.value.key == "space"
    with pytest.raises(InputError) as err:
        registry.register(replace(SPACES["PGLIN0-Q8"], id="PG-UNKNOWN", trial_space="NOPE"))
    assert err.value.key == "trial_space" and "PG-UNKNOWN" not in SPACES
