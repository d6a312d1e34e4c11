# Machines stage (not part of reproduce-all): the CI profile's full ledger on every machine path
# this CPU can take — OpenBLAS's core types and MKL's code branches (study/machines/paths.py: PATHS) —
# each in a copy of the workflow of its own; `snakemake verify-machines` fails unless the ledger's
# `verdict` column and the kernel columns of its tables (machines.LEDGER_TABLES) are byte-identical.
import re

from infsup_contact.study.machines.paths import PATHS


rule machine_ledger:
    # one path: its ledger and kernel tables (or, where the CPU cannot take it, the stated reason)
    output:
        "results/machines/{path}.json",
    input:
        PACKAGE_SOURCES,
    wildcard_constraints:
        path="|".join(re.escape(p.wildcard) for p in PATHS),
    threads: workflow.cores  # the nested run uses every core: one path at a time
    log:
        "results/logs/machines/{path}.log",
    shell:
        "python workflow/scripts/machine_ledger.py {wildcards.path} {output} {threads} > {log} 2>&1"


rule verify_machines:
    name: "verify-machines"
    output:
        verdicts="results/machines/verdicts.csv",
        columns="results/machines/columns.csv",
    input:
        expand("results/machines/{path}.json", path=[p.wildcard for p in PATHS]),
    log:
        "results/logs/verify_machines.log",
    script:
        "../scripts/verify_machines.py"
