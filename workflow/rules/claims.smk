# Claims stage: the ledger results/claims.csv from the β_h and rate tables plus the two
# claims that need their own small computation (the (3.13) sign, Rem 5.5 instances).


rule claims_extra:
    output:
        "results/tables/claims_extra.csv",
    input:
        PACKAGE_SOURCES,
    params:
        cfg=lambda wc: config["claims"],
    threads: 1
    benchmark:
        "results/benchmarks/rules/claims_extra.tsv"
    log:
        "results/logs/claims_extra.log",
    script:
        "../scripts/claims_extra.py"


# The tables the ledger is made of (rule claims below), each with the schema it reads under, and
# one stage further up the contact table the rates are fitted on: the gate (verify-claims,
# workflow/Snakefile) needs each of them, checks it and refuses a ledger older than them
# (study/claims/gate.py).
LEDGER_TABLES = {
    "results/tables/beta.csv": "beta",
    "results/tables/rates.csv": "rates",
    "results/tables/claims_extra.csv": "claims",
    **{path: "claims" for path in MODEL_CLAIMS},  # the model table's studies (rule model_claims)
    # rules/producers.smk: no rows where no code has predictions ("?": study/claims/gate.py)
    **{path: "claims?" for path in PRODUCERS_TABLES[1:]},
}
GATE_STAGES = [
    ("results/claims.csv", LEDGER_TABLES),
    ("results/tables/rates.csv", {"results/tables/contact.csv": "contact"}),
]


rule claims:
    output:
        "results/claims.csv",
    input:
        beta="results/tables/beta.csv",
        rates="results/tables/rates.csv",
        extra="results/tables/claims_extra.csv",
        models=MODEL_CLAIMS,  # the model table's studies' claims (rule model_claims below), in its order
        producers=PRODUCERS_TABLES[1:],  # the producers' claims (rules/producers.smk), with a producers section
        src=PACKAGE_SOURCES,
    params:
        cfg=lambda wc: config["claims"],
        rate_scene=lambda wc: config["contact"]["primary_scene"],
    benchmark:
        "results/benchmarks/rules/claims.tsv"
    log:
        "results/logs/claims.log",
    script:
        "../scripts/claims.py"


rule model_claims:
    # one study of the model table: its plan's claims from its tables (plans/<study>.py)
    output:
        "results/tables/{model}_claims.csv",
    input:
        lambda wc: [path for path, _ in MODEL_STUDIES[wc.model].claim_inputs().files.values()],
        src=PACKAGE_SOURCES,
    params:
        cfg=lambda wc: config["claims"],
    wildcard_constraints:
        model=MODEL_NAMES_RE,
    benchmark:
        "results/benchmarks/rules/model_claims/{model}.tsv"
    log:
        "results/logs/{model}/claims.log",
    script:
        "../scripts/model_claims.py"
