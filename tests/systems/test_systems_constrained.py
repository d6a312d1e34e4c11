"""Constrained rows of A, B and G: one rule (the table of systems/checks.py). Removed with a
note where the removal cannot change β_h, kept as a kernel where there is no constraint,
refused with one line naming the file and the rows where neither reading is safe.

R5.2 (M^1_k) and T3 (M^1_{0,k}) share their basis but for the two end functions (rows 0 and
m − 1 of R5.2; checked below): T3 is R5.2 with μ = 0 at Γ's ends, exactly what an FE code
imposes with a boundary condition on the multiplier space. A displacement dof v_d = 0 is
imposed by a declared list, a unit row or a penalty row of A; all must give the β_h of the
system with that dof removed.
"""
from __future__ import annotations

import io

import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.cli import main
from infsup_contact.systems.engine import level_spectrum, touched_dofs
from infsup_contact.systems.export import suite_system, write_system
from infsup_contact.systems.levels import load_level, system_rows, system_verdict
from infsup_contact.systems.manifest import load_manifest
from infsup_contact.systems.readers import SystemFileError

K, N = 2, 8
NS_STABLE = (8, 16, 32)  # T3 on 4, 8, 16 is INCONCLUSIVE (slope CI up to 0.163) even exactly
CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
RTOL = 1e-10


def _suite(case, n=N):
    A, B, G = suite_system(case, K, n, n)
    return sp.csr_matrix(A), sp.csr_matrix(B), np.asarray(G, float)


def _ends(B, G):
    return np.array([0, B.shape[0] - 1])


# ------------------------------------------------------------------ multiplier rows (B and G)

def _unit_rows(B, G, rows):
    """The FE idiom: B's rows zero, G's rows and columns zero but a unit diagonal."""
    B, G = B.tolil(), G.copy()
    B[rows, :] = 0.0
    G[rows, :] = 0.0
    G[:, rows] = 0.0
    G[rows, rows] = 1.0
    return B.tocsr(), G


def _kept_diagonal(B, G, rows):
    """The same with G's own diagonal kept (rows and columns zeroed around it)."""
    B2, G2 = _unit_rows(B, G, rows)
    G2[rows, rows] = np.diag(G)[rows]
    return B2, G2


def _g_penalty(B, G, rows):
    """A penalty on G's diagonal, B's rows and G's couplings left as assembled."""
    G = G.copy()
    G[rows, rows] = 1e30
    return B, G


MULTIPLIER_PATTERNS = {
    "unit rows in G": (_unit_rows, "constrained multipliers"),
    "G's diagonal kept": (_kept_diagonal, "constrained multipliers"),
    "penalty rows in G": (_g_penalty, "penalty rows of G"),
}


def _level0(tmp_path, A, B, G, extra="", level_extra=""):
    path = write_system(tmp_path, [(1.0 / (i + 1), A, B, G) for i in range(3)], "npz", "toy")
    text = path.read_text().replace("norm: given\n", "norm: given\n" + extra)
    if level_extra:
        text = text.replace("G0.npz}", "G0.npz, " + level_extra + "}")
    path.write_text(text)
    m = load_manifest(path)
    return m, load_level(m, m.levels[0])


def test_t3_is_r52_without_its_end_functions():
    A, B, G = _suite("R5.2")
    A3, B3, G3 = _suite("T3")
    keep = np.setdiff1d(np.arange(B.shape[0]), _ends(B, G))
    assert np.array_equal(G[np.ix_(keep, keep)], G3) and abs(B[keep] - B3).max() == 0.0


@pytest.mark.parametrize("pattern", sorted(MULTIPLIER_PATTERNS))
def test_constrained_multipliers_are_removed(tmp_path, pattern):
    make, said = MULTIPLIER_PATTERNS[pattern]
    A, B, G = _suite("R5.2")
    Bc, Gc = make(B, G, _ends(B, G))
    _, lv = _level0(tmp_path, A, Bc, Gc)
    assert lv.removed_multipliers == 2 and lv.B.shape[0] == B.shape[0] - 2
    assert any(said in note and "rows 0, 16 (0-based)" in note for note in lv.notes), lv.notes
    ref = level_spectrum(*_suite("T3"))
    res = level_spectrum(lv.A, lv.B, lv.G)
    assert res.kernel.dim == 0 and abs(res.beta - ref.beta) <= RTOL * ref.beta


def test_r52_with_end_rows_constrained_is_t3_stable(tmp_path, capsys):
    """T3 exported as R5.2 with its end rows constrained: STABLE, with the note, β_h of T3."""
    levels = []
    for n in NS_STABLE:
        A, B, G = _suite("R5.2", n)
        levels.append((1.0 / n, A) + _unit_rows(B, G, _ends(B, G)))
    path = write_system(tmp_path, levels, "mtx", "R5.2 with end rows constrained")
    err = io.StringIO()
    out, rows = system_verdict(load_manifest(path), **CRITERION, notes=err)
    assert out["verdict"] == "STABLE", out["evidence"]
    assert err.getvalue().count("constrained multipliers") == len(NS_STABLE)
    assert all(r["removed_multipliers"] == 2 and "boundary condition on the multiplier space" in r["notes"]
               for r in rows)
    for r, n in zip(rows, NS_STABLE):
        ref = level_spectrum(*_suite("T3", n))
        assert abs(r["beta"] - ref.beta) <= RTOL * ref.beta
    assert main(["verdict", "--system", str(path), "--expect", "stable"]) == 0
    # the same export without the constraint is R5.2: its two end functions are the kernel
    plain = write_system(tmp_path / "plain", [(1.0 / n,) + _suite("R5.2", n) for n in NS_STABLE], "mtx", "R5.2")
    out, _ = system_verdict(load_manifest(plain), **CRITERION, notes=io.StringIO())
    assert out["verdict"] == "UNSTABLE" and out["kernel_dim"] == 2


# ------------------------------------------------------------------ displacement rows (A, with B over them)

def _a_reference(A, B, G, d):
    keep = np.setdiff1d(np.arange(A.shape[0]), [d])
    return level_spectrum(A[keep][:, keep], B[:, keep], G)


def _a_penalty(A, B, d):
    A = A.tolil()
    A[d, d] = 1e30
    return A.tocsr(), B, ""


def _a_unit(A, B, d):
    A = A.tolil()
    A[d, :] = 0.0
    A[:, d] = 0.0
    A[d, d] = 1.0
    return A.tocsr(), B, ""


def _a_unit_b_zeroed(A, B, d):
    A, _, _ = _a_unit(A, B, d)
    B = B.tolil()
    B[:, d] = 0.0
    return A, B.tocsr(), ""


def _a_declared(A, B, d):
    return A, B, f"constrained: [{d}]"


DISPLACEMENT_PATTERNS = {
    "penalty row, B over it": (_a_penalty, "Dirichlet penalty rows"),
    "unit row, B over it": (_a_unit, "unit rows"),
    "unit row, B not over it": (_a_unit_b_zeroed, "identity rows"),
    "declared, B over it": (_a_declared, "declared constrained dofs"),
}


@pytest.mark.parametrize("pattern", sorted(DISPLACEMENT_PATTERNS))
def test_constrained_displacements_give_one_beta(tmp_path, pattern):
    """v_d = 0 however it is marked: the same β_h, that of the system without d, to 1e-10."""
    make, said = DISPLACEMENT_PATTERNS[pattern]
    A, B, G = _suite("T3")
    d = int(touched_dofs(B)[3])  # a Γ dof that B couples to
    Ac, Bc, level_extra = make(A, B, d)
    _, lv = _level0(tmp_path, Ac, Bc, G, level_extra=level_extra)
    assert lv.removed == 1 and any(said in note for note in lv.notes), lv.notes
    if "B over it" in pattern:
        assert any("entries on them dropped" in note for note in lv.notes)
    ref = _a_reference(A, B, G, d)
    assert abs(level_spectrum(lv.A, lv.B, lv.G).beta - ref.beta) <= RTOL * ref.beta


def test_a_multiplier_coupled_only_to_fixed_dofs_is_a_kernel(tmp_path):
    """Not a constraint of the multiplier: B's row was not zero as exported, it couples only to
    dofs v = 0. A kernel of Bᵀ (UNSTABLE unless declared), named in a note."""
    A, B, G = _suite("T3")
    row = B.getrow(3)
    Ac = A.tolil()
    for d in row.indices:
        Ac[d, d] = 1e30
    _, lv = _level0(tmp_path, Ac.tocsr(), B, G)
    # row 3's dofs carry all of rows 2 and 4 too (P2 functions on the same elements)
    assert any("3 multipliers couple only to the removed dofs (rows 2, 3, 4 (0-based))" in note
               for note in lv.notes), lv.notes
    res = level_spectrum(lv.A, lv.B, lv.G)
    assert res.kernel.dim >= 3 and res.beta == 0.0  # e_2, e_3, e_4 at least (rows 1, 5 lose conditions too)


# ------------------------------------------------------------------ kept as a kernel, and refused

def test_a_zero_row_of_b_coupled_in_g_is_a_kernel_not_a_constraint(tmp_path):
    """A zero row of B whose G row couples it (a P1–P1 corner pressure): no constraint pattern,
    so nothing is removed (that would change β_h); a kernel, UNSTABLE, with a note."""
    A, B, G = _suite("T3")
    Bz = B.tolil()
    Bz[2, :] = 0.0
    _, lv = _level0(tmp_path, A, Bz.tocsr(), G)
    assert lv.removed_multipliers == 0 and lv.B.shape[0] == B.shape[0]
    assert any("zero rows (2 (0-based)) kept: a kernel" in note for note in lv.notes), lv.notes
    assert level_spectrum(lv.A, lv.B, lv.G).kernel.dim == 1


def test_multipliers_in_neither_b_nor_g_are_removed(tmp_path):
    A, B, G = _suite("T3")
    Bz, Gz = B.tolil(), G.copy()
    Bz[[1, 5], :] = 0.0
    Gz[[1, 5], :] = 0.0
    Gz[:, [1, 5]] = 0.0
    _, lv = _level0(tmp_path, A, Bz.tocsr(), Gz)
    assert lv.removed_multipliers == 2 and any("in neither B nor G" in note for note in lv.notes)


def _incomplete_unit_row(A, B, G):
    Bz, Gz = B.tolil(), G.copy()
    Bz[[0, 4], :] = 0.0
    Gz[[0, 4], [0, 4]] = 1.0  # the unit diagonal set, the row and column left coupled
    return A, Bz.tocsr(), Gz, "", "G0.npz", r"rows 0, 4 \(0-based\).*G still couples them"


def _g_penalty_refused(A, B, G):
    _, Gp = _g_penalty(B, G, [0, 6])
    return A, B, Gp, "tgv: refuse\n", "G0.npz", r"2 penalty rows of G .*rows 0, 6 \(0-based\).*tgv: refuse"


def _a_penalty_refused(A, B, G):
    Ap, _, _ = _a_penalty(A, B, 5)
    return Ap, B, G, "tgv: refuse\n", "A0.npz", "1 Dirichlet penalty rows.*tgv: refuse"


REFUSED = {"incomplete unit row of G": _incomplete_unit_row, "penalty in G, tgv: refuse": _g_penalty_refused,
           "penalty in A, tgv: refuse": _a_penalty_refused}


@pytest.mark.parametrize("pattern", sorted(REFUSED))
def test_refused_patterns_are_one_line(tmp_path, capsys, pattern):
    A, B, G, extra, name, said = REFUSED[pattern](*_suite("T3"))
    with pytest.raises(SystemFileError, match=said) as err:
        _level0(tmp_path, A, B, G, extra=extra)
    assert name in str(err.value) and "\n" not in str(err.value)
    path = tmp_path / "levels.yaml"
    assert main(["verdict", "--system", str(path)]) == 2
    msg = capsys.readouterr().err.strip()
    assert len(msg.splitlines()) == 1 and name in msg and "Traceback" not in msg


def test_rows_report_what_was_removed(tmp_path):
    A, B, G = _suite("R5.2")
    Bc, Gc = _unit_rows(B, G, _ends(B, G))
    path = write_system(tmp_path, [(1.0 / (i + 1), A, Bc, Gc) for i in range(3)], "npz", "toy")
    rows = system_rows(load_manifest(path), notes=io.StringIO())
    assert all(r["removed_multipliers"] == 2 and r["m"] == B.shape[0] - 2 for r in rows)


def _jacobi(A, B):
    """A scaled to a unit diagonal (and B with it): the same pencil, unit rows everywhere."""
    d = np.sqrt(A.diagonal())
    return sp.csr_matrix(sp.diags(1.0 / d) @ A @ sp.diags(1.0 / d)), sp.csr_matrix(B @ sp.diags(1.0 / d))


def test_a_unit_diagonal_everywhere_still_eliminates_unit_rows_on_an_interface(tmp_path):
    """A Jacobi-scaled contact A: a dof coupled to nothing but touched by B is not told from the
    others by its diagonal, but B couples Γ only and an element bubble has no trace there: the
    unit row is a constrained dof, eliminated, β_h that of the system without it."""
    A, B, G = _suite("T3")
    J, Bj = _jacobi(A, B)
    dof = int(touched_dofs(B)[3])
    Jd, _, _ = _a_unit(J, Bj, dof)
    _, lv = _level0(tmp_path, Jd, Bj, G)
    assert lv.removed == 1 and any("1 unit rows" in note for note in lv.notes), lv.notes
    assert not any("bubble" in note for note in lv.notes)
    ref = _a_reference(J, Bj, G, dof)
    assert abs(level_spectrum(lv.A, lv.B, lv.G).beta - ref.beta) <= RTOL * ref.beta


def test_a_unit_diagonal_everywhere_keeps_decoupled_dofs_of_a_whole_body_coupling(tmp_path):
    """A Jacobi-scaled A whose B touches every dof (a Stokes divergence, not an interface): a
    decoupled dof touched by B may be an element bubble (MINI's): kept, with the note."""
    A, B, G = _suite("T3")
    J, _ = _jacobi(A, B)
    Bw = sp.csr_matrix(np.random.default_rng(1).standard_normal((B.shape[0], A.shape[0])))
    Jd, _, _ = _a_unit(J, Bw, 7)
    _, lv = _level0(tmp_path, Jd, Bw, G)
    assert lv.removed == 0 and any("kept (element bubbles, as MINI's; fixed dofs? declare them in "
                                   "levels[0].constrained)" in note for note in lv.notes), lv.notes


def test_a_decoupled_dof_on_an_interface_with_another_diagonal_is_refused(tmp_path, capsys):
    """Coupled to nothing in A, touched by a contact B, diagonal 2.5 (not the unit-row idiom): no
    element bubble reaches Γ, and eliminating an unmarked dof could change β_h: refused in one line
    naming the file, the row and the key to declare it with."""
    A, B, G = _suite("T3")
    dof = int(touched_dofs(B)[3])
    Ad, _, _ = _a_unit(A, B, dof)
    Ad = Ad.tolil()
    Ad[dof, dof] = 2.5
    with pytest.raises(SystemFileError, match=rf"A0.npz: rows {dof} \(0-based\): coupled to nothing in A, touched by "
                                              r"B, diagonal 2.5 .*declare them in levels\[0\]\.constrained"):
        _level0(tmp_path, Ad.tocsr(), B, G)
    assert main(["verdict", "--system", str(tmp_path / "levels.yaml")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_a_decoupled_dof_under_producer_zeros_of_b_is_an_identity_row(tmp_path):
    """Kratos' Dirichlet rows (row and column zeroed, the stiffness diagonal kept) with B's column
    holding only round-off (1e-14 max|b|: a producer zero): B does not touch it, so it is removed as
    an identity row, not refused as an unmarked dof on the interface."""
    A, B, G = _suite("T3")
    dof = int(touched_dofs(B)[3])
    Ad, Bd, _ = _a_unit_b_zeroed(A, B, dof)
    Ad, Bd = Ad.tolil(), Bd.tolil()
    Ad[dof, dof] = 4.0
    Bd[2, dof] = 1e-14 * abs(B).max()
    _, lv = _level0(tmp_path, Ad.tocsr(), Bd.tocsr(), G)
    assert lv.removed == 1 and any("1 identity rows" in note for note in lv.notes), lv.notes


def _dolfinx_unassembled_bcs(case, n):
    """A DOLFINx-style k = 1 level: every Dirichlet dof (∂Ω_i off Γ, Γ's end vertices included: 26
    of 50 at N = 4) a unit row of A (diagonal 1, row and column zero), B assembled without the bcs
    (its columns at Γ's four end vertices are the exact ∫ψ_i φ_end), and the norm: H description."""
    from types import SimpleNamespace
    from pathlib import Path

    from infsup_contact.systems.export import suite_levels
    from infsup_contact.systems.mortar_distance import _traces, exact_coupling
    from infsup_contact.systems.multiplier_basis import Gamma, describe

    (h, A, B, G, mult, traces), = suite_levels(case, 1, (n,), 0)[0]
    fixed = 2 * (n + 1) ** 2 - A.shape[0]
    full, nxt = [], A.shape[0]
    for t in traces:  # each body's whole P1 trace, the end hats in new columns (the Dirichlet dofs)
        full.append({"basis": "lagrange", "degree": 1, "breakpoints": t["breakpoints"], "sign": t["sign"],
                     "columns": [nxt] + list(t["columns"]) + [nxt + 1]})
        nxt += 2
    gamma = Gamma("segment", (1.0,))
    parsed = _traces(SimpleNamespace(path=Path("m.yaml"), gamma=gamma), SimpleNamespace(index=0, traces=full),
                     A.shape[0] + fixed)
    exact = exact_coupling(describe("m.yaml", 0, mult, gamma), parsed, A.shape[0] + fixed)
    Bd = sp.hstack([B, exact[:, A.shape[0]:]], format="csr")
    return (h, sp.block_diag([A, sp.identity(fixed)], format="csr"), Bd, G, mult), fixed


@pytest.mark.parametrize("norm", ["H", "L2"])
@pytest.mark.parametrize("case", ["R5.2", "R5.4"])
def test_dolfinx_dirichlet_unit_rows_touched_by_b_are_eliminated(tmp_path, case, norm):
    """A real-client rerun: at N = 4 the Dirichlet unit rows are most of A's diagonal, which hid them as a
    "Jacobi-scaled" A and kept the four B touches ("element bubbles?"): kernel 0 where R5.2 has 2
    and R5.4 1, β 19 % off. Now they are eliminated, with the manifest's gamma (norm: H) and
    without it (norm: L2, the interface told from B), and the level is the suite's own."""
    from infsup_contact.systems.export import suite_levels

    n = 4
    level, fixed = _dolfinx_unassembled_bcs(case, n)
    assert fixed == 26 and np.sum(level[1].diagonal() == 1.0) == 26 and level[1].shape[0] == 50
    assert _b_entries_on_new(level[2], level[1].shape[0] - fixed) == (8 if case == "R5.2" else 4)
    levels, _, gamma = suite_levels(case, 1, (n,), 0)
    if norm == "L2":
        level, gamma = level[:4], None
    rows = {}
    for label, lv in (("dolfinx", level), ("suite", levels[0][:len(level)])):
        path = write_system(tmp_path / label, [lv], "mtx", label, norm, gamma=gamma)
        err = io.StringIO()
        rows[label], = system_rows(load_manifest(path, min_levels=1), notes=err)
        assert "bubble" not in err.getvalue()
    d, s = rows["dolfinx"], rows["suite"]
    assert d["removed_dofs"] == fixed and d["kernel_detected"] == s["kernel_detected"] >= 1
    assert abs(d["smallest_nonzero"] - s["smallest_nonzero"]) <= RTOL * s["smallest_nonzero"]


def _b_entries_on_new(B, first):
    block = sp.csc_matrix(B)[:, first:]
    block.eliminate_zeros()
    return block.nnz


@pytest.mark.parametrize("what", ["multipliers", "dofs"])
def test_nothing_left_is_one_line(tmp_path, what):
    """Every multiplier (or every dof) constrained: refused in one line, not an empty eigenproblem."""
    A, B, G = _suite("T3")
    level_extra = ""
    if what == "multipliers":
        B, G = _unit_rows(B, G, np.arange(B.shape[0]))
        B = sp.csr_matrix(B.shape)
        name = "B0.npz"
    else:
        level_extra = f"constrained: {list(range(A.shape[0]))}"
        name = "A0.npz"
    with pytest.raises(SystemFileError, match="is constrained .*nothing is left") as err:
        _level0(tmp_path, A, B, G, level_extra=level_extra)
    assert name in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("route", ["gamma-dense", "shift-invert"])
def test_zero_coupling_is_a_kernel_of_every_multiplier(tmp_path, route):
    """B = 0 with the diagonal P0 mass of equal cells, not unit rows (FreeFEM's shipped mortar tutorial, whose
    skeleton integrals come out empty): no row is singled out from the others, so none is a
    constraint; every multiplier is in the kernel of Bᵀ (dim M), β_h = 0, UNSTABLE — it was
    refused as "every multiplier row constrained", then crashed on the deflated route."""
    levels = []
    for n in NS_STABLE:
        A, B, _ = _suite("T4", n)
        m = B.shape[0]
        levels.append((1.0 / n, A, sp.csr_matrix(B.shape), np.eye(m) / m))  # P0 on m equal cells: G = I/m
    path = write_system(tmp_path, levels, "npz", "B = 0")
    manifest = load_manifest(path)
    lv = load_level(manifest, manifest.levels[-1])
    assert lv.removed_multipliers == 0 and any("kept: a kernel" in note for note in lv.notes), lv.notes
    res = level_spectrum(lv.A, lv.B, lv.G, route=route)
    assert res.kernel.dim == lv.B.shape[0] and res.beta == 0.0
    head, rows = system_verdict(manifest, **CRITERION)
    assert head["verdict"] == "UNSTABLE"
    assert [int(r["kernel_detected"]) for r in rows] == [_suite("T4", n)[1].shape[0] for n in NS_STABLE]
