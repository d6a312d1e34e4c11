# Docs stage: docs/performance.md's tables generated from results/benchmarks/ (never typed).
# Not part of reproduce-all (it would make a tracked page an output of every run): run
# `snakemake docs` after `snakemake benchmarks` or a full run. The sources are the files the
# page's `<!-- generated: … -->` markers name.

import re as _re

DOCS_PAGE = "docs/performance.md"
DOCS_SOURCES = _re.findall(r"^<!-- generated: (\S+) -->$", open(DOCS_PAGE, encoding="utf-8").read(), _re.M)


rule docs:
    input:
        DOCS_SOURCES,
        script="workflow/scripts/docs_performance.py",
    log:
        "results/logs/docs.log",
    shell:
        "python {input.script} " + DOCS_PAGE + " 2> {log}"
