# Contact stage: one job per (scene, family, k, N); every case of the config in the job.


rule contact_job:
    output:
        "results/tables/contact/{scene}_{family}_k{k}_{n}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        cc=lambda wc: config["contact"],
    threads: 1
    resources:
        mem_mb=lambda wc: contact_mem_mb(wc) + (0 if workflow.local_exec else 500),  # + Snakemake in a cluster job
        runtime=30,
    benchmark:
        "results/benchmarks/rules/contact_job/{scene}_{family}_k{k}_{n}.tsv"
    log:
        "results/logs/contact/{scene}_{family}_k{k}_{n}.log",
    script:
        "../scripts/contact_job.py"


rule contact_table:
    output:
        "results/tables/contact.csv",
    input:
        contact_tables,
    log:
        "results/logs/contact_table.log",
    script:
        "../scripts/concat_tables.py"
