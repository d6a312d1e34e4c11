"""Benchmark plumbing on tiny sizes (no timing assertions) and the Pareto front."""
import numpy as np
import pandas as pd
import pytest

from infsup_contact import bench
from infsup_contact.bench import beta_bench, contact_routes
from infsup_contact.bench.beta_models import membranes_bench

BETA_REQUIRED = {"what", "route", "k", "N", "seconds_median", "seconds_min", "seconds_max",
                 "ratio_to_ours", "max_abs_diff"}
CONTACT_REQUIRED = BETA_REQUIRED | {"iterations", "tolerance"}


# ------------------------------------------------------------------ Pareto front
def test_pareto_front_hand_made():
    t = [1.0, 2.0, 3.0, 2.5, 0.5, 4.0]
    e = [1.0, 0.5, 0.1, 0.6, 2.0, 0.1]
    # (2.5, 0.6) is dominated by (2, 0.5); (4, 0.1) by (3, 0.1)
    assert bench.pareto_front(t, e).tolist() == [True, True, True, False, True, False]


def test_pareto_front_ties_nan_and_single_point():
    assert bench.pareto_front([1.0], [1.0]).tolist() == [True]
    # same time, better error dominates; exact duplicates are both kept
    assert bench.pareto_front([1, 1, 1], [2, 1, 1]).tolist() == [False, True, True]
    # NaN never on the front and dominates nothing
    assert bench.pareto_front([np.nan, 2, 1], [0.0, 1, np.nan]).tolist() == [False, True, False]
    assert bench.pareto_front([], []).tolist() == []
    with pytest.raises(ValueError):
        bench.pareto_front([1, 2], [1])


def test_pareto_front_matches_brute_force():
    rng = np.random.default_rng(1)
    t, e = rng.random(60), rng.random(60)
    mask = bench.pareto_front(t, e)
    for i in range(60):
        dominated = any(t[j] <= t[i] and e[j] <= e[i] and (t[j] < t[i] or e[j] < e[i]) for j in range(60))
        assert mask[i] == (not dominated)
    front = np.argsort(t[mask])
    assert np.all(np.diff(e[mask][front]) < 0)  # faster ⇒ less accurate along the front


# ------------------------------------------------------------------ timing helper
def test_run_interleaved_order_budget_and_caps():
    calls = []
    routes = {"a": lambda: calls.append("a") or 1, "b": lambda: calls.append("b") or 2,
              "c": lambda: calls.append("c") or 0.5}
    out = bench.run_interleaved(routes, 3, max_repeats={"b": 1}, self_timed=("c",))
    assert calls == ["a", "b", "c", "a", "c", "a", "c"]
    assert len(out["a"][1]) == 3 and len(out["b"][1]) == 1 and out["c"][1] == [0.5, 0.5, 0.5]
    out = bench.run_interleaved({"x": lambda: None}, 5, budget=-1.0)
    assert len(out["x"][1]) == 1  # always once, then over budget


# ------------------------------------------------------------------ bench tables
def test_bench_beta_columns_and_agreement():
    frame = pd.DataFrame(bench.bench_beta(bench.bench_for("beta"), [4], [1, 2], repeats=1))
    assert BETA_REQUIRED <= set(frame.columns)
    assert set(frame.route) == {"ours", "ours_core", "limit", "eigsh", "dense"}
    assert len(frame) == 10
    solved = frame[frame.route != "limit"]
    assert (solved.max_abs_diff <= 1e-8).all(), solved[["route", "k", "max_abs_diff"]]
    assert solved.kernel_ok.all()
    assert np.allclose(frame[frame.route == "ours"].ratio_to_ours, 1.0)
    assert (frame.seconds_min <= frame.seconds_median).all() and (frame.seconds_median <= frame.seconds_max).all()


def test_bench_contact_columns_and_agreement():
    frame = pd.DataFrame(bench.bench_contact([4], [1, 2], repeats=1))
    assert CONTACT_REQUIRED <= set(frame.columns)
    assert {"ours", "ours_end_to_end", "floor", "limit", "osqp", "clarabel", "kkt_sparse"} == set(frame.route)
    solved = frame[frame.route != "limit"]
    assert (solved.rel_diff_u <= 1e-8).all() and (solved.rel_diff_lambda <= 1e-8).all()
    peers_ = frame[frame.route.isin(["osqp", "clarabel"])]
    assert peers_.accuracy_reached.astype(bool).all()
    assert np.isfinite(peers_.tolerance).all() and (peers_.iterations > 0).all()
    assert (frame[frame.route == "ours"].iterations >= 1).all()


def test_beta_limit_and_core_routes_agree_with_ours():
    setup = beta_bench.BetaSetup(membranes_bench(), 4, 2)
    ref = beta_bench.reference(setup, beta_bench.beta_ours(setup))
    core = beta_bench.beta_ours_core(setup)
    diff, kernel_ok = beta_bench.compare(core, ref)
    assert diff <= 1e-12 and kernel_ok
    lim = beta_bench.beta_limit(setup)()
    assert set(lim) == set(ref)
    diff, kernel_ok = beta_bench.compare(lim, ref)  # the same (S, G): the eigensolve alone differs
    assert diff <= 1e-12 and kernel_ok


@pytest.mark.parametrize("route", ["solves", "nested"])
def test_reduced_qp_equals_solve_contact(route):
    """The QP-level route (only A, B, F) = the mesh-level route, for both factorizations."""
    from infsup_contact.contact.contact import solve_contact
    from infsup_contact.bench.peers import contact_qp
    from infsup_contact.contact.reduced_qp import solve_reduced_qp
    from infsup_contact.study.contact.scenes import membranes

    sc, sides, Bs, F = contact_routes._contact_problem(6, 2)
    sol = solve_contact(membranes(), "T3", 2, "structured", 6, 6, time_floor=False)
    qp = solve_reduced_qp(*contact_qp(sides, Bs, F), route=route)
    assert qp.route == route and qp.n_gamma == sum(B.shape[1] for B in Bs)
    assert np.abs(qp.lam - sol.lam).max() <= 1e-12 * np.abs(sol.lam).max()
    assert np.abs(qp.u - contact_routes._ours_u(sol)).max() <= 1e-12 * np.abs(qp.u).max()
    # the early exit on a passed KKT check may come one step apart on round-off
    assert abs(qp.iterations - sol.pdas.iterations) <= 1


# ------------------------------------------------------------------ speed–accuracy
def test_speed_accuracy_table_from_contact_rows():
    from infsup_contact.study.contact.rows import contact_row

    rows = [contact_row("manufactured", case, k, "structured", n, n, time_floor=False)
            for case, k in (("T3", 1), ("T4", 2)) for n in (4, 6)]
    table = bench.speed_accuracy_table(pd.DataFrame(rows), repeats=1)
    required = {"scene", "case", "k", "N", "seconds", "energy_error", "lambda_hm12_error",
                "pareto_energy", "pareto_lambda"}
    assert required <= set(table.columns)
    assert len(table) == 4 and (table.seconds > 0).all()
    assert table.pareto_energy.any() and table.pareto_lambda.any()
    g = table
    assert (bench.pareto_front(g.seconds, g.energy_error) == g.pareto_energy.to_numpy()).all()


def test_split_timing_parts_are_ordered_and_a_shared_pair_solves_as_a_fresh_one():
    from infsup_contact.bench.speed_accuracy import time_contact_solves
    from infsup_contact.contact.contact import contact_pair, solve_contact, solve_contact_on
    from infsup_contact.study.contact.scenes import membranes

    t = time_contact_solves(["T3", "R5.4"], 2, 4, repeats=3)
    for med, lo, hi, runs in t.values():
        assert 0 < lo <= med <= hi and runs == 3
    pair = contact_pair(membranes(), 2, "structured", 40, 40)
    first = solve_contact_on(pair, "T3", time_floor=False)
    for side in pair.sides:
        assert side.steklov is None  # N = 40, k = 2: the nested route, X M by the Cholesky factor of S
        assert side.trace.basis_cache and "_schur_cholesky" in side.__dict__
        side.forget_cached()
        assert not side.trace.basis_cache and "_schur_cholesky" not in side.__dict__
    again = solve_contact_on(pair, "T3", time_floor=False)
    fresh = solve_contact(membranes(), "T3", 2, "structured", 40, 40, time_floor=False)
    assert np.array_equal(first.lam, again.lam) and np.array_equal(again.lam, fresh.lam)


def test_machine_info_has_versions(tmp_path):
    info = bench.machine_info()
    assert info["cores"] >= 1 and info["cpu_model"]
    for lib in ("numpy", "scipy", "ngsolve", "osqp", "clarabel", "qpsolvers"):
        assert lib in info["versions"]
    bench.write_machine_info(tmp_path / "m.json")
    import json
    assert json.loads((tmp_path / "m.json").read_text())["versions"]["osqp"]
