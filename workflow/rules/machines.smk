# Machines stage (not part of reproduce-all): the CI profile's full ledger under every OpenBLAS
# core type this CPU can execute (study/machines.py: CORE_TYPES), each in a copy of the workflow
# of its own; `snakemake verify-machines` fails unless the `verdict` column is byte-identical.
from infsup_contact.study.machines import CORE_TYPES


rule machine_ledger:
    # one core type: its ledger (or, where the CPU lacks its instructions, the stated reason)
    output:
        "results/machines/{core}.json",
    input:
        PACKAGE_SOURCES,
    wildcard_constraints:
        core="|".join(CORE_TYPES),
    threads: workflow.cores  # the nested run uses every core: one core type at a time
    log:
        "results/logs/machines/{core}.log",
    shell:
        "python workflow/scripts/machine_ledger.py {wildcards.core} {output} {threads} > {log} 2>&1"


rule verify_machines:
    name: "verify-machines"
    output:
        "results/machines/verdicts.csv",
    input:
        expand("results/machines/{core}.json", core=CORE_TYPES),
    log:
        "results/logs/verify_machines.log",
    script:
        "../scripts/verify_machines.py"
