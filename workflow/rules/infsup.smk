# β_h stage: one job per batch of mesh pairs of one (family, k) (BETA_BATCHES, common.smk;
# discretization/gamma/mesh_series.py): every pair of every series (matching, fixed ratios, the
# non-matching families), every seed of the perturbed family, and every case, norm,
# multiplier mesh and c pair of the config, from one side factorization per mesh pair.
# A batch is a few dozen seconds of work, so NGSolve's start-up is paid once per batch.


rule beta_job:
    output:
        "results/tables/beta/{batch}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        ic=lambda wc: config["infsup"],
        batch=lambda wc: BETA_BATCHES[wc.batch],
    wildcard_constraints:
        batch="[a-z]+_k[1-4]_[0-9]+",
    threads: 1
    resources:
        mem_mb=lambda wc: beta_mem_mb(wc) + (0 if workflow.local_exec else 500),  # + Snakemake in a cluster job
        runtime=30,
    benchmark:
        "results/benchmarks/rules/beta_job/{batch}.tsv"
    log:
        "results/logs/beta/{batch}.log",
    script:
        "../scripts/beta_job.py"


rule beta_table:
    output:
        "results/tables/beta.csv",
    input:
        beta_tables,
    benchmark:
        "results/benchmarks/rules/beta_table.tsv"
    params:
        kind="beta",  # the job tables' schema (infsup_contact.table_schemas.SCHEMAS)
    log:
        "results/logs/beta_table.log",
    script:
        "../scripts/concat_tables.py"
