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
    "results/tables/elastic_claims.csv": "claims",
    **{path: "claims" for path in FACE_CLAIMS},
    **{path: "claims" for path in PRODUCERS_TABLES[1:]},  # rules/producers.smk
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
        elastic="results/tables/elastic_claims.csv",  # the elastic stage's claims (rules/elastic.smk)
        face=FACE_CLAIMS,  # the face stage's claims (rules/face.smk), when the config has a face section
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
