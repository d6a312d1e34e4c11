# Benchmarks stage: speed as ratios measured side by side in one job (all cores to itself).


rule bench_beta:
    output:
        "results/benchmarks/beta.csv",
    input:
        PACKAGE_SOURCES,
    params:
        N=lambda wc: config["benchmarks"]["beta_N"],
        k=lambda wc: config["benchmarks"]["beta_k"],
        repeats=lambda wc: config["benchmarks"]["repeats"],
    threads: workflow.cores
    log:
        "results/logs/bench_beta.log",
    shell:
        "OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 infsup-contact bench --what beta"
        " --N {params.N} --k {params.k} --repeats {params.repeats} > {output}.tmp 2> {log}"
        " && mv {output}.tmp {output}"


rule bench_contact:
    output:
        "results/benchmarks/contact.csv",
    input:
        PACKAGE_SOURCES,
    params:
        N=lambda wc: config["benchmarks"]["contact_N"],
        k=lambda wc: config["benchmarks"]["contact_k"],
        repeats=lambda wc: config["benchmarks"]["repeats"],
    threads: workflow.cores
    log:
        "results/logs/bench_contact.log",
    shell:
        "OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 infsup-contact bench --what contact"
        " --N {params.N} --k {params.k} --repeats {params.repeats} > {output}.tmp 2> {log}"
        " && mv {output}.tmp {output}"
