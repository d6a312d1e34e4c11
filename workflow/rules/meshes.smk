# Mesh stage: every mesh of a family (as NGSolve .vol files) and its quality table.
# The β_h and contact jobs rebuild the same meshes from the same deterministic builders.


rule mesh_family:
    output:
        table="results/tables/mesh_quality/{family}.csv",
        meshes=directory("results/meshes/{family}"),
    input:
        PACKAGE_SOURCES,
    params:
        pairs=lambda wc: beta_pairs(),
        ic=lambda wc: config["infsup"],
    threads: 1
    benchmark:
        "results/benchmarks/rules/mesh_family/{family}.tsv"
    log:
        "results/logs/meshes/{family}.log",
    script:
        "../scripts/mesh_family.py"


rule mesh_quality:
    output:
        "results/tables/mesh_quality.csv",
    input:
        expand("results/tables/mesh_quality/{family}.csv", family=config["infsup"]["families"]),
    benchmark:
        "results/benchmarks/rules/mesh_quality.tsv"
    params:
        kind="mesh_quality",  # the job tables' schema (infsup_contact.table_schemas.SCHEMAS)
    log:
        "results/logs/mesh_quality.log",
    script:
        "../scripts/concat_tables.py"
