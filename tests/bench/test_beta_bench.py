"""The β_h benchmark over models (bench/beta_bench.py with bench/beta_models.py): every model
times the same three routes, they agree on β_h, and the comparison follows its definition."""
import numpy as np
import pytest

from infsup_contact.bench import bench_beta, bench_for
from infsup_contact.bench.beta_bench import KERNEL_BETA, BetaSetup, compare
from infsup_contact.errors import InputError

from helpers.cli import run_in_process

TINY = {"beta": ([4], {}), "elastic": ([2], {}), "face": ([2], {"element": "hex"})}


@pytest.mark.parametrize("what", list(TINY))
def test_every_model_times_the_same_routes_and_they_agree(what):
    """ours, ours_core and limit first for every model, in its columns; ours_core solves the same
    β_h as ours from the assembled stiffness (round-off: 1e-8 covers the eigensolves' ~1e-12 and
    the membranes' Lanczos route's ~1e-8 on a kernel next to its shift)."""
    bench = bench_for(what)
    ns, options = TINY[what]
    rows = [r for r in bench_beta(bench, ns, [1], repeats=1, **options) if r["what"] == bench.what]
    assert [r["route"] for r in rows][:3] == ["ours", "ours_core", "limit"]
    assert all(list(r) == list(bench.columns) for r in rows)
    by = {r["route"]: r for r in rows}
    assert by["ours"]["ratio_to_ours"] == 1.0 and by["ours"]["max_abs_diff"] == 0.0
    assert by[bench.second_ratio.removeprefix("ratio_to_")][bench.second_ratio] == 1.0
    compared = [r for r in rows if not np.isnan(r["max_abs_diff"])]
    assert by["ours_core"] in compared and all(r["max_abs_diff"] <= 1e-8 for r in compared), rows
    assert len({r["n_problems"] for r in rows}) == 1 and rows[0]["n_problems"] > 0


def test_compare_takes_beta_above_the_reference_kernel():
    """β is the first value above the reference kernel (its length); a kernel value ≥ KERNEL_BETA
    fails kernel_ok; a space without β in both routes counts as equal, in one route as NaN."""
    ref = {("A", "H"): (np.zeros(2), 0.5), ("B", "H"): (np.zeros(0), 0.3)}
    got = {("A", "H"): np.array([0.36, 1e-20, 0.0]), ("B", "H"): np.array([0.09, 4.0])}
    diff, ok = compare(got, ref)
    assert diff == pytest.approx(0.1, abs=1e-15) and ok
    got[("A", "H")] = np.array([(2 * KERNEL_BETA) ** 2, 0.0, 0.25])
    assert compare(got, ref) == (0.0, False)
    ref[("C", "H")], got[("C", "H")] = (np.zeros(1), np.nan), np.array([0.0])
    assert compare(got, ref)[0] == 0.0
    ref[("C", "H")] = (np.zeros(1), 0.2)
    assert np.isnan(compare(got, ref)[0])


def test_compare_takes_two_kernel_betas_as_equal():
    """β = 0 against β = √(1.7e-16) (an eigenvalue at round-off, as the elastic bench's R5.4 gives
    on one BLAS code path and not on another): both zero, difference 0; one of them at KERNEL_BETA
    or above is a difference again."""
    ref = {("R5.4", "H"): (np.zeros(0), 0.0)}
    assert compare({("R5.4", "H"): np.array([1.7e-16, 2.5])}, ref) == (0.0, True)
    big = compare({("R5.4", "H"): np.array([KERNEL_BETA ** 2, 2.5])}, ref)[0]
    assert big == pytest.approx(KERNEL_BETA)


@pytest.mark.parametrize("what, options", [("beta", {"element": "hex"}), ("face", {"element": "prism"}),
                                           ("face", {"seed": 1})])
def test_a_mesh_option_the_model_does_not_take_is_refused(what, options):
    with pytest.raises(InputError, match=next(iter(options))):
        BetaSetup(bench_for(what), 2, 1, **options)


def test_cli_elastic_bench():
    """``bench --what elastic``: the elastic_beta.csv columns, the given cases where defined for
    k (T4 needs k ≥ 2), H norm only, the three routes agreeing."""
    import io

    import pandas as pd

    code, out, err = run_in_process(["bench", "--what", "elastic", "--N", "2", "--k", "1", "--repeats", "1",
                                     "--case", "T3", "R5.2", "T4", "--nu", "0.25"])
    assert code in (0, None), err
    frame = pd.read_csv(io.StringIO(out))
    assert list(frame.columns) == list(bench_for("elastic").columns)
    assert list(frame.route) == ["ours", "ours_core", "limit"] and (frame.what == "elastic_beta").all()
    assert (frame.n_problems == 2).all() and (frame.max_abs_diff <= 1e-8).all()
    assert frame.set_index("route").loc["limit", "ratio_to_limit"] == 1.0


def test_an_unknown_benchmark_is_refused_naming_the_choices():
    with pytest.raises(InputError, match="what.*beta, elastic, face"):
        bench_for("contact")


@pytest.mark.parametrize("what, options", [("beta", {}), ("elastic", {}), ("face", {"element": "tet"})])
def test_the_given_cases_are_the_ones_run_where_defined(what, options):
    """``cases`` narrows every model's default list; T4 (discontinuous P_(k-2)) needs k >= 2."""
    setup = BetaSetup(bench_for(what), 2, 1, cases=["T3", "T4"], **options)
    assert setup.cases == ["T3"] and set(setup.spaces) == {"T3"}


def test_row_values_give_back_the_rows_bottom():
    """row_values of a row with a kernel: bottom() reads its kernel values and its first β above
    (smallest_nonzero); without a kernel, its β."""
    from infsup_contact.bench.beta_bench import bottom, row_values

    kern, beta = bottom(row_values({"kernel_dim": 3, "beta": 1e-9, "smallest_nonzero": 0.25}), 3)
    assert len(kern) == 3 and np.all(kern == 1e-9) and beta == 0.25
    assert bottom(row_values({"kernel_dim": 0, "beta": 0.5, "smallest_nonzero": np.nan}), 0)[1] == 0.5


def test_the_face_core_route_is_ours_engine(monkeypatch):
    """The face's ours_core runs ours' engine (beta_rows) on the given sides, never meshing: its
    bottoms are those of ours' rows, value for value, on a hex pair."""
    from infsup_contact.bench import beta_bench
    from infsup_contact.bench.beta_models import FACE_BENCH
    from infsup_contact.models import contract

    assert FACE_BENCH.core_route is beta_bench.beta_ours_engine
    setup = beta_bench.BetaSetup(FACE_BENCH, 2, 2, element="hex")
    ours = beta_bench.beta_ours(setup)
    monkeypatch.setattr(contract.Model, "subdomain_mesh", lambda *a, **k: pytest.fail("ours_core meshed"))
    got = beta_bench.beta_ours_engine(setup)
    assert set(got) == set(ours) == set(setup.keys())
    assert all(np.array_equal(got[key], beta_bench.row_values(ours[key]), equal_nan=True) for key in got)
