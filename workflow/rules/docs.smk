# Docs stage: docs/performance.md's tables generated from results/benchmarks/ (never typed).
# Not part of reproduce-all (it would make a tracked page an output of every run): run
# `snakemake docs` after `snakemake benchmarks` or a full run. The sources are the files the
# page's `<!-- generated: … -->` markers name.

import re as _re

DOCS_PAGE = "docs/performance.md"


def docs_sources(wildcards):
    """The benchmark tables the page's markers name, read when the rule is needed (not when the
    workflow is parsed: a copy of the workflow without docs/ must still parse)."""
    with open(DOCS_PAGE, encoding="utf-8") as page:
        return _re.findall(r"^<!-- generated: (\S+) -->$", page.read(), _re.M)


rule docs:
    input:
        docs_sources,
        script="workflow/scripts/docs_performance.py",
    log:
        "results/logs/docs.log",
    shell:
        "python {input.script} " + DOCS_PAGE + " 2> {log}"
