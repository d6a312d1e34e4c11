"""OpenBLAS's threads fitted to the idle cores (la/openblas.py): the rule, the measurement of
idle cores from /proc/stat, and that the count reaches both OpenBLAS copies."""
import pytest

from infsup_contact.cli import main
from infsup_contact.la import openblas


@pytest.mark.parametrize("asked,idle,used", [(2, 2.0, 2), (2, 1.8, 2), (2, 1.7, 1), (2, 1.0, 1), (2, 0.0, 1),
                                             (4, 2.9, 3), (1, 0.0, 1), (2, None, 2)])
def test_as_many_threads_as_idle_cores_never_more_than_asked_never_none(asked, idle, used):
    assert openblas.fitted_threads(asked, idle) == used


def test_idle_cores_from_two_samples_of_proc_stat(tmp_path, monkeypatch):
    """Half the jiffies idle or iowait between the samples on a 2-CPU process: one idle core."""
    stat = tmp_path / "stat"
    samples = iter(["cpu 100 0 100 100 0 0 0 0 0 0\n", "cpu 150 0 150 180 20 0 0 0 0 0\n"])
    real_open = open

    def fake_open(path, *a, **k):
        if path == str(stat):
            stat.write_text(next(samples))
        return real_open(path, *a, **k)

    monkeypatch.setattr("builtins.open", fake_open)
    monkeypatch.setattr(openblas.os, "sched_getaffinity", lambda pid: {0, 1})
    assert openblas.idle_cores(window=0.0, stat=str(stat)) == pytest.approx(1.0)
    assert openblas.idle_cores(stat=str(tmp_path / "absent")) is None


def test_the_count_reaches_numpys_and_scipys_openblas():
    before = openblas.threads_now()
    assert set(before) == {"numpy", "scipy"}
    try:
        openblas.set_threads(1)
        assert set(openblas.threads_now().values()) == {1}
        openblas.set_threads(2)
        assert set(openblas.threads_now().values()) == {2}
    finally:
        openblas.set_threads(max(before.values()))


def test_the_cli_says_when_it_runs_fewer_threads_than_asked(monkeypatch, capsys):
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")
    monkeypatch.setattr(openblas, "idle_cores", lambda *a, **k: 0.4)
    before = openblas.threads_now()
    try:
        assert main(["beta", "--case", "T3", "--k", "1", "--N1", "2", "--N2", "2"]) == 0
        assert set(openblas.threads_now().values()) == {1}
    finally:
        openblas.set_threads(max(before.values()))
    err = capsys.readouterr().err
    assert "0.4 of" in err and "OpenBLAS runs 1 thread(s), not 2" in err and "INFSUP_BLAS_FIT=0" in err
    monkeypatch.setenv("INFSUP_BLAS_FIT", "0")
    assert main(["beta", "--case", "T3", "--k", "1", "--N1", "2", "--N2", "2"]) == 0
    assert "OpenBLAS runs" not in capsys.readouterr().err
