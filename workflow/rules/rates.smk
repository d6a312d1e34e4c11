# Rates stage: least-squares slopes over the finest meshes, against the expected rates.


rule rates:
    output:
        "results/tables/rates.csv",
    input:
        table="results/tables/contact.csv",
        src=PACKAGE_SOURCES,
    params:
        window=lambda wc: config["contact"]["rate_window"],
    benchmark:
        "results/benchmarks/rules/rates.tsv"
    log:
        "results/logs/rates.log",
    shell:
        "infsup-contact rates {input.table} --window {params.window} > {output}.tmp 2> {log}"
        " && mv {output}.tmp {output}"
