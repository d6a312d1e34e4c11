"""The memory and time estimate (resources.py): properties, no solves.

The constants were calibrated against /usr/bin/time -v runs (README, "What is refused");
here only what must hold for any constants: monotone in the sizes, the interpreter counted,
the job's mem_mb above the estimate, /proc/meminfo read robustly.
"""
from __future__ import annotations

import pytest

from infsup_contact import resources as R
from infsup_contact.cli import main


def test_beta_estimate_grows_with_every_size():
    base = R.beta_estimate("structured", 1, 16, 16).bytes
    assert R.beta_estimate("structured", 1, 32, 16).bytes > base
    assert R.beta_estimate("structured", 1, 16, 32).bytes > base
    assert R.beta_estimate("structured", 2, 16, 16).bytes > base
    assert R.beta_estimate("unstructured", 1, 16, 16).bytes > base
    assert R.beta_estimate("structured", 1, 16, 16, "union").bytes > base
    assert base >= R.PROCESS_BYTES["beta"]  # the interpreter is part of the peak


def test_dofs_scale_like_nk_squared():
    # doubling N or k quadruples the dofs (and more than quadruples the memory: n log n)
    assert R.side_dofs("structured", 64, 1) == pytest.approx(4 * R.side_dofs("structured", 32, 1), rel=0.05)
    assert R.side_dofs("structured", 32, 2) == pytest.approx(R.side_dofs("structured", 64, 1))
    small, large = (R.beta_estimate("structured", 1, n, n, process=False).bytes for n in (256, 512))
    assert large > 4 * small


def test_contact_reference_and_cases_cost_more():
    plain = R.contact_estimate("structured", 1, 16, 16)
    with_ref = R.contact_estimate("structured", 1, 16, 16, n_ref=64)
    assert with_ref.bytes > plain.bytes and with_ref.seconds > plain.seconds
    assert R.contact_estimate("structured", 1, 16, 16, n_cases=5).seconds > plain.seconds


def test_verdict_and_bench_are_bounded_by_their_largest_size():
    v = R.verdict_estimate("structured", 2, [8, 16, 64], "H")
    assert v.bytes == pytest.approx(R.beta_estimate("structured", 2, 64, 64, norms=("H",)).bytes)
    b = R.bench_estimate("beta", [8, 64], [1, 2], repeats=1)
    assert b.bytes > R.beta_estimate("structured", 2, 64, 64).bytes


def test_job_mem_mb_covers_the_estimate():
    for est in (R.beta_estimate("structured", 1, 4, 4), R.contact_estimate("structured", 3, 32, 32, 64)):
        assert R.job_mem_mb(est) * 1e6 >= 1.25 * est.bytes and R.job_mem_mb(est) % 100 == 0


def test_the_issue_request_is_hundreds_of_terabytes():
    est = R.beta_estimate("structured", 2, 100000, 4)
    assert est.bytes > 100 * 1024 ** 4 and "TiB" in est.describe()


def test_meminfo_parsing(tmp_path):
    f = tmp_path / "meminfo"
    f.write_text("MemTotal:       16000000 kB\nMemFree: 1 kB\nMemAvailable:    8000000 kB\n")
    assert R.available_bytes(str(f)) == 8000000 * 1024 and R.total_bytes(str(f)) == 16000000 * 1024
    f.write_text("garbage\n")
    assert R.available_bytes(str(f)) is None and R.total_bytes(str(f)) is None
    assert R.available_bytes(str(tmp_path / "none")) is None


def test_cli_refuses_what_does_not_fit(monkeypatch, capsys):
    """The CLI compares the same estimate with MemAvailable: a machine with 100 MB refuses
    even the smallest request, naming the flag and the estimate."""
    monkeypatch.setattr(R, "available_bytes", lambda meminfo="/proc/meminfo": 100e6)
    assert main(["beta", "--k", "1", "--N1", "4", "--N2", "4", "--dry-run"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("infsup-contact: error: invalid --N1 (got 4)") and "95.4 MiB available" in err


def test_system_estimate_covers_the_measured_3d_export():
    """A membranes3d export (R5.2, k = 2, N = 20: 121,680 dofs, 1,681 multipliers, B touching
    3,042 dofs, gamma-dense) peaked at 4.4 GB in 42 s: the estimate is above both; a 2D interface
    (B touching ~n^{1/2}) and a Stokes-like B (most dofs) keep the 2D formula."""
    from infsup_contact import resources

    n, m, nt, nnz = 121_680, 1_681, 3_042, 121_680 * 125
    assert resources.looks_3d(n, nt)
    est = resources.system_estimate([(n, m, nt, nnz, "gamma-dense")])
    assert est.bytes >= 4.4e9 and est.seconds >= 42
    assert not resources.looks_3d(132_098, 510) and not resources.looks_3d(n, n // 2)


def test_face_estimate_grows_with_n_and_k_across_the_routes():
    """The 3D bodies' estimate (both norms, every space): its memory never falls as N or k grows,
    across the dense route's gate to the large route (dim M = (k N + 1)² > DENSE_MAX_M) and up to
    k = 2, N = 48; its time never falls within a route (at the gate it may: the large route is the
    faster one there, resources.DENSE_ROUTE_SECONDS_3D)."""
    from infsup_contact.la.bottom import DENSE_MAX_M

    def est(k, n):
        return R.beta_estimate("structured", k, n, n, dim=3, element="hex", n_spaces=12)
    for k in (1, 2):
        series = [(n, est(k, n)) for n in range(2, 49)]
        for (n0, a), (n1, b) in zip(series, series[1:]):
            assert b.bytes >= a.bytes, (k, n1)
            same_route = ((k * n0 + 1) ** 2 > DENSE_MAX_M) == ((k * n1 + 1) ** 2 > DENSE_MAX_M)
            assert b.seconds >= a.seconds or not same_route, (k, n1)
    assert all(est(2, n).bytes >= est(1, n).bytes for n in range(2, 49))


@pytest.mark.parametrize("flag, value", [("--N1", "0"), ("--N2", "-3"), ("--k", "0"), ("--N1", "x")])
def test_face_dry_run_refuses_bad_sizes_in_one_line(flag, value, capsys):
    argv = ["beta", "--model", "membranes3d", "--case", "all", "--k", "2", "--N1", "4", "--N2", "4", "--dry-run"]
    argv[argv.index(flag) + 1] = value
    try:
        code = main(argv)
    except SystemExit as stop:  # argparse's own type errors
        code = stop.code
    captured = capsys.readouterr()
    lines = [ln for ln in captured.err.splitlines() if ln.strip()]
    assert code == 2 and captured.out == "" and len(lines) == 1 and flag in lines[0], captured.err


def test_the_large_route_fit_recovers_the_constants_it_is_given():
    """bench.estimates.fit_large_route_3d on requests that cost exactly a Σnd + b m² bytes and
    c Σnd + d m³ seconds beyond the process gives back (a, b, c, d)."""
    from infsup_contact.bench.estimates import fit_large_route_3d

    a, b, c, d = 3000.0, 120.0, 1e-4, 5e-10
    points = []
    for n in (20, 26, 32):
        nd, m = 2 * R.face_side_dofs(n, 2), float((2 * n + 1) ** 2)
        points.append((2, n, R.PROCESS_BYTES["beta"] + R.MKL_BYTES + a * nd + b * m * m,
                       R.START_SECONDS + c * nd + d * m ** 3))
    assert fit_large_route_3d(points) == pytest.approx((a, b, c, d), rel=1e-6)
