"""workflow/scripts/docs_performance.py: docs/performance.md's tables come from
results/benchmarks/*.csv; only the marked blocks are rewritten, and a missing or damaged
benchmark table is refused with one line, the page untouched."""
import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "workflow" / "scripts" / "docs_performance.py"

BETA = """what,route,k,N,seconds_median,seconds_min,seconds_max,ratio_to_ours,repeats,includes
beta,ours,1,8,0.02,0.019,0.021,1,3,everything
beta,limit,1,8,0.005,0.004,0.006,0.25,3,the least
beta,ours,2,8,0.04,0.039,0.041,1,3,everything
beta,limit,2,8,0.01,0.009,0.011,0.25,3,the least
"""
DAG = "rule,jobs,wall_s_sum,wall_s_max,cpu_s_sum,max_rss_mb\nbeta_job,2,3.5,2.0,3.1,600\nall,2,3.5,2.0,3.1,600\n"

PAGE = """# Performance

Prose that quotes a marker, `<!-- generated: results/benchmarks/x.csv -->`, is text.

<!-- generated: results/benchmarks/beta.csv -->
| stale | table |
<!-- end generated -->

Between the blocks: kept byte for byte.  

<!-- generated: results/benchmarks/dag.csv -->
<!-- end generated -->
tail without a newline"""


def load():
    spec = importlib.util.spec_from_file_location("docs_performance", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def tree(tmp_path):
    bench = tmp_path / "results" / "benchmarks"
    bench.mkdir(parents=True)
    (bench / "beta.csv").write_text(BETA)
    (bench / "dag.csv").write_text(DAG)
    page = tmp_path / "performance.md"
    page.write_text(PAGE)
    return tmp_path, page


def run(page, root):
    return subprocess.run([sys.executable, str(SCRIPT), str(page), "--root", str(root)],
                          capture_output=True, text=True, cwd=root)


def outside_blocks(text: str) -> list:
    """The page with every generated block's body cut out."""
    gen = load()
    return gen.BLOCK.sub(lambda m: m.group(1) + m.group(4), text)


def test_only_the_marked_blocks_are_rewritten(tree):
    root, page = tree
    done = run(page, root)
    assert done.returncode == 0, done.stderr
    new = page.read_text()
    assert outside_blocks(new) == outside_blocks(PAGE)  # every byte outside the blocks kept
    assert "| stale | table |" not in new
    body = new.split("<!-- generated: results/benchmarks/beta.csv -->\n")[1].split("<!-- end generated -->")[0]
    rows = [line for line in body.splitlines() if line.startswith("| beta |")]
    assert len(rows) == 2  # one per (k, N)
    # the ratio column is computed from the medians: limit / ours = 0.005 / 0.02
    assert rows[0].split(" | ")[-1].rstrip(" |") == "0.25"
    assert "| beta_job | 2 | 3.5 | 2 | 3.1 | 600 |" in new
    again = run(page, root)  # idempotent: the second run changes nothing
    assert again.returncode == 0 and page.read_text() == new


@pytest.mark.parametrize("damage, words", [
    (lambda b: b.unlink(), "no such file"),
    (lambda b: b.write_text("what,route,k\nbeta,ours,1\n"), "missing columns"),
    (lambda b: b.write_text(BETA.replace("0.02,0.019", "fast,0.019")), "seconds_median"),
    (lambda b: b.write_text(BETA[:-20]), "newline"),
])
def test_a_missing_or_garbled_benchmark_is_one_line(tree, damage, words):
    root, page = tree
    damage(root / "results" / "benchmarks" / "beta.csv")
    done = run(page, root)
    assert done.returncode == 2 and done.stdout == ""
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("docs_performance: error:") and words in lines[0], done.stderr
    assert "beta.csv" in lines[0]
    assert page.read_text() == PAGE  # untouched


@pytest.mark.parametrize("page_text, words", [
    (PAGE.replace("<!-- end generated -->\ntail", "tail"), "unbalanced markers"),
    (PAGE.replace("benchmarks/dag.csv -->", "benchmarks/notes.csv -->"), "no table is generated"),
])
def test_a_broken_page_is_one_line(tree, page_text, words):
    root, page = tree
    page.write_text(page_text)
    done = run(page, root)
    assert done.returncode == 2 and words in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert page.read_text() == page_text


def test_the_page_in_the_repository_has_a_block_per_benchmark():
    """docs/performance.md names its sources by markers, and the rule `docs` reads them."""
    gen = load()
    text = (ROOT / "docs" / "performance.md").read_text()
    sources = [m.group("source") for m in gen.BLOCK.finditer(text)]
    assert {"results/benchmarks/beta.csv", "results/benchmarks/contact.csv"} <= set(sources)
    assert len(gen.OPEN.findall(text)) == len(sources)


PHASES = """what,element,k,N,phase,cpu_s,wall_s,cpu_percent,share,peak_added_mib
face_beta,hex,2,8,"sides: mesh, assembly, factorization",1.5,1,150,0.75,20
face_beta,hex,2,8,other,0.5,0.5,100,0.25,180
face_beta,hex,2,8,total,2,1.5,133.3,1,200
"""


def test_the_phases_table_has_its_columns_and_rows(tree):
    """bench --phases' table: one Markdown row per phase with CPU, wall, CPU % and share; a
    phases file with a column missing is refused in one line, the page untouched."""
    root, page = tree
    bench = root / "results" / "benchmarks"
    (bench / "face_phases.csv").write_text(PHASES)
    page.write_text("<!-- generated: results/benchmarks/face_phases.csv -->\n<!-- end generated -->\n")
    assert run(page, root).returncode == 0
    lines = page.read_text().splitlines()
    assert lines[1].split(" | ")[4:] == ["phase", "CPU (s)", "wall (s)", "CPU %", "share of CPU",
                                         "peak memory added (MiB) |"]
    assert "| sides: mesh, assembly, factorization | 1.5 | 1 | 150 % | 75.0 % | 20 |" in lines[3]
    assert len([ln for ln in lines if ln.startswith("| face_beta")]) == 3
    (bench / "face_phases.csv").write_text("\n".join(ln.rsplit(",", 1)[0] for ln in PHASES.splitlines()) + "\n")
    before = page.read_text()
    res = run(page, root)
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1 and page.read_text() == before
