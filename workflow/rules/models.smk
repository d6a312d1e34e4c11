# Model stage: every study of the model table (config key `studies`; src/infsup_contact/plans/),
# the study's name as the {model} wildcard. A study's jobs each write results/tables/{model}/{job}.csv
# (one process per table: β of one element or family and k, a sweep, a patch test, ...), and its
# joined tables results/tables/{model}_{table}.csv concatenate some of them in order. Its claims
# (rules/claims.smk: model_claims) and its paper files (rules/paper.smk: model_paper) take the same
# wildcard. What each study computes is its plan's to say (plans/<study>.py); these rules never
# name a model.

# MODEL_TABLE, MODEL_STUDIES, MODEL_JOBS, MODEL_TABLES, MODEL_NAMES_RE: common.smk (the claims and paper stages list them too)


def model_job(wildcards):
    """The plan's Job of this {model}/{job} (plans/protocol.py)."""
    return MODEL_STUDIES[wildcards.model].jobs()[wildcards.job]


def model_table_jobs(wildcards):
    """The job tables a joined table concatenates, in order."""
    table = MODEL_STUDIES[wildcards.model].tables()[wildcards.table]
    return [job_path(wildcards.model, j) for j in table.jobs]


rule model_job:
    output:
        "results/tables/{model}/{job}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        model=lambda wc: wc.model,
    wildcard_constraints:
        model=MODEL_NAMES_RE,
        job="[a-z0-9_]+",
    threads: 1
    # ahead of the β batches and contact jobs: the longest jobs of a run are model jobs (the face's
    # tetrahedra), and a long job started last is the run's tail
    priority: 1
    resources:
        mem_mb=lambda wc: model_job(wc).mem_mb() + (0 if workflow.local_exec else 500),
        runtime=10,
    benchmark:
        "results/benchmarks/rules/model_job/{model}/{job}.tsv"
    log:
        "results/logs/{model}/{job}.log",
    script:
        "../scripts/model_job.py"


rule model_table:
    output:
        "results/tables/{model}_{table}.csv",
    input:
        model_table_jobs,
    params:
        kind=lambda wc: MODEL_STUDIES[wc.model].tables()[wc.table].kind,  # the job tables' schema (table_schemas.SCHEMAS)
    wildcard_constraints:
        model=MODEL_NAMES_RE,
        table=MODEL_TABLE_NAMES_RE,
    benchmark:
        "results/benchmarks/rules/model_table/{model}_{table}.tsv"
    log:
        "results/logs/{model}/table_{table}.log",
    script:
        "../scripts/concat_tables.py"
