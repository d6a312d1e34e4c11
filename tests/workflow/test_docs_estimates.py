"""docs/performance.md's "Estimates" table: generated from results/benchmarks/estimates.csv
(bench/estimates.py), never typed; a damaged file is refused with one line, the page untouched.
The benchmark itself (minutes of CPU) is not run here: `snakemake bench_estimates`."""
import subprocess
import sys
from pathlib import Path

from infsup_contact.bench.estimates import COLUMNS, EXAMPLES

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "workflow" / "scripts" / "docs_performance.py"

CSV = ("example,command,est_mib,rss_mib,mem_ratio,est_s,cpu_s,wall_s,time_ratio,load_before,load_after\n"
       "hex k=1,infsup-contact beta --k 1,300,200,1.5,3,4,9,0.75,2.04,3.96\n"
       "Stokes,infsup-contact verdict --system DIR/levels.yaml,5000,4000,1.25,60,80,300,0.75,9.5,10\n")
PAGE = "# P\n\n<!-- generated: results/benchmarks/estimates.csv -->\n<!-- end generated -->\nafter\n"


def _run(tmp_path, csv):
    bench = tmp_path / "results" / "benchmarks"
    bench.mkdir(parents=True)
    (bench / "estimates.csv").write_text(csv)
    page = tmp_path / "performance.md"
    page.write_text(PAGE)
    done = subprocess.run([sys.executable, str(SCRIPT), str(page), "--root", str(tmp_path)],
                          capture_output=True, text=True, cwd=tmp_path)
    return done, page.read_text()


def test_the_table_shows_each_example_with_its_ratios(tmp_path):
    done, page = _run(tmp_path, CSV)
    assert done.returncode == 0, done.stderr
    rows = [line for line in page.splitlines() if line.startswith("| hex") or line.startswith("| Stokes")]
    assert len(rows) == 2  # one per example, in the file's order
    cells = [c.strip() for c in rows[0].strip("|").split("|")]
    assert cells[:5] == ["hex k=1", "`infsup-contact beta --k 1`", "300", "200", "1.5"]
    assert cells[7] == "0.75" and cells[9] == "2.0 → 4.0"
    assert "CPU (s, user+sys)" in page and page.endswith("<!-- end generated -->\nafter\n")


def test_a_damaged_estimates_table_is_one_line(tmp_path):
    done, page = _run(tmp_path, CSV.replace(",0.75,2.04", ",,2.04", 1))
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "estimates.csv" in done.stderr and "time_ratio" in done.stderr
    assert page == PAGE


def test_the_benchmark_writes_what_the_generator_reads():
    from infsup_contact.table_schemas import SCHEMAS

    assert set(SCHEMAS["estimates"].columns) == set(COLUMNS)
    assert len({ex.name for ex in EXAMPLES}) == len(EXAMPLES)  # the table's key


def test_the_page_has_the_estimates_block():
    assert "<!-- generated: results/benchmarks/estimates.csv -->" in (ROOT / "docs" / "performance.md").read_text()


def test_the_benchmark_reads_back_what_dry_run_prints():
    # describe() rounds memory to 3 and time to 2 significant digits; the parse loses nothing more
    from infsup_contact.bench.estimates import parse_dry_run
    from infsup_contact.resources import Estimate

    for nbytes, seconds in [(3.07e8, 3.8), (4.78e9, 84.0), (2.5e14, 4e8), (5e5, 0.4)]:
        line = f"dry run: valid request; estimated {Estimate(nbytes, seconds).describe()} (available memory 20 GiB)"
        got_bytes, got_seconds = parse_dry_run(line)
        assert abs(got_bytes / nbytes - 1) < 5e-3, line
        assert abs(got_seconds / max(seconds, 1) - 1) < 5e-2, line
