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
