"""The Python API (infsup_contact.beta, verdict, certify): the commands' tables as DataFrames,
bad arguments refused as the command line refuses them, and docs/api.md's example run."""
import re
from pathlib import Path

import pandas as pd
import pytest

import infsup_contact as ic
from infsup_contact.cli import main
from infsup_contact.errors import InputError

ROOT = Path(__file__).resolve().parents[1]


def cli_table(capsys, argv) -> pd.DataFrame:
    assert main(argv) == 0
    import io

    return pd.read_csv(io.StringIO(capsys.readouterr().out), dtype={"N_list": str})


def test_beta_is_the_commands_table(capsys):
    frame = ic.beta(case="T3", k=2, N1=8, N2=6, norm="all")
    table = cli_table(capsys, ["beta", "--case", "T3", "--k", "2", "--N1", "8", "--N2", "6", "--norm", "all"])
    assert list(frame.columns) == list(table.columns)
    assert len(frame) == len(table) == 2
    timing = [c for c in frame.columns if c.startswith("t_")]
    # the CSV prints 12 significant digits (%.12g): the same numbers up to that rounding
    pd.testing.assert_frame_equal(frame.drop(columns=timing), table.drop(columns=timing),
                                  check_dtype=False, rtol=1e-11, atol=0)


def test_verdict_is_the_commands_row(capsys):
    frame = ic.verdict(case="R5.4", k=1, N=[4, 8, 16])
    table = cli_table(capsys, ["verdict", "--case", "R5.4", "--k", "1", "--N", "4", "8", "16"])
    assert list(frame.columns) == list(table.columns)
    assert frame.verdict[0] == table.verdict[0] == "UNSTABLE"
    assert frame.N_list[0] == table.N_list[0] == "4 8 16"


@pytest.mark.parametrize("keywords, argv, key", [
    (dict(case="T3", k=9, N1=8, N2=8), ["--case", "T3", "--k", "9", "--N1", "8", "--N2", "8"], "k"),
    (dict(case="T3", k=2, N1=0, N2=8), ["--case", "T3", "--k", "2", "--N1", "0", "--N2", "8"], "N1"),
    (dict(case="T3", k=2, N1=8, N2=8, seed=3), ["--case", "T3", "--k", "2", "--N1", "8", "--N2", "8", "--seed", "3"],
     "seed"),
])
def test_a_bad_value_is_the_commands_line(capsys, keywords, argv, key):
    """The same check, the same line: the command spells the key as its flag, the API as its keyword."""
    with pytest.raises(InputError) as err:
        ic.beta(**keywords)
    assert err.value.key == key and "\n" not in str(err.value)
    assert main(["beta", *argv]) == 2
    line = capsys.readouterr().err.strip().removeprefix("infsup-contact: error: ")
    flag = "--" + key.replace("_", "-")
    assert line == str(err.value).replace(f"invalid {key}", f"invalid {flag}", 1)


@pytest.mark.parametrize("keywords, key", [
    (dict(case="T3", k=2, N1=8, N2=8, norm="Q"), "norm"),       # argparse's choices
    (dict(case="T3", k="two", N1=8, N2=8), "k"),               # argparse's type
    (dict(case="T3", k=2, N1=8, N2=8, colour="red"), "colour"),  # no such flag
    (dict(case="T3", k=2, N1=8, N2=8, dry_run=True), "dry_run"),  # about the command line, not a result
    (dict(case="NOPE", k=2, N1=8, N2=8), "case"),
])
def test_what_argparse_would_refuse_is_an_input_error(keywords, key):
    with pytest.raises(InputError) as err:
        ic.beta(**keywords)
    assert err.value.key == key and "\n" not in str(err.value)


def test_verdict_needs_exactly_one_space():
    with pytest.raises(InputError, match="exactly one of case=, space= and system="):
        ic.verdict(k=2)
    with pytest.raises(InputError, match="exactly one"):
        ic.verdict(case="T3", system="levels.yaml", k=2)


def test_certify_refuses_a_missing_manifest(tmp_path):
    with pytest.raises(InputError) as err:
        ic.certify(tmp_path / "levels.yaml")
    assert "no such manifest" in str(err.value)


def python_blocks(page: Path) -> list:
    return re.findall(r"^```python\n(.*?)^```", page.read_text(encoding="utf-8"), re.S | re.M)


def test_the_worked_example_of_docs_api_runs(tmp_path, monkeypatch):
    blocks = python_blocks(ROOT / "docs" / "api.md")
    assert len(blocks) >= 2
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    scope = {}
    for block in blocks:
        exec(compile(block, "docs/api.md", "exec"), scope)
    t3, r54, series, certificate = scope["t3"], scope["r54"], scope["series"], scope["certificate"]
    # Theorem 3: T3 with k = 2 is stable, no kernel
    assert len(t3) == 1 and t3.beta[0] > 0 and t3.kernel_dim[0] == 0
    # Remark 5.4: discontinuous P_{k-1} has exactly one zero mode on matching meshes, in both norms
    assert set(r54.norm) == {"H", "L2"} and (r54.kernel_dim == 1).all() and (r54.beta == 0).all()
    assert (r54.smallest_nonzero > 0).all()
    assert series.verdict[0] == "UNSTABLE" and series.kernel_dim[0] == 1
    # the exported T3 series read back as a foreign system: the same β_h as `beta` on its finest level
    levels = certificate.attrs["levels"]
    assert certificate.verdict[0] == "STABLE" and (levels.kernel_dim == 0).all()
    assert abs(levels.beta.iloc[0] - ic.beta(case="T3", k=2, N1=8, N2=8, norm="H").beta[0]) < 1e-10
