# Elastic stage (issue 12): plane-strain bodies on the paper's geometry (models/elastic.py).
# The spaces are those of infsup.cases (one list for the membranes' and the elastic stages),
# each where defined for k. β_h of each next to the membranes on the same meshes (one job per family
# and k, all its mesh pairs in one process), the ν → 1/2 sweep (one job per k), the tables
# and the ledger claims (results/tables/elastic_claims.csv, appended to results/claims.csv).


def elastic_mem_mb(wildcards):
    """mem_mb of an elastic β job: the β estimate of its largest pair with two displacement
    components per node (resources.beta_estimate, +25 %)."""
    ec = config["elastic"]
    pairs = [(n, n) for n in ec["N"]] + [tuple(p) for p in ec["nonmatching"]]
    n1, n2 = max(pairs, key=lambda p: p[0] * p[0] + p[1] * p[1])
    return resources.job_mem_mb(resources.beta_estimate(
        getattr(wildcards, "family", "structured"), int(wildcards.k), n1, n2, "omega2", ("H",), components=2))


ELASTIC_BETA = [f"results/tables/elastic/beta_{f}_k{k}.csv"
                for f in config["elastic"]["families"] for k in config["elastic"]["k"]]
ELASTIC_SWEEP = [f"results/tables/elastic/nu_sweep_k{k}.csv" for k in config["elastic"]["nu_sweep_k"]]


rule elastic_beta_job:
    output:
        "results/tables/elastic/beta_{family}_k{k}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        ec=lambda wc: config["elastic"],
        cases=lambda wc: list(config["infsup"]["cases"]),
    threads: 1
    resources:
        mem_mb=lambda wc: elastic_mem_mb(wc) + (0 if workflow.local_exec else 500),
        runtime=10,
    benchmark:
        "results/benchmarks/rules/elastic_beta_job/{family}_k{k}.tsv"
    log:
        "results/logs/elastic/beta_{family}_k{k}.log",
    script:
        "../scripts/elastic_beta_job.py"


rule elastic_sweep_job:
    output:
        "results/tables/elastic/nu_sweep_k{k}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        ec=lambda wc: config["elastic"],
        cases=lambda wc: list(config["infsup"]["cases"]),
    threads: 1
    resources:
        mem_mb=lambda wc: elastic_mem_mb(wc) + (0 if workflow.local_exec else 500),
        runtime=10,
    benchmark:
        "results/benchmarks/rules/elastic_sweep_job/k{k}.tsv"
    log:
        "results/logs/elastic/nu_sweep_k{k}.log",
    script:
        "../scripts/elastic_beta_job.py"


rule elastic_patch:
    output:
        "results/tables/elastic_patch.csv",
    input:
        PACKAGE_SOURCES,
    params:
        ec=lambda wc: config["elastic"],
        cases=lambda wc: list(config["infsup"]["cases"]),
    threads: 1
    benchmark:
        "results/benchmarks/rules/elastic_patch.tsv"
    log:
        "results/logs/elastic/patch.log",
    script:
        "../scripts/elastic_patch.py"


rule elastic_hertz_job:
    output:
        "results/tables/elastic/hertz_{study}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        ec=lambda wc: config["elastic"],
        cases=lambda wc: list(config["infsup"]["cases"]),
    wildcard_constraints:
        study="k[0-9]+|modeling",
    threads: 1
    benchmark:
        "results/benchmarks/rules/elastic_hertz_job/{study}.tsv"
    log:
        "results/logs/elastic/hertz_{study}.log",
    script:
        "../scripts/elastic_hertz_job.py"


ELASTIC_HERTZ = [f"results/tables/elastic/hertz_k{k}.csv" for k in config["elastic"]["hertz"]["k"]] + [
    "results/tables/elastic/hertz_modeling.csv"]


# Figure data: λ_h on Γ, stable vs unstable, the Hertz scene's d and R on one mesh; the (case,
# k) pairs and the mesh: config key figures.elastic_profiles.


rule elastic_hertz_profiles:
    output:
        "results/tables/elastic_hertz_profiles.csv",
    input:
        PACKAGE_SOURCES,
    params:
        ec=lambda wc: config["elastic"],
        fig=lambda wc: config["figures"]["elastic_profiles"],
    threads: 1
    benchmark:
        "results/benchmarks/rules/elastic_hertz_profiles.tsv"
    log:
        "results/logs/elastic/hertz_profiles.log",
    script:
        "../scripts/elastic_hertz_job.py"


rule elastic_figure:
    output:
        pdf="results/figures/fig9_elastic.pdf",
        png="results/figures/fig9_elastic.png",
    input:
        sweep="results/tables/elastic_nu_sweep.csv",
        profiles="results/tables/elastic_hertz_profiles.csv",
        style=PLOT_STYLE,
    benchmark:
        "results/benchmarks/rules/elastic_figure.tsv"
    log:
        "results/logs/figures/fig9_elastic.log",
    script:
        "../scripts/fig_elastic.py"


rule elastic_paper:
    output:
        macros="results/paper/elastic_macros.tex",
        beta="results/paper/elastic_beta_table.tex",
        patch="results/paper/elastic_patch_table.tex",
        hertz="results/paper/elastic_hertz_table.tex",
    input:
        beta="results/tables/elastic_beta.csv",
        sweep="results/tables/elastic_nu_sweep.csv",
        patch="results/tables/elastic_patch.csv",
        hertz="results/tables/elastic_hertz.csv",
        claims="results/tables/elastic_claims.csv",
        speed="results/benchmarks/elastic_beta.csv",
        tex="paper/elastic.tex",
        src=REPORT_SOURCES,
    params:
        nu_slope_cases=lambda wc: config["figures"]["nu_slope_cases"],
    benchmark:
        "results/benchmarks/rules/elastic_paper.tsv"
    log:
        "results/logs/elastic_paper.log",
    script:
        "../scripts/elastic_paper.py"


rule elastic_bench:
    # speed of the elastic β_h vs the limit (one factorization per body + one eigh per case);
    # the whole machine to itself locally (ratios are single-thread ratios)
    output:
        "results/benchmarks/elastic_beta.csv",
    input:
        PACKAGE_SOURCES,
        BENCH_SOURCES,
    params:
        ec=lambda wc: config["elastic"],
        cases=lambda wc: list(config["infsup"]["cases"]),
    threads: workflow.cores
    benchmark:
        "results/benchmarks/rules/elastic_bench.tsv"
    log:
        "results/logs/elastic_bench.log",
    script:
        "../scripts/elastic_bench.py"


rule elastic_tables:
    output:
        beta="results/tables/elastic_beta.csv",
        sweep="results/tables/elastic_nu_sweep.csv",
        hertz="results/tables/elastic_hertz.csv",
    input:
        beta=ELASTIC_BETA,
        sweep=ELASTIC_SWEEP,
        hertz=ELASTIC_HERTZ,
    benchmark:
        "results/benchmarks/rules/elastic_tables.tsv"
    log:
        "results/logs/elastic_tables.log",
    script:
        "../scripts/elastic_tables.py"


rule elastic_claims:
    output:
        "results/tables/elastic_claims.csv",
    input:
        beta="results/tables/elastic_beta.csv",
        sweep="results/tables/elastic_nu_sweep.csv",
        patch="results/tables/elastic_patch.csv",
        hertz="results/tables/elastic_hertz.csv",
        src=PACKAGE_SOURCES,
    params:
        cfg=lambda wc: config["claims"],
    benchmark:
        "results/benchmarks/rules/elastic_claims.tsv"
    log:
        "results/logs/elastic_claims.log",
    script:
        "../scripts/elastic_claims.py"
