"""results/benchmarks/dag.csv from Snakemake benchmark files (bench/dag.py)."""
import pytest

from infsup_contact.bench.dag import dag_table

HEAD = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"


def _tsv(path, s, rss, cpu):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(HEAD + f"{s}\t0:00:01\t{rss}\t1\t1\t1\t0\t0\t50\t{cpu}\n")


def test_rules_jobs_and_totals(tmp_path):
    _tsv(tmp_path / "beta_job" / "structured_k1_0.tsv", 10.0, 300, 9.0)
    _tsv(tmp_path / "beta_job" / "perturbed_k2_1.tsv", 30.0, 500, 28.0)
    _tsv(tmp_path / "claims.tsv", 2.0, 100, 1.5)
    t = dag_table(tmp_path).set_index("rule")
    assert t.loc["beta_job", "jobs"] == 2 and t.loc["beta_job", "wall_s_sum"] == pytest.approx(40.0)
    assert t.loc["beta_job", "wall_s_max"] == pytest.approx(30.0) and t.loc["beta_job", "max_rss_mb"] == 500
    assert t.loc["claims", "jobs"] == 1
    assert t.loc["all", "jobs"] == 3 and t.loc["all", "wall_s_sum"] == pytest.approx(42.0)
    assert t.loc["all", "cpu_s_sum"] == pytest.approx(38.5)
