# Face studies stage (issue 28, items 6 and 7): the 3D contact patch test (study/patch/face.py),
# the α sweep of the transformed dual bases (study/face/alpha.py) and edge dropping
# (study/face/edge_dropping.py), one job per table (config face.patch, face.alpha, face.edge_dropping;
# workflow/scripts/face_study_job.py), their ledger claims results/tables/face_study_claims.csv
# (study/claims/membranes3d_studies.py; appended to results/claims.csv) and their three tables in the
# paper's face section (rule face_paper, report/face_studies.py). Sized for seconds: a config
# without a `face` section has no such stage.

# FACE_STUDIES, FACE_STUDY_CLAIMS: common.smk (the claims and paper stages list them too)


rule face_study_job:
    output:
        "results/face/{study}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        study=lambda wc: wc.study,
        fc=lambda wc: config["face"],
    wildcard_constraints:
        study="patch|alpha|edge_dropping",
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    benchmark:
        "results/benchmarks/rules/face_study_job/{study}.tsv"
    log:
        "results/logs/face/study_{study}.log",
    script:
        "../scripts/face_study_job.py"


rule face_study_claims:
    output:
        "results/tables/face_study_claims.csv",
    input:
        patch="results/face/patch.csv",
        alpha="results/face/alpha.csv",
        edge="results/face/edge_dropping.csv",
        src=PACKAGE_SOURCES,
    params:
        cfg=lambda wc: config["claims"],
        fc=lambda wc: config["face"],
    benchmark:
        "results/benchmarks/rules/face_study_claims.tsv"
    log:
        "results/logs/face_study_claims.log",
    script:
        "../scripts/face_study_claims.py"
