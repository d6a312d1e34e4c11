"""Progress on stderr (src/infsup_contact/progress.py, docs/cli.md "Progress"): a request's stage,
space, mesh level and elapsed time as plain lines when stderr is not a terminal (one line per step,
no carriage return), a tqdm bar when it is; ``--quiet`` silences it; stdout is the same either
way; a refusal, ``--dry-run`` and the Python API print none. ``INFSUP_PROGRESS_DELAY=0`` shows it
from the first step (by default a request done within 3 s prints nothing). Small requests: seconds."""
from __future__ import annotations

import io
import re

import pytest

from infsup_contact import api, progress
from infsup_contact.cli import main

LINE = re.compile(r"^infsup-contact: \[\d+\.\d s\] (?P<title>[^:]+)(?:: (?P<where>.*))?$")
BETA = ["beta", "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4"]


@pytest.fixture
def no_delay(monkeypatch):
    monkeypatch.setenv("INFSUP_PROGRESS_DELAY", "0")


def _run(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def _lines(err: str) -> list:
    """The progress lines of ``err``, each checked against the plain format."""
    assert "\r" not in err, "plain mode: no carriage return"
    lines = [ln for ln in err.splitlines() if ln.startswith("infsup-contact: [")]
    for ln in lines:
        assert LINE.match(ln), ln
    return lines


def _export(tmp_path, capsys, *extra):
    out = tmp_path / "sys"
    code, stdout, err = _run(capsys, ["export", "--case", "T3", "--k", "2", "--N", "4", "8", "16", "--out", str(out),
                                      *extra])
    assert code == 0, err
    return out / "levels.yaml", stdout, err


@pytest.mark.parametrize("argv, title, where", [
    (BETA, "beta membranes T3 k=2 N1=4 N2=4", ["space T3 (1/1)", "side 1 of 2 (N1=4)", "side 2 of 2 (N2=4)",
                                               "Gram matrix G, norm H", "eigenproblem"]),
    (["verdict", "--case", "T3", "--k", "2", "--N", "4", "8", "16"], "verdict membranes T3 k=2 N=4,8,16",
     ["level N=4 (1/3)", "level N=8 (2/3)", "level N=16 (3/3), space T3 (1/1)"]),
    (["contact", "--scene", "manufactured", "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4"],
     "contact manufactured membranes T3 k=2 N1=4 N2=4", ["space T3 (1/1)", "contact solve"]),
])
def test_plain_lines_name_stage_space_level_and_time(capsys, no_delay, argv, title, where):
    code, out, err = _run(capsys, argv)
    assert code == 0 and out, err
    lines = _lines(err)
    assert lines and all(LINE.match(ln)["title"] == title for ln in lines), lines
    for text in where:
        assert any(text in ln for ln in lines), (text, lines)
    times = [float(re.search(r"\[(\d+\.\d) s\]", ln)[1]) for ln in lines]
    assert times == sorted(times), "elapsed time never goes back"


def test_export_and_its_verdict_report_levels(tmp_path, capsys, no_delay):
    manifest, _, err = _export(tmp_path, capsys)
    lines = _lines(err)
    assert any("export membranes T3 k=2 N=4,8,16: level N=16 (3/3)" in ln for ln in lines), lines
    assert any("writing level h=0.0625 (3/3)" in ln for ln in lines), lines
    code, _, err = _run(capsys, ["verdict", "--system", str(manifest)])
    lines = _lines(err)
    assert code == 0 and any(f"verdict --system {manifest}: level h=0.25 (1/3): reading A, B, G" in ln
                             for ln in lines), lines


def test_quiet_silences_progress_and_stdout_is_the_same(tmp_path, capsys, no_delay):
    code, loud, err = _run(capsys, BETA)
    assert code == 0 and _lines(err)
    code, quiet, err = _run(capsys, [*BETA, "--quiet"])
    assert code == 0 and err == ""
    # the timing columns differ run to run: every other byte of the CSV is the same
    strip = lambda csv: [ln.rsplit(",", 3)[0] for ln in csv.splitlines()]  # noqa: E731
    assert strip(loud) == strip(quiet) and loud.count("\n") == quiet.count("\n")
    _, stdout, err = _export(tmp_path, capsys, "--quiet")
    assert err == "" and stdout.strip().endswith("levels.yaml")


def test_export_stdout_is_byte_identical_with_and_without_progress(tmp_path, capsys, no_delay):
    """No timing column: the whole stdout (the manifest's path) and the files written match."""
    _, loud, err = _export(tmp_path / "a", capsys)
    _, quiet, _ = _export(tmp_path / "b", capsys, "--quiet")
    assert _lines(err) and loud.replace(str(tmp_path / "a"), "") == quiet.replace(str(tmp_path / "b"), "")
    for f in (tmp_path / "a" / "sys").iterdir():
        assert f.read_bytes() == (tmp_path / "b" / "sys" / f.name).read_bytes(), f.name


def test_refusal_and_dry_run_print_no_progress(capsys, no_delay):
    code, out, err = _run(capsys, [*BETA[:-1], "0"])
    assert code == 2 and out == "" and len(err.splitlines()) == 1 and "--N2" in err, err
    code, out, err = _run(capsys, [*BETA, "--dry-run"])
    assert code == 0 and out.startswith("dry run:") and err == ""


def test_api_prints_nothing(capsys, no_delay):
    rows = api.beta(case="T3", k=2, N1=4, N2=4)
    assert len(rows) and capsys.readouterr().err == ""
    assert not progress.active()


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_terminal_gets_a_tqdm_bar_and_a_pipe_plain_lines():
    """The same steps: on a terminal one bar redrawn in place (carriage returns, the count
    and the step in it), elsewhere one line per step."""
    for stream in (_Terminal(), io.StringIO()):
        with progress.reporting("demo", stream=stream, delay=0):
            for _ in progress.steps(["a", "b"], "space"):
                progress.note("stage")
        text = stream.getvalue()
        if isinstance(stream, _Terminal):
            assert "\r" in text and "2/2" in text and "space b (2/2): stage" in text, text
        else:
            assert "\r" not in text and text.splitlines()[-1].endswith("demo: space b (2/2): stage"), text
            assert len(text.splitlines()) == 4, text


def test_no_reporter_is_a_plain_loop():
    """Without a reporter (library use) steps() yields the items unchanged and note() is silent."""
    assert not progress.active()
    assert list(progress.steps(iter(range(3)), "x")) == [0, 1, 2]
    progress.note("nothing")


def test_a_face_request_says_its_spaces_in_worker_processes_and_each_one_done(capsys, monkeypatch, no_delay):
    """``beta`` on the face runs its spaces in worker processes (solvers/side_by_side.py) and
    says so, then each space as its task finishes (a task of the spaces sharing a Gram series
    names each of them); stdout is the table the
    threads give (``INFSUP_SPACE_PROCESSES=0``), the timings aside."""
    import pandas as pd

    from infsup_contact.solvers import side_by_side

    if not side_by_side.sys.platform.startswith("linux"):
        pytest.skip("worker processes are forked (Linux)")
    monkeypatch.setattr(side_by_side, "space_workers", lambda dim, n, available=None: 2)
    argv = ["beta", "--model", "membranes3d", "--case", "all", "--k", "2", "--N1", "2", "--N2", "2"]
    code, out, err = _run(capsys, argv)
    assert code == 0
    where = [LINE.match(ln)["where"] or "" for ln in _lines(err)]
    n = int(next(w for w in where if w.endswith("spaces, 2 worker processes")).split()[0])
    done = [w for w in where if re.fullmatch(rf"space \S+ done \(\d+ of {n}\)", w)]
    assert len(done) == n and len({w.split()[1] for w in done}) == n
    monkeypatch.setenv("INFSUP_SPACE_PROCESSES", "0")
    code, threads_out, err = _run(capsys, argv)
    assert code == 0 and not any("worker processes" in ln for ln in _lines(err))
    frames = [pd.read_csv(io.StringIO(csv)) for csv in (out, threads_out)]
    frames = [f[[c for c in f.columns if not c.startswith("t_")]] for f in frames]
    pd.testing.assert_frame_equal(*frames, check_exact=True)
