"""workflow/scripts/compare_results.py: two results trees agree iff every compared cell does."""
import importlib.util
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "workflow" / "scripts" / "compare_results.py"
spec = importlib.util.spec_from_file_location("compare_results", SCRIPT)
compare_results = importlib.util.module_from_spec(spec)
spec.loader.exec_module(compare_results)

LEDGER = "claim_id,verdict,predicted\nThm3-k1,PASS,PASS\nR5.4-structured,PASS,PASS\n"
TABLE = "case,k,beta,seconds,git_commit\nT3,1,0.8650,1.25,abc\nT3,2,0.8100,2.50,abc\n"


def tree(root: Path, ledger: str = LEDGER, table: str = TABLE) -> Path:
    (root / "tables" / "beta").mkdir(parents=True)
    (root / "claims.csv").write_text(ledger)
    (root / "tables" / "beta" / "structured_k1.csv").write_text(table)
    return root


def test_timing_and_provenance_columns_are_ignored(tmp_path, capsys):
    base = tree(tmp_path / "a")
    new = tree(tmp_path / "b", table=TABLE.replace("1.25", "9.75").replace("abc", "def"))
    assert compare_results.main([str(base), str(new)]) == 0
    assert "identical" in capsys.readouterr().out


@pytest.mark.parametrize("edit, expected", [
    (dict(ledger=LEDGER.replace("R5.4-structured,PASS", "R5.4-structured,FAIL")), "row 3, verdict: 'PASS' -> 'FAIL'"),
    (dict(table=TABLE.replace("0.8100", "0.8101")), "row 3, beta: '0.8100' -> '0.8101'"),
    (dict(table=TABLE + "T3,3,0.7,1.0,abc\n"), "2 rows in base, 3 in new"),
    (dict(table=TABLE.replace("beta,", "beta_h,")), "only in base ['beta']"),
])
def test_a_changed_cell_row_or_column_is_named(tmp_path, capsys, edit, expected):
    base, new = tree(tmp_path / "a"), tree(tmp_path / "b", **edit)
    assert compare_results.main([str(base), str(new)]) == 1
    assert expected in capsys.readouterr().out


def test_a_missing_table_is_named(tmp_path, capsys):
    base, new = tree(tmp_path / "a"), tree(tmp_path / "b")
    (new / "tables" / "beta" / "structured_k1.csv").unlink()
    assert compare_results.main([str(base), str(new)]) == 1
    assert "tables/beta/structured_k1.csv: only in base" in capsys.readouterr().out


def test_bad_usage_is_one_line(tmp_path, capsys):
    assert compare_results.main([str(tmp_path / "missing")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


# ------------------------------------------------------------------ round-off columns (table_schemas.ROUNDOFF_COLUMNS)
BETA = ("case,k,beta,kernel_dim,smallest_nonzero,gap_over_roundoff,nmax_rel_error\n"
        "T5,2,0.8836972,0,0.8836972,2.1e13,8.11255422501e-08\n"     # no kernel: smallest_nonzero is β
        "R5.4,1,0,6,0.0946762899636,4.29e11,9.77341819234e-07\n"    # β above a 6-dim kernel, resolved
        "T3,4,0,3,3.311061e-08,0.0081,3.95112452417e-07\n")         # below the round-off level: noise


def beta_tree(root: Path, table: str) -> Path:
    (root / "tables").mkdir(parents=True)
    (root / "tables" / "beta.csv").write_text(table)
    return root


def edit(table: str, row: int, column: str, value: str) -> str:
    lines = [line.split(",") for line in table.splitlines()]
    lines[row][lines[0].index(column)] = value
    return "\n".join(",".join(line) for line in lines) + "\n"


@pytest.mark.parametrize("row, column, value", [
    (1, "nmax_rel_error", "8.11255646881e-08"),       # the Gram bound, another route
    (3, "gap_over_roundoff", "0.0073"),               # in units of the round-off level: well below 1 apart
    (3, "smallest_nonzero", "3.139311e-08"),          # sqrt of a round-off eigenvalue: within sqrt(η)
    (2, "smallest_nonzero", "0.0946762899637"),       # a resolved β above the kernel: within η/s
])
def test_round_off_columns_agree_within_their_stated_error(tmp_path, capsys, row, column, value):
    base, new = beta_tree(tmp_path / "a", BETA), beta_tree(tmp_path / "b", edit(BETA, row, column, value))
    assert compare_results.main([str(base), str(new)]) == 0
    out = capsys.readouterr().out
    assert f"tables/beta.csv: identical but round-off columns within their tolerance: {column} within" in out
    assert "1 cells differ" in out


@pytest.mark.parametrize("row, column, value, why", [
    (2, "smallest_nonzero", "0.0946763", "resolved: 1e-7 is far above its η/s"),
    (1, "smallest_nonzero", "0.8836973", "no kernel: it is β, compared as text"),
    (1, "beta", "0.8836973", "β is never a round-off column"),
    (1, "nmax_rel_error", "9e-08", "the Gram bound stating another accuracy"),
])
def test_beyond_the_stated_error_or_outside_the_rule_is_a_difference(tmp_path, capsys, row, column, value, why):
    base, new = beta_tree(tmp_path / "a", BETA), beta_tree(tmp_path / "b", edit(BETA, row, column, value))
    assert compare_results.main([str(base), str(new)]) == 1, why
    out = capsys.readouterr().out
    assert f"row {row + 1}, {column}:" in out and "(relative " in out
    assert ("beyond its round-off tolerance" in out) == (column in ("nmax_rel_error",) or (row, column) == (2, "smallest_nonzero"))


def test_an_identical_file_says_so_per_file(tmp_path, capsys):
    base, new = beta_tree(tmp_path / "a", BETA), beta_tree(tmp_path / "b", BETA)
    assert compare_results.main([str(base), str(new)]) == 0
    assert "tables/beta.csv: identical\n" in capsys.readouterr().out


def test_every_round_off_column_states_its_reason_and_tolerance():
    from infsup_contact.table_schemas import ROUNDOFF_COLUMNS

    for name, rule in ROUNDOFF_COLUMNS.items():
        assert len(rule.reason) > 40 and rule.describe() != "0", name
    assert "beta" not in ROUNDOFF_COLUMNS and "kernel_dim" not in ROUNDOFF_COLUMNS
