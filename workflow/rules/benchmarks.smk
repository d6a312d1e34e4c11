# Benchmarks stage: speed as ratios measured side by side in one job (one core and one BLAS thread:
# the ratios are single-thread ratios), plus the speed–accuracy points. A benchmark shares the
# machine with the other core's jobs: its routes run interleaved, round-robin, so a background
# load slows every route of a ratio alike (bench/harness.py); absolute seconds carry that load,
# as they carry the machine's drift (docs/performance.md). Alone: `snakemake benchmarks --cores 1`.
# Optional config keys (with their defaults): benchmarks.peers ([osqp, clarabel]),
# benchmarks.eigsh_max_N (no limit), benchmarks.dense_max_size (2500),
# benchmarks.route_budget_s (10), benchmarks.kkt_max_N (64), benchmarks.speed_accuracy_repeats (3),
# benchmarks.speed_accuracy_budget_s (10),
# benchmarks.speed_accuracy_scene (contact.primary_scene), benchmarks.face_N ([]: no face
# benchmark), benchmarks.face_k ([2]).

_BLAS1 = "export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1; "


rule benchmarks:
    # `snakemake benchmarks`: the stage on its own (also part of reproduce-all)
    input:
        "results/benchmarks/beta.csv",
        "results/benchmarks/contact.csv",
        "results/tables/speed_accuracy.csv",
        "results/figures/fig7_speed_accuracy.pdf",
        FACE_BENCH,


rule bench_beta:
    output:
        table="results/benchmarks/beta.csv",
        machine="results/benchmarks/machine.json",
    input:
        PACKAGE_SOURCES,
        BENCH_SOURCES,
    params:
        N=lambda wc: config["benchmarks"]["beta_N"],
        k=lambda wc: config["benchmarks"]["beta_k"],
        repeats=lambda wc: config["benchmarks"]["repeats"],
        eigsh=lambda wc: (f"--eigsh-max-N {config['benchmarks']['eigsh_max_N']}"
                          if "eigsh_max_N" in config["benchmarks"] else ""),
        dense=lambda wc: config["benchmarks"].get("dense_max_size", 2500),
        budget=lambda wc: config["benchmarks"].get("route_budget_s", 10),
    threads: 1
    benchmark:
        "results/benchmarks/rules/bench_beta.tsv"
    log:
        "results/logs/bench_beta.log",
    shell:
        _BLAS1 + "python -c 'import sys; from infsup_contact.bench import write_machine_info;"
        " write_machine_info(sys.argv[1])' {output.machine} 2> {log}"
        " && infsup-contact bench --what beta --N {params.N} --k {params.k} --repeats {params.repeats}"
        " {params.eigsh} --dense-max-size {params.dense} --route-budget {params.budget}"
        " > {output.table}.tmp 2>> {log} && mv {output.table}.tmp {output.table}"


rule bench_face:
    # the 3D face: β_h routes as ratios to the limit and the Schur-complement routes side by side,
    # and where one request's time goes, per phase (--phases; docs/performance.md's breakdown)
    output:
        table="results/benchmarks/face.csv",
        phases="results/benchmarks/face_phases.csv",
    input:
        PACKAGE_SOURCES,
        BENCH_SOURCES,
    params:
        N=lambda wc: config["benchmarks"]["face_N"],
        k=lambda wc: config["benchmarks"].get("face_k", [2]),
        repeats=lambda wc: config["benchmarks"]["repeats"],
        budget=lambda wc: config["benchmarks"].get("route_budget_s", 10),
    threads: 1
    benchmark:
        "results/benchmarks/rules/bench_face.tsv"
    log:
        "results/logs/bench_face.log",
    shell:
        _BLAS1 + "infsup-contact bench --what face --N {params.N} --k {params.k} --repeats {params.repeats}"
        " --route-budget {params.budget} --phases {output.phases} > {output.table}.tmp 2> {log}"
        " && mv {output.table}.tmp {output.table}"


rule bench_contact:
    output:
        "results/benchmarks/contact.csv",
    input:
        PACKAGE_SOURCES,
        BENCH_SOURCES,
    params:
        N=lambda wc: config["benchmarks"]["contact_N"],
        k=lambda wc: config["benchmarks"]["contact_k"],
        repeats=lambda wc: config["benchmarks"]["repeats"],
        peers=lambda wc: " ".join(config["benchmarks"].get("peers", ["osqp", "clarabel"])) or "none",
        budget=lambda wc: config["benchmarks"].get("route_budget_s", 10),
        kkt=lambda wc: config["benchmarks"].get("kkt_max_N", 64),
    threads: 1
    benchmark:
        "results/benchmarks/rules/bench_contact.tsv"
    log:
        "results/logs/bench_contact.log",
    shell:
        _BLAS1 + "infsup-contact bench --what contact --N {params.N} --k {params.k} --repeats {params.repeats}"
        " --peers {params.peers} --route-budget {params.budget} --kkt-max-N {params.kkt}"
        " > {output}.tmp 2> {log} && mv {output}.tmp {output}"


rule speed_accuracy:
    output:
        "results/tables/speed_accuracy.csv",
    input:
        contact="results/tables/contact.csv",
        src=PACKAGE_SOURCES,
        bench=BENCH_SOURCES,
    params:
        cc=speed_accuracy_config,  # the timed scene and c: a fit window's change reruns no timing
        repeats=lambda wc: config["benchmarks"].get("speed_accuracy_repeats", 3),
        budget=lambda wc: config["benchmarks"].get("speed_accuracy_budget_s", 10),
        scene=lambda wc: speed_accuracy_scene(config),
    threads: 1
    benchmark:
        "results/benchmarks/rules/speed_accuracy.tsv"
    log:
        "results/logs/speed_accuracy.log",
    script:
        "../scripts/speed_accuracy_job.py"


rule elastic_bench:
    # speed of the elastic β_h vs the limit (one factorization per body + one eigh per case)
    output:
        "results/benchmarks/elastic_beta.csv",
    input:
        PACKAGE_SOURCES,
        BENCH_SOURCES,
    params:
        ec=lambda wc: scenes_of(config, "elastic"),  # the model table's elastic study (config key studies.elastic)
        cases=lambda wc: list(config["infsup"]["cases"]),
    threads: 1
    benchmark:
        "results/benchmarks/rules/elastic_bench.tsv"
    log:
        "results/logs/elastic_bench.log",
    script:
        "../scripts/elastic_bench.py"


rule bench_arc:
    # what a curved Γ costs: β_h on the arc, exact and projected couplings, beside the flat segment
    # and the limit (bench/curved.py)
    output:
        "results/benchmarks/arc.csv",
    input:
        PACKAGE_SOURCES,
        BENCH_SOURCES,
    params:
        N=lambda wc: config["benchmarks"]["arc_N"],
        k=lambda wc: config["benchmarks"]["arc_k"],
        radius=lambda wc: config["benchmarks"]["arc_radius"],
        repeats=lambda wc: config["benchmarks"]["repeats"],
        budget=lambda wc: config["benchmarks"].get("route_budget_s", 10),
    threads: 1
    benchmark:
        "results/benchmarks/rules/bench_arc.tsv"
    log:
        "results/logs/bench_arc.log",
    shell:
        _BLAS1 + "infsup-contact bench --what arc --N {params.N} --k {params.k} --radius {params.radius}"
        " --repeats {params.repeats} --route-budget {params.budget} > {output}.tmp 2> {log} && mv {output}.tmp {output}"


rule bench_estimates:
    # --dry-run's time and memory estimates against measured runs of the docs' examples
    # (bench/estimates.py: max RSS and CPU time of each request as a child process); not part of
    # reproduce-all or `benchmarks` (minutes of CPU, a 4.7 GB Stokes run): `snakemake bench_estimates`,
    # then `snakemake docs` for docs/performance.md's table
    output:
        "results/benchmarks/estimates.csv",
    input:
        PACKAGE_SOURCES,
        "examples/stokes_skfem.py",
    threads: 1
    benchmark:
        "results/benchmarks/rules/bench_estimates.tsv"
    log:
        "results/logs/bench_estimates.log",
    shell:
        _BLAS1 + "python -m infsup_contact.bench.estimates {output} 2> {log}"
