# Producers stage: other codes' exporters (examples/producers/<code>/export.py) run for their spaces,
# matching and non-matching, each export certified by verdict --system in the norms of the config
# (study/producers.py). A producer not installed is a row saying so, with its install command.
# Only with a `producers` config section (the CI profile has none: Kratos is an optional install).
# A producer not installed: its claims are NOT RUN (the gate lists them, unjudged). The stage reruns
# when a code's installation changes: its interpreter and the version it reports are params (probed
# once per snakemake process; params are a default rerun trigger), so `make producers-<code>`
# followed by `make reproduce-all` recomputes the tables, the ledger and the paper.
from infsup_contact.study.producers import installation

PRODUCERS = config.get("producers")
PRODUCERS_TABLES = ["results/tables/producers.csv", "results/tables/producers_claims.csv"] if PRODUCERS else []
# the census (rule census) and its mode plots (rule census_modes) are in the section: the paper needs them
PRODUCERS_PAPER = ["results/paper/producers.tex", "results/figures/census_modes.pdf"] if PRODUCERS else []

if PRODUCERS:

    rule producers:
        output:
            table="results/tables/producers.csv",
            claims="results/tables/producers_claims.csv",
            modes="results/tables/producers_modes.csv",  # each H export's finest worst mode on Γ (the census plots)
        input:
            exporters=sorted({spec["export"] for spec in PRODUCERS["codes"].values()}),
            src=PACKAGE_SOURCES,
        params:
            cfg=lambda wc: dict(PRODUCERS, criterion=config["claims"]),
            installed=lambda wc: installation(PRODUCERS["codes"]),
            workdir="results/producers",
        threads: 1
        # started first: most of its wall time is the other codes' start-up, not CPU, and
        # overlaps the CPU-bound jobs instead of trailing them (results/benchmarks/dag.csv)
        priority: 50
        benchmark:
            "results/benchmarks/rules/producers.tsv"
        log:
            "results/logs/producers.log",
        script:
            "../scripts/producers_job.py"

    rule producers_paper:
        output:
            "results/paper/producers.tex",
        input:
            table="results/tables/producers.csv",
            claims="results/tables/producers_claims.csv",
            census="results/tables/census.csv",
            modes="results/tables/producers_modes.csv",
            paragraphs=[p for p in (f"examples/producers/{n}/paper.tex" for n in PRODUCERS["codes"]) if Path(p).is_file()],
            src=REPORT_SOURCES,
        benchmark:
            "results/benchmarks/rules/producers_paper.tsv"
        log:
            "results/logs/producers_paper.log",
        script:
            "../scripts/producers_paper.py"

    rule census:
        # one row per code, space and offset: the verdict against the prediction, kernel against
        # dim M_h, β_h, slope, the prediction's fix, its claim and the commit that holds it
        # (study/census.py; git's history read where there is one, '-' where not)
        output:
            "results/tables/census.csv",
        input:
            table="results/tables/producers.csv",
            claims="results/tables/producers_claims.csv",
            src=PACKAGE_SOURCES,
        params:
            cfg=lambda wc: PRODUCERS,
        benchmark:
            "results/benchmarks/rules/census.tsv"
        log:
            "results/logs/census.log",
        script:
            "../scripts/census_job.py"

    rule census_modes:
        # the worst mode on Γ of each UNSTABLE space of the census (report/figures/census.py)
        output:
            pdf="results/figures/census_modes.pdf",
            png="results/figures/census_modes.png",
        input:
            census="results/tables/census.csv",
            modes="results/tables/producers_modes.csv",
            src=REPORT_SOURCES + ["src/infsup_contact/report/figures/census.py"],
        benchmark:
            "results/benchmarks/rules/census_modes.tsv"
        log:
            "results/logs/census_modes.log",
        script:
            "../scripts/fig_census_modes.py"
