"""The 3D β_h benchmark (bench/beta_models.py FACE_BENCH, bench/face_schur.py): its three routes give the same
β_h, one of them checked against the full saddle-point pencil, and ``infsup-contact bench --what
face`` writes the ratio columns and refuses bad input in one line."""
import io

import numpy as np
import pandas as pd
import pytest

from infsup_contact.bench import beta_bench, face_schur
from infsup_contact.bench.beta_models import FACE_BENCH, FACE_COLUMNS
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.solvers.infsup import saddle_point_beta
from infsup_contact.contact.contact import contact_qp

from helpers.cli import run_in_process
from infsup_contact.discretization.spaces import registry


@pytest.mark.parametrize("n", [2, 3])
def test_routes_agree_on_beta(n):
    rows = beta_bench.bench_beta(FACE_BENCH, [n], [1], repeats=1, element="hex")
    beta = [r for r in rows if r["what"] == "face_beta"]
    assert [r["route"] for r in beta] == ["ours", "ours_core", "limit"]
    for r in beta:
        assert r["max_abs_diff"] <= 1e-8, r
        assert r["n_problems"] == 2 * len(registry.common_ids(1))     # k = 1: no quadratic face elements


def test_schur_routes_give_one_schur_complement():
    """The face_schur rows: every route of gamma_factorization timed on the same bodies gives S to
    round-off (relative to the first route, PARDISO), one row per route."""
    rows = [r for r in beta_bench.bench_beta(FACE_BENCH, [3], [2], repeats=1, element="hex")
            if r["what"] == "face_schur"]
    assert [r["route"] for r in rows] == list(face_schur.SCHUR_ROUTES)
    assert all(r["max_abs_diff"] <= 1e-12 for r in rows), rows
    assert rows[0]["ratio_to_ours"] == 1.0


def test_core_beta_equals_the_full_pencil():
    """β_h of ours_core (Γ-reduced, B A⁻¹ Bᵀ m = β² G m) = β_h of the full pencil
    [[A, Bᵀ], [B, 0]] x = σ [[A, 0], [0, G]] x, an independent dense route, for a stable space."""
    setup = beta_bench.BetaSetup(FACE_BENCH, 2, 1, element="hex")
    core = beta_bench.beta_ours_core(setup)
    case = next(c for c in setup.cases if beta_bench.beta_ours(setup)[c, "H"]["kernel_dim"] == 0)
    Bs = [coupling_matrix(s.trace, setup.spaces[case], 1) for s in setup.sides]
    A, B, _ = contact_qp(setup.sides, Bs, [np.zeros(s.ndof) for s in setup.sides])  # the assembled pencil
    B = B.toarray()
    for nm in FACE_BENCH.norms:
        G = setup.gamma.gram(setup.spaces[case], nm)[0]
        assert abs(np.sqrt(core[case, nm][0]) - saddle_point_beta(A, B, G)) <= 1e-10


def test_cli_csv_has_the_ratio_columns():
    code, out, err = run_in_process(["bench", "--what", "face", "--N", "2", "--k", "1", "--repeats", "1"])
    assert code in (0, None), err
    frame = pd.read_csv(io.StringIO(out))
    assert list(FACE_COLUMNS) == list(frame.columns)
    by = frame[frame["what"] == "face_beta"].set_index("route")
    assert by.loc["limit", "ratio_to_limit"] == 1.0 and by.loc["ours", "ratio_to_ours"] == 1.0
    assert np.isclose(by.loc["ours", "ratio_to_limit"],
                      by.loc["ours", "seconds_median"] / by.loc["limit", "seconds_median"], rtol=1e-4)
    assert (frame["element"] == "hex").all()


def test_limit_counts_its_flops_and_every_route_its_rate(tmp_path):
    """The limit's columns: its GFLOP (PARDISO's count + 11/3 m³ per pencil block: at least the
    pencils' part, the same on every β row) and each route's rate = GFLOP / its median seconds;
    --phases writes the breakdown, whose phases add up to its total."""
    from infsup_contact.bench import face_limit

    phases = tmp_path / "phases.csv"
    code, out, err = run_in_process(["bench", "--what", "face", "--N", "2", "--k", "2", "--repeats", "1",
                                     "--phases", str(phases)])
    assert code in (0, None), err
    frame = pd.read_csv(io.StringIO(out))
    beta = frame[frame["what"] == "face_beta"]
    assert {"limit_gflop", "gflop_per_s"} <= set(frame.columns) and beta["limit_gflop"].nunique() == 1
    assert np.allclose(beta["gflop_per_s"], beta["limit_gflop"] / beta["seconds_median"], rtol=1e-4)
    setup = beta_bench.BetaSetup(FACE_BENCH, 2, 2, element="hex")
    blocks = face_limit.pencil_blocks(setup, setup.operators())
    dims = [S.shape[0] for pairs in blocks.values() for S, _ in pairs]
    assert beta["limit_gflop"].iloc[0] >= 11 / 3 * sum(m ** 3 for m in dims) / 1e9 * (1 - 1e-3)
    table = pd.read_csv(phases)
    assert list(table.columns) == list(("what", "element", "k", "N", "phase", "cpu_s", "wall_s", "cpu_percent",
                                        "share", "peak_added_mib"))
    parts, total = table[table["phase"] != "total"], table[table["phase"] == "total"].iloc[0]
    assert {"sides: mesh, assembly, factorization", "H Grams", "eigensolves", "other"} <= set(parts["phase"])
    assert np.isclose(parts["cpu_s"].sum(), total["cpu_s"], rtol=1e-3) and np.isclose(parts["share"].sum(), 1.0,
                                                                                       rtol=1e-3)
    assert (table["peak_added_mib"] >= 0).all()  # a peak never falls


def test_limit_pencil_blocks_hold_the_whole_spectrum():
    """The limit's parity blocks of each pencil: their eigenvalues together are the whole pencil's."""
    import scipy.linalg as sla

    from infsup_contact.bench import face_limit

    setup = beta_bench.BetaSetup(FACE_BENCH, 2, 2, element="hex")
    ops = setup.operators()
    blocks = face_limit.pencil_blocks(setup, ops)
    assert any(len(pairs) > 1 for pairs in blocks.values())                    # the reflections split some
    for key, (S, G) in ops.items():
        whole = sla.eigh(S, G, eigvals_only=True)
        split = np.sort(np.concatenate([sla.eigh(s, g, eigvals_only=True) for s, g in blocks[key]]))
        assert len(split) == len(whole) and np.allclose(split, whole, rtol=1e-8, atol=1e-10 * whole.max())


@pytest.mark.parametrize("m", [1, 7, 60])
def test_limit_block_eigenvalues_are_the_pencils(m):
    """The limit's GIL-free route (G = L Lᵀ, L⁻¹ S L⁻ᵀ, eigvalsh) against LAPACK's dsygvd (scipy's
    eigh) on a pencil with a known spectrum: S = G V diag(λ) Vᵀ G for G-orthonormal V."""
    import scipy.linalg as sla

    from infsup_contact.bench import face_limit

    rng = np.random.default_rng(m)
    A = rng.standard_normal((m, m))
    G = A @ A.T + m * np.eye(m)
    V = np.linalg.solve(np.linalg.cholesky(G).T, np.linalg.qr(rng.standard_normal((m, m)))[0])  # Vᵀ G V = I
    lam = np.sort(rng.uniform(0.0, 2.0, m))
    lam[0] = 0.0                                                                     # a kernel mode
    S = G @ V @ np.diag(lam) @ V.T @ G
    S = (S + S.T) / 2
    got = face_limit.block_eigenvalues(S, G)
    assert np.allclose(got, lam, atol=1e-10 * lam.max()) and np.all(np.diff(got) >= 0)
    assert np.allclose(got, sla.eigh(S, G, eigvals_only=True), atol=1e-12 * lam.max())


def test_limit_runs_its_parts_and_blocks_side_by_side(monkeypatch):
    """The limit's Choleskys and its pencil blocks go through the concurrent map (the request's
    threads), the largest blocks first, and its values are the whole pencils' eigenvalues."""
    import scipy.linalg as sla

    from infsup_contact.bench import face_limit

    setup = beta_bench.BetaSetup(FACE_BENCH, 2, 2, element="hex")
    ops = setup.operators()
    seen = []

    def spy(fn, items):
        items = list(items)
        seen.append(items)
        return [fn(x) for x in items]

    monkeypatch.setattr(face_limit, "concurrent_map", spy)
    run, gflop = face_limit.face_limit(setup, ops)
    values = run()
    assert len(seen) == 2 and len(seen[0]) == len(face_limit.floor_matrices(setup.sides))
    blocks = face_limit.pencil_blocks(setup, ops)
    sizes = [blocks[key][i][0].shape[0] for key, i in seen[1]]
    assert sizes == sorted(sizes, reverse=True) and len(sizes) == sum(len(p) for p in blocks.values())
    for key, (S, G) in ops.items():
        assert np.allclose(values[key], sla.eigh(S, G, eigvals_only=True), rtol=1e-8,
                           atol=1e-10 * np.abs(values[key]).max())
    assert gflop() > 0


@pytest.mark.parametrize("argv, key", [
    (["--what", "beta", "--phases", "x.csv"], "--phases"),
    (["--what", "face", "--element", "prism"], "--element"),
    (["--what", "beta", "--element", "hex"], "--element"),
    (["--what", "face", "--peers", "osqp"], "--peers"),
    (["--what", "face", "--eigsh-max-N", "4"], "--eigsh-max-N"),
    (["--what", "face", "--k", "5"], "--k"),
])
def test_bad_input_is_refused_in_one_line(argv, key):
    argv = ["bench", "--N", "2", *(["--k", "1"] if "--k" not in argv else []), *argv]
    code, out, err = run_in_process(argv)
    assert code == 2 and out == ""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and key in lines[0], err


def test_setup_refuses_an_unknown_element():
    from infsup_contact.errors import InputError

    with pytest.raises(InputError, match="element"):
        beta_bench.BetaSetup(FACE_BENCH, 2, 1, element="prism")


def test_dry_run_estimates_the_face_routes():
    """The estimate is the 3D model's (face_beta_estimate): it grows with N, and a size that does
    not fit in memory is refused naming --N before anything is computed."""
    from infsup_contact import resources

    small, large = (resources.bench_estimate("face", [n], [2]) for n in (4, 12))
    assert 0 < small.bytes < large.bytes and 0 < small.seconds < large.seconds
    code, out, err = run_in_process(["bench", "--what", "face", "--N", "4", "--k", "1", "--dry-run"])
    assert code in (0, None) and "dry run" in out + err
    code, _, err = run_in_process(["bench", "--what", "face", "--N", "256", "--k", "2", "--dry-run"])
    assert code == 2 and "--N" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("k", [1, 2])
def test_the_face_estimate_grows_with_n_across_the_large_route(monkeypatch, k):
    """On the PARDISO route the estimate switches to the large route's fit above dim M =
    DENSE_MAX_M; memory still grows with N through the switch, time within each route (the
    large route is the faster one at the gate: that is what it is for)."""
    from infsup_contact import resources
    from infsup_contact.la.bottom import DENSE_MAX_M

    monkeypatch.setattr(resources, "face_route", lambda: "pardiso")
    ests = [resources.face_beta_estimate(k, n, n) for n in range(4, 80 // k)]
    switch = next(n for n in range(4, 80) if (k * n + 1) ** 2 > DENSE_MAX_M)
    assert all(b.bytes >= a.bytes for a, b in zip(ests, ests[1:]))
    assert all(b.seconds >= a.seconds for a, b in zip(ests, ests[1:]) if b is not ests[switch - 4])
    a, b, c, d = resources.LARGE_ROUTE_3D[k]
    nd = 2 * resources.face_side_dofs(switch, k)
    e = resources.face_beta_estimate(k, switch, switch)
    assert e.bytes > resources.LARGE_ROUTE_MARGIN * (a * nd + b * float((k * switch + 1) ** 2) ** 2)
