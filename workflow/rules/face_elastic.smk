# The 3D elastic bodies on the contact face (issue 28; config face_elastic, models/elastic3d.py):
# β_H of the face spaces per element (all k, the table's ν on every mesh pair, the ν → 1/2 sweep
# on its meshes: study/face/elastic.py), the table results/tables/face_elastic_beta.csv, the
# elastic face patch test results/face/elastic_patch.csv (study/patch/face_elastic.py), their
# ledger claims results/tables/face_elastic_claims.csv (study/claims/elastic3d.py; appended to
# results/claims.csv through FACE_CLAIMS) and the generated subsection results/paper/face_elastic.tex
# of the face section (report/face_elastic.py). Sized for seconds; a config without a
# `face_elastic` section has no such stage.

# FACE_ELASTIC, FACE_ELASTIC_BETA, FACE_ELASTIC_PAPER: common.smk (the claims and paper stages list them too)


rule face_elastic_beta_job:
    output:
        "results/tables/face_elastic/beta_{element}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        fe=lambda wc: config["face_elastic"],
    wildcard_constraints:
        element="[a-z0-9]+",
    threads: 1
    resources:
        mem_mb=1500,
        runtime=10,
    benchmark:
        "results/benchmarks/rules/face_elastic_beta_job/{element}.tsv"
    log:
        "results/logs/face_elastic/beta_{element}.log",
    script:
        "../scripts/face_elastic_job.py"


rule face_elastic_patch:
    output:
        "results/face/elastic_patch.csv",
    input:
        PACKAGE_SOURCES,
    params:
        fe=lambda wc: config["face_elastic"],
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    benchmark:
        "results/benchmarks/rules/face_elastic_patch.tsv"
    log:
        "results/logs/face_elastic/patch.log",
    script:
        "../scripts/face_elastic_job.py"


rule face_elastic_table:
    output:
        "results/tables/face_elastic_beta.csv",
    input:
        FACE_ELASTIC_BETA,
    params:
        kind="face_elastic_beta",  # the job tables' schema (infsup_contact.table_schemas.SCHEMAS)
    benchmark:
        "results/benchmarks/rules/face_elastic_table.tsv"
    log:
        "results/logs/face_elastic_table.log",
    script:
        "../scripts/concat_tables.py"


rule face_elastic_claims:
    output:
        "results/tables/face_elastic_claims.csv",
    input:
        beta="results/tables/face_elastic_beta.csv",
        patch="results/face/elastic_patch.csv",
        membranes=["results/tables/face_beta.csv"] if FACE else [],  # the kernel comparison, when computed
        src=PACKAGE_SOURCES,
    params:
        cfg=lambda wc: config["claims"],
        fe=lambda wc: config["face_elastic"],
    benchmark:
        "results/benchmarks/rules/face_elastic_claims.tsv"
    log:
        "results/logs/face_elastic_claims.log",
    script:
        "../scripts/face_elastic_claims.py"


rule face_elastic_paper:
    output:
        "results/paper/face_elastic.tex",
    input:
        beta="results/tables/face_elastic_beta.csv",
        patch="results/face/elastic_patch.csv",
        claims="results/tables/face_elastic_claims.csv",
        src=REPORT_SOURCES + ["src/infsup_contact/study/claims/elastic3d.py"],  # its slope fit
    params:
        fe=lambda wc: config["face_elastic"],
    benchmark:
        "results/benchmarks/rules/face_elastic_paper.tsv"
    log:
        "results/logs/face_elastic_paper.log",
    script:
        "../scripts/face_elastic_paper.py"
