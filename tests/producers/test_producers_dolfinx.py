"""The DOLFINx producer (examples/producers/dolfinx/export.py), run by its own interpreter
(``make producers-dolfinx`` builds .venv-dolfinx): what it exports is checked against the
mathematics — A SPD, B the exact mortar coupling of the basis its manifest describes (the
meshes match: DOLFINx's quadrature is exact there), G the L² mass of that basis — and its
L² β_h against ``beta --case`` on the suite's structured meshes (the same triangles)."""
from __future__ import annotations

import numpy as np
import pytest

import helpers.producers as P

PYTHON = P.ROOT / ".venv-dolfinx" / "bin" / "python"
SCRIPT = P.ROOT / "examples" / "producers" / "dolfinx" / "export.py"
if not P.python_has(PYTHON, "dolfinx_solver"):
    pytest.skip(f"DOLFINx is not installed ({PYTHON} missing or without dolfinx_solver): run "
                "`make producers-dolfinx`", allow_module_level=True)

SPACES = {"T3-k1": 1, "T3-k2": 2, "R5.2-k1": 1, "R5.2-k2": 2, "T4-k2": 2, "R5.4-k1": 1, "R5.4-k2": 2,
          "T5-k2": 2}
NS = (4, 8, 16)
_cache = {}


@pytest.fixture(scope="module")
def export(tmp_path_factory):
    """The manifest of one space on NS, exported once per module run."""
    def get(space):
        if space not in _cache:
            _cache[space] = P.run_export(PYTHON, SCRIPT, tmp_path_factory.mktemp(space), space, NS)
        return _cache[space]
    return get


def test_list_spaces():
    code, out, err = P.run_cli(PYTHON, SCRIPT, "--list-spaces")
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert [line.split("\t")[0] for line in lines] == list(SPACES)
    assert all(len(line.split("\t")) == 2 and line.split("\t")[1] for line in lines)


@pytest.mark.parametrize("args, names", [
    (("--out", "OUT", "--space", "T3-k1", "--N", "4", "8", "--offset", "1"), "--offset 1"),
    (("--out", "OUT", "--space", "Q9", "--N", "4"), "--space 'Q9'"),
    (("--out", "OUT", "--space", "T3-k1", "--N", "0", "4"), "--N 0"),
    (("--out", "OUT", "--space", "T3-k1", "--N", "4", "100000"), "--N 100000"),
    (("--out", "OUT", "--space", "T3-k1", "--N", "8", "4"), "increasing"),
    (("--out", "OUT", "--space", "T3-k1", "--N", "4", "four"), "invalid int value"),
    (("--space", "T3-k1", "--N", "4"), "--out"),
    (("--out", "FILE", "--space", "T3-k1", "--N", "4"), "not a directory"),
    (("--out", "/proc/no/such/dir", "--space", "T3-k1", "--N", "4", "5", "6"), "--out /proc/no/such/dir"),
])
def test_bad_arguments_one_line_exit_2(tmp_path, args, names):
    P.check_refused(PYTHON, SCRIPT, tmp_path, args, names)


@pytest.mark.parametrize("space", SPACES)
def test_A_spd_G_mass_B_exact(export, space):
    """A SPD; G = the L² mass of the described basis (rows in DOLFINx's order); B = the exact
    ∫_Γ μ_i (φ2 − φ1) of that basis against the bodies' Γ traces, zero off Γ and on the
    Dirichlet dofs (columns the bcs zeroed); the T3 end rows are constrained rows exactly."""
    manifest = export(space)
    for i, n in enumerate(NS):
        lv, A, B, G = P.read_level(manifest, i)
        P.check_spd(A)
        constrained = P.constrained_rows(B, G)  # the dirichletbc's rows: zero in B, unit in G
        assert len(constrained) == (2 if space.startswith("T3") else 0)
        assert P.mass_mismatch(G, lv["multipliers"], constrained) <= P.ROUNDOFF
        coords, n1 = P.body_coordinates(PYTHON, SCRIPT, n, space, ns=NS)
        exact, on_gamma = P.exact_coupling(lv["multipliers"], coords, n1, SPACES[space])
        _, rows = P.described_space(lv["multipliers"])
        assert sorted(rows) == list(range(B.shape[0]))  # the whole space described, ends included
        rows = rows[~np.isin(rows, constrained)]
        Bd = B.toarray()
        ends = on_gamma & (np.isclose(coords[:, 0], 0.0) | np.isclose(coords[:, 0], 1.0))
        assert np.all(Bd[:, ~on_gamma | ends] == 0)
        inner = on_gamma & ~ends
        assert np.abs(Bd[np.ix_(rows, inner)] - exact[np.ix_(rows, inner)]).max() <= P.ROUNDOFF * np.abs(exact).max()
        if space.startswith("T3"):  # the constrained rows are the functions at Γ's two ends
            space_, all_rows = P.described_space(lv["multipliers"])
            ends_at = space_.nodes()[np.isin(all_rows, constrained)]
            assert np.allclose(np.sort(ends_at), [0.0, 1.0])


@pytest.mark.parametrize("space", ["T3-k2", "R5.4-k1", "T5-k2"])
def test_B_on_a_polynomial_trace(export, space):
    """B v for v1 = x(1 − x) y, v2 = 0 (zero on ∂Ω1 \\ Γ; in P_k for k = 2, and for k = 1 its
    interpolant): B v = −∫_Γ I_h(x(1 − x)) μ_i exactly, the quadrature being exact here."""
    k = SPACES[space]
    lv, A, B, G = P.read_level(export(space), 1)
    coords, n1 = P.body_coordinates(PYTHON, SCRIPT, NS[1], space, ns=NS)
    v = np.where(np.arange(len(coords)) < n1, coords[:, 0] * (1 - coords[:, 0]) * coords[:, 1], 0.0)
    exact, _ = P.exact_coupling(lv["multipliers"], coords, n1, k)
    space_, rows = P.described_space(lv["multipliers"])
    free = ~np.isin(rows, P.constrained_rows(B, G))  # the dirichletbc zeroed the others' rows of B
    rows = rows[free]
    Bv, want = B @ v, exact @ v
    assert np.abs(Bv[rows] - want[rows]).max() <= P.ROUNDOFF * np.abs(B).sum(axis=1).max() * np.abs(v).max()
    if k == 2:  # the trace is x(1 - x) itself: ∫ x(1 − x) μ by Gauss on the multipliers' partition
        x, w = P.gauss_on_union(space_.breakpoints)
        direct = -(space_.evaluate(x) * (w * x * (1 - x))[:, None]).sum(axis=0)[free]
        assert np.abs(Bv[rows] - direct).max() <= P.ROUNDOFF * np.abs(direct).max()


@pytest.mark.parametrize("space", ["R5.2-k1", "T4-k2", "R5.4-k1", "R5.4-k2", "T5-k2"])
def test_L2_beta_matches_beta_case(export, space):
    """Same triangles (create_rectangle's "right" diagonals are the suite's structured
    family): the L² β above the kernel of the DOLFINx system equals that of ``beta --case``
    (NGSolve's assembly), level by level."""
    rows = P.beta_rows(P.strip_manifest(export(space), "L2"))
    case, k = space.split("-k")
    for n, row in zip(NS, rows):
        ref = P.suite_beta(case, int(k), n, n)
        assert float(row["smallest_nonzero"]) == pytest.approx(float(ref["smallest_nonzero"]), rel=1e-9)


def test_T3_without_its_constrained_rows_matches_beta_case(export, tmp_path):
    """T3's two constrained rows removed by hand (the rows the manifest's ``rows`` leaves
    out): β then equals ``beta --case T3`` in L²."""
    import scipy.io
    import yaml

    manifest = export("T3-k2")
    data = yaml.safe_load(manifest.read_text())
    for i, lv in enumerate(data["levels"]):
        _, A, B, G = P.read_level(manifest, i)
        rows = lv.pop("multipliers")["rows"]
        lv.pop("traces")
        for key, M in (("B", B[rows]), ("G", G[rows][:, rows]), ("A", A)):
            scipy.io.mmwrite(tmp_path / f"{key}{i}.mtx", M, precision=17)
            lv[key] = f"{key}{i}.mtx"
    data.update(norm="L2")
    data.pop("gamma")
    (tmp_path / "levels.yaml").write_text(yaml.safe_dump(data))
    for n, row in zip(NS, P.beta_rows(tmp_path / "levels.yaml")):
        ref = P.suite_beta("T3", 2, n, n)
        assert float(row["beta"]) == pytest.approx(float(ref["beta"]), rel=1e-9)
        assert row["kernel_dim"] == "0"


@pytest.mark.parametrize("space", SPACES)
def test_manifest_dry_run(export, space):
    """The L² and h-L² copies validate, and the ``norm: H`` manifest itself (T3's rows the
    dirichletbc constrained included)."""
    for norm in ("L2", "h-L2"):
        code, _, err = P.verdict_row(P.strip_manifest(export(space), norm), "--dry-run")
        assert code == 0, err
    code, _, err = P.verdict_row(export(space), "--dry-run")
    assert code == 0, err


def test_T3_norm_H(tmp_path):
    """T3 with DOLFINx's dirichletbc on the multipliers is Thm 3's space: STABLE in H^{-1/2}_00
    once the two constrained end rows are set aside (as the h-L² copy's are): the manifest
    describes DOLFINx's whole P_2 space, the certifier removes the two rows its dirichletbc
    constrained."""
    manifest = P.run_export(PYTHON, SCRIPT, tmp_path, "T3-k2", (8, 16, 32))  # N = 4: pre-asymptotic
    code, row, err = P.verdict_row(manifest)
    assert row is not None and row["verdict"] == "STABLE", err


@pytest.mark.parametrize("norm", ["h-L2", "H"])
@pytest.mark.parametrize("space, verdict", [("R5.2-k1", "UNSTABLE"), ("R5.2-k2", "UNSTABLE"),
                                            ("T4-k2", "STABLE"), ("T5-k2", "STABLE")])
def test_verdicts(tmp_path, space, verdict, norm):
    """R5.2 has a kernel (dim M − dim of the Γ traces > 0: UNSTABLE in any norm); T4 and T5 are
    H^{-1/2}-stable (Thms 4, 5), hence stable in the weaker h-L² norm too. On N = 8, 16, 32:
    T5's h-L² β rises 0.412 → 0.433 from N = 4 to 8 (pre-asymptotic: INCONCLUSIVE on 4, 8, 16)."""
    manifest = P.run_export(PYTHON, SCRIPT, tmp_path, space, (8, 16, 32))
    code, row, err = P.verdict_row(manifest if norm == "H" else P.strip_manifest(manifest, norm))
    assert row is not None, err
    assert row["verdict"] == verdict, row["evidence"]


@pytest.mark.parametrize("space", ["R5.2-k2", "T4-k2", "R5.4-k2", "T5-k2"])
def test_certifier_coupling_distance(export, space):
    """With the manifest's ``traces`` the certifier measures B's distance to the exact mortar
    coupling itself: round-off here (matching meshes, FFCx's quadrature exact)."""
    for row in P.beta_rows(export(space)):
        assert float(row["coupling_distance"]) <= 10 * P.ROUNDOFF
