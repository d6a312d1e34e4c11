# 3D contact face stage (issue 28): β_h of the tensor face spaces on Γ = (0,1)²×{1} of the 3D
# model (config face; models/membranes3d.py), one job per (element, k) with all its mesh pairs,
# cases and norms in one process (study/beta/batch_rows.py), the table results/tables/face_beta.csv,
# the ledger claims results/tables/face_claims.csv (appended to results/claims.csv) and the
# paper's face section (report/face.py). A config without a `face` section has no face stage.

# FACE, FACE_BETA, FACE_CLAIMS, FACE_PAPER: common.smk (the claims and paper stages list them too)


def face_mem_mb(wildcards, l2_only=False):
    """mem_mb of a face job: the 3D β estimate of its largest pair (resources.face_beta_estimate, +25 %)."""
    if l2_only:
        pairs, norms = [(n, n) for n in l2_only_sizes(FACE, wildcards.element)], ("L2",)
    else:
        pairs, norms = face_pairs(FACE, wildcards.element), tuple(FACE["norms"])
    return max(resources.job_mem_mb(resources.beta_estimate("structured", int(wildcards.k), n1, n2, "omega2",
                                                            norms, dim=3)) for n1, n2 in pairs)


rule face_beta_job:
    output:
        "results/tables/face/beta_{element}_k{k}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        fc=lambda wc: config["face"],
    wildcard_constraints:
        element="[a-z0-9]+",
        k="[1-4]",
    threads: 1
    resources:
        mem_mb=lambda wc: face_mem_mb(wc) + (0 if workflow.local_exec else 500),
        runtime=10,
    benchmark:
        "results/benchmarks/rules/face_beta_job/{element}_k{k}.tsv"
    log:
        "results/logs/face/beta_{element}_k{k}.log",
    script:
        "../scripts/face_beta_job.py"


rule face_l2_job:
    # the matching N above face.max_N up to face.l2_max_N, L²(Γ) rows alone (config.face.l2_only_sizes):
    # a job of its own, so it runs beside the element's main job
    output:
        "results/tables/face/l2_{element}_k{k}.csv",
    input:
        PACKAGE_SOURCES,
    params:
        fc=lambda wc: config["face"],
        l2_only=True,
    wildcard_constraints:
        element="[a-z0-9]+",
        k="[1-4]",
    threads: 1
    resources:
        mem_mb=lambda wc: face_mem_mb(wc, l2_only=True) + (0 if workflow.local_exec else 500),
        runtime=10,
    benchmark:
        "results/benchmarks/rules/face_l2_job/{element}_k{k}.tsv"
    log:
        "results/logs/face/l2_{element}_k{k}.log",
    script:
        "../scripts/face_beta_job.py"


rule face_table:
    output:
        "results/tables/face_beta.csv",
    input:
        FACE_BETA,
    params:
        kind="face_beta",  # the job tables' schema (infsup_contact.table_schemas.SCHEMAS)
    benchmark:
        "results/benchmarks/rules/face_table.tsv"
    log:
        "results/logs/face_table.log",
    script:
        "../scripts/concat_tables.py"


rule face_claims:
    output:
        "results/tables/face_claims.csv",
    input:
        beta="results/tables/face_beta.csv",
        src=PACKAGE_SOURCES,
    params:
        cfg=lambda wc: config["claims"],
        fc=lambda wc: config["face"],
    benchmark:
        "results/benchmarks/rules/face_claims.tsv"
    log:
        "results/logs/face_claims.log",
    script:
        "../scripts/face_claims.py"


rule face_paper:
    output:
        macros="results/paper/face_macros.tex",
        beta="results/paper/face_beta_table.tex",
        patch="results/paper/face_patch_table.tex",  # the face studies' tables (rules/face_studies.smk)
        alpha="results/paper/face_alpha_table.tex",
        edge="results/paper/face_edge_table.tex",
    input:
        beta="results/tables/face_beta.csv",
        claims="results/tables/face_claims.csv",
        patch="results/face/patch.csv",
        alpha="results/face/alpha.csv",
        edge="results/face/edge_dropping.csv",
        study_claims="results/tables/face_study_claims.csv",
        tex="paper/face.tex",
        src=REPORT_SOURCES,
    params:
        fc=lambda wc: config["face"],
    benchmark:
        "results/benchmarks/rules/face_paper.tsv"
    log:
        "results/logs/face_paper.log",
    script:
        "../scripts/face_paper.py"
