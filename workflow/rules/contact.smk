# Contact stage: one job per (scene, family, k) with every N of the scene and every case of
# the config; the membranes reference (no exact solution) is solved once per (scene, k) in its
# own job and read by the contact jobs of that k.


rule membranes_reference:
    output:
        "results/references/{scene}_k{k}.npz",
    input:
        PACKAGE_SOURCES,
    params:
        cc=reference_job_config,  # its scene, c, reference_N: another key reruns no solve
    threads: 1
    resources:
        mem_mb=lambda wc: reference_mem_mb(wc) + (0 if workflow.local_exec else 500),  # + Snakemake in a cluster job
        runtime=30,
    benchmark:
        "results/benchmarks/rules/membranes_reference/{scene}_k{k}.tsv"
    log:
        "results/logs/reference/{scene}_k{k}.log",
    script:
        "../scripts/reference_job.py"


rule contact_job:
    output:
        "results/tables/contact/{scene}_{family}_k{k}.csv",
    input:
        src=PACKAGE_SOURCES,
        reference=contact_reference,
    params:
        cc=contact_job_config,  # its scene, c, cases: another key reruns no solve
        ns=lambda wc: contact_ns(wc.scene),
    wildcard_constraints:
        k="[1-4]",
    threads: 1
    resources:
        mem_mb=lambda wc: contact_mem_mb(wc) + (0 if workflow.local_exec else 500),  # + Snakemake in a cluster job
        runtime=30,
    benchmark:
        "results/benchmarks/rules/contact_job/{scene}_{family}_k{k}.tsv"
    log:
        "results/logs/contact/{scene}_{family}_k{k}.log",
    script:
        "../scripts/contact_job.py"


rule contact_table:
    output:
        "results/tables/contact.csv",
    input:
        contact_tables,
    benchmark:
        "results/benchmarks/rules/contact_table.tsv"
    params:
        kind="contact",  # the job tables' schema (infsup_contact.table_schemas.SCHEMAS)
    log:
        "results/logs/contact_table.log",
    script:
        "../scripts/concat_tables.py"
