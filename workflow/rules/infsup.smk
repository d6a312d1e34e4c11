# β_h stage: one job per (family, k, N1, N2); every case, norm, multiplier mesh and c pair
# of the config is computed from one interface operator inside the job.


rule beta_job:
    output:
        "results/tables/beta/{family}_k{k}_{n1}x{n2}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        ic=lambda wc: config["infsup"],
    threads: 1
    resources:
        mem_mb=lambda wc: beta_mem_mb(wc) + (0 if workflow.local_exec else 500),  # + Snakemake in a cluster job
        runtime=30,
    benchmark:
        "results/benchmarks/rules/beta_job/{family}_k{k}_{n1}x{n2}.tsv"
    log:
        "results/logs/beta/{family}_k{k}_{n1}x{n2}.log",
    script:
        "../scripts/beta_job.py"


rule beta_table:
    output:
        "results/tables/beta.csv",
    input:
        beta_tables,
    log:
        "results/logs/beta_table.log",
    script:
        "../scripts/concat_tables.py"
