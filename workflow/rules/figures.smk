# Figures stage: one rule per figure, each drawn from tables under results/tables/ only
# (nothing recomputed), written as results/figures/NAME.pdf and .png. Shared style (one
# Okabe–Ito colour and one marker per case): src/infsup_contact/report/style.py.
# Captions for `snakemake --report`: workflow/report/NAME.rst.

FIGURE_NAMES = [
    "fig1_model_problem",
    "fig2_beta_H",
    "fig3_beta_L2",
    "fig4_families",
    "fig5_contact_solutions",
    "fig6_convergence",
    "fig7_speed_accuracy",
    "fig8_dual",
]
# The face section's figures (paper/face.tex), where the model table has the face study: both
# drawn by one rule (rule face_figures: one job, one Python start), the worst mode by one small job.
FACE_STUDY = "membranes3d"
FACE_FIGURE_NAMES = (["fig10_face_beta", "fig11_face_studies"]
                     if FACE_STUDY in MODEL_STUDIES and config["figures"].get("face_mode") else [])
FIGURE_NAMES += FACE_FIGURE_NAMES
# The curved segment's figure (the arc study's generated subsection), where the model table has it
from infsup_contact.plans.arc import FIGURE as ARC_FIGURE, FIGURE_STUDY as ARC_STUDY, PATCH as ARC_PATCH
ARC_FIGURE_NAMES = ([ARC_FIGURE] if ARC_STUDY in MODEL_STUDIES and MODEL_STUDIES[ARC_STUDY].cfg.get("patch")
                    and MODEL_STUDIES[ARC_STUDY].element is None and config["figures"].get("arc_mode") else [])
FIGURE_NAMES += ARC_FIGURE_NAMES
# Every figure output (pdf and png): inputs of `rule figures` and of reproduce-all.
FIGURES = [f"results/figures/{name}.{ext}" for name in FIGURE_NAMES for ext in ("pdf", "png")]

# Figure 5: a stable and an unstable pair on the same mesh; Figure 8: dual mortar multipliers
# against the paper's T3 (β_h, λ_h on Γ, energy error). Cases, k, mesh, family, scene: config
# keys figures.contact_solutions and figures.dual (config.checks.check_figures).
FIG5 = config["figures"]["contact_solutions"]
FIG8 = config["figures"]["dual"]

PLOT_STYLE = "src/infsup_contact/report/style.py"


# NAME → {"pdf": ..., "png": ...}: the outputs marked for the report, caption workflow/report/NAME.rst.
FIGURE_OUT = {
    name: {
        fmt: report(f"results/figures/{name}.{fmt}", caption=f"../report/{name}.rst", category="Figures",
                    labels={"figure": name, "format": fmt.upper()})
        for fmt in ("pdf", "png")
    }
    for name in FIGURE_NAMES
}


rule figures_all:
    name: "figures"
    input:
        FIGURES,


rule fig1_model_problem:
    output:
        pdf=FIGURE_OUT["fig1_model_problem"]["pdf"],
        png=FIGURE_OUT["fig1_model_problem"]["png"],
    input:
        style=PLOT_STYLE,
    benchmark:
        "results/benchmarks/rules/fig1_model_problem.tsv"
    log:
        "results/logs/figures/fig1_model_problem.log",
    script:
        "../scripts/fig_model_problem.py"


rule fig2_beta_H:
    output:
        pdf=FIGURE_OUT["fig2_beta_H"]["pdf"],
        png=FIGURE_OUT["fig2_beta_H"]["png"],
    input:
        beta="results/tables/beta.csv",
        style=PLOT_STYLE,
    params:
        norm="H",
    benchmark:
        "results/benchmarks/rules/fig2_beta_H.tsv"
    log:
        "results/logs/figures/fig2_beta_H.log",
    script:
        "../scripts/fig_beta.py"


rule fig3_beta_L2:
    output:
        pdf=FIGURE_OUT["fig3_beta_L2"]["pdf"],
        png=FIGURE_OUT["fig3_beta_L2"]["png"],
    input:
        beta="results/tables/beta.csv",
        style=PLOT_STYLE,
    params:
        norm="L2",
    benchmark:
        "results/benchmarks/rules/fig3_beta_L2.tsv"
    log:
        "results/logs/figures/fig3_beta_L2.log",
    script:
        "../scripts/fig_beta.py"


rule fig4_families:
    output:
        pdf=FIGURE_OUT["fig4_families"]["pdf"],
        png=FIGURE_OUT["fig4_families"]["png"],
    input:
        beta="results/tables/beta.csv",
        style=PLOT_STYLE,
        meshes="src/infsup_contact/discretization/segment/meshes.py",  # the mesh panels are drawn from mesh_pair
    params:
        seed=lambda wc: seeds(config["infsup"])[0],  # the figure draws the first seed's meshes
        alpha=lambda wc: config["infsup"]["alpha"],
    benchmark:
        "results/benchmarks/rules/fig4_families.tsv"
    log:
        "results/logs/figures/fig4_families.log",
    script:
        "../scripts/fig_families.py"


rule gamma_profiles:
    output:
        gamma="results/tables/gamma_profiles.csv",
        field="results/tables/field_values.csv",
    input:
        PACKAGE_SOURCES,
    params:
        cases=FIG5["cases"],
        k=FIG5["k"],
        N=FIG5["N"],
        family=FIG5["family"],
        per_interval=FIG5["per_interval"],
        scene_spec=lambda wc: config["contact"]["scenes"].get(FIG5["scene"], {"kind": FIG5["scene"]}),
        c=lambda wc: config["contact"]["c"],
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    benchmark:
        "results/benchmarks/rules/gamma_profiles.tsv"
    log:
        "results/logs/gamma_profiles.log",
    script:
        "../scripts/gamma_profiles_job.py"


rule fig5_contact_solutions:
    output:
        pdf=FIGURE_OUT["fig5_contact_solutions"]["pdf"],
        png=FIGURE_OUT["fig5_contact_solutions"]["png"],
    input:
        gamma="results/tables/gamma_profiles.csv",
        field="results/tables/field_values.csv",
        style=PLOT_STYLE,
    benchmark:
        "results/benchmarks/rules/fig5_contact_solutions.tsv"
    log:
        "results/logs/figures/fig5_contact_solutions.log",
    script:
        "../scripts/fig_contact_solutions.py"


rule fig6_convergence:
    output:
        pdf=FIGURE_OUT["fig6_convergence"]["pdf"],
        png=FIGURE_OUT["fig6_convergence"]["png"],
    input:
        contact="results/tables/contact.csv",
        rates="results/tables/rates.csv",
        style=PLOT_STYLE,
    params:
        scene=config["contact"]["primary_scene"],
    benchmark:
        "results/benchmarks/rules/fig6_convergence.tsv"
    log:
        "results/logs/figures/fig6_convergence.log",
    script:
        "../scripts/fig_convergence.py"


rule fig7_speed_accuracy:
    output:
        pdf=FIGURE_OUT["fig7_speed_accuracy"]["pdf"],
        png=FIGURE_OUT["fig7_speed_accuracy"]["png"],
    input:
        table="results/tables/speed_accuracy.csv",  # written by the benchmarks stage
        style=PLOT_STYLE,
        pareto="src/infsup_contact/bench/speed_accuracy.py",  # pareto_front
    benchmark:
        "results/benchmarks/rules/fig7_speed_accuracy.tsv"
    log:
        "results/logs/figures/fig7_speed_accuracy.log",
    script:
        "../scripts/fig_speed_accuracy.py"


rule dual_profiles:
    output:
        gamma="results/tables/gamma_profiles_dual.csv",
        field="results/tables/field_values_dual.csv",
    input:
        PACKAGE_SOURCES,
    params:
        cases=FIG8["cases"],
        k=FIG8["k"],
        N=FIG8["N"],
        family=FIG8["family"],
        per_interval=FIG8["per_interval"],
        scene_spec=lambda wc: config["contact"]["scenes"].get(FIG8["scene"], {"kind": FIG8["scene"]}),
        c=lambda wc: config["contact"]["c"],
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    benchmark:
        "results/benchmarks/rules/dual_profiles.tsv"
    log:
        "results/logs/dual_profiles.log",
    script:
        "../scripts/gamma_profiles_job.py"


rule fig8_dual:
    output:
        pdf=FIGURE_OUT["fig8_dual"]["pdf"],
        png=FIGURE_OUT["fig8_dual"]["png"],
    input:
        beta="results/tables/beta.csv",
        contact="results/tables/contact.csv",
        gamma="results/tables/gamma_profiles_dual.csv",
        style=PLOT_STYLE,
    params:
        cases=FIG8["cases"],
        scene=config["contact"]["primary_scene"],
        profile_scene=FIG8["scene"],
    benchmark:
        "results/benchmarks/rules/fig8_dual.tsv"
    log:
        "results/logs/figures/fig8_dual.log",
    script:
        "../scripts/fig_dual.py"


# Figure data: λ_h on Γ, stable vs unstable, the Hertz scene's d and R on one mesh; the (case,
# k) pairs and the mesh: config key figures.elastic_profiles.


rule elastic_hertz_profiles:
    output:
        "results/tables/elastic_hertz_profiles.csv",
    input:
        PACKAGE_SOURCES,
    params:
        ec=lambda wc: scenes_of(config, "elastic"),  # the model table's elastic study (config key studies.elastic)
        fig=lambda wc: config["figures"]["elastic_profiles"],
    threads: 1
    benchmark:
        "results/benchmarks/rules/elastic_hertz_profiles.tsv"
    log:
        "results/logs/elastic/hertz_profiles.log",
    script:
        "../scripts/hertz_profiles_job.py"


rule elastic_figure:
    output:
        pdf="results/figures/fig9_elastic.pdf",
        png="results/figures/fig9_elastic.png",
    input:
        sweep="results/tables/elastic_nu_sweep.csv",
        profiles="results/tables/elastic_hertz_profiles.csv",
        style=PLOT_STYLE,
    benchmark:
        "results/benchmarks/rules/elastic_figure.tsv"
    log:
        "results/logs/figures/fig9_elastic.log",
    script:
        "../scripts/fig_elastic.py"


if FACE_FIGURE_NAMES:
    # The worst mode of panel (d), config figures.face_mode (the tetrahedra's P_0 at k = 2 on the Kuhn triangles of Γ),
    # whose one kernel mode is the checkerboard. A kernel vector does not depend on the norm, so the
    # cheap L2 Gram serves; N = 4 shows the pattern (32 triangles) in well under a second.
    FACE_MODE = dict(config["figures"]["face_mode"], model=scenes_of(config, FACE_STUDY)["model"], norm="L2")
    # HEX20 bodies (k = 2, QUAD8 faces) for the third panel of fig10_face_beta: the β table of the
    # model table's beta study on HEX20 bodies (config models: an entry with elements [hex20]), where
    # there is one; its claims are the ledger's
    FACE_HEX20_STUDY = next((name for name, study in MODEL_STUDIES.items()
                             if "hex20" in getattr(study, "elements", ())), None)

    rule face_worst_mode:
        output:
            "results/tables/face_worst_mode.csv",
        input:
            PACKAGE_SOURCES,
        params:
            args=(f"--model {FACE_MODE['model']} --element {FACE_MODE['element']} --case {FACE_MODE['case']} "
                  f"--k {FACE_MODE['k']} --N1 {FACE_MODE['N']} --N2 {FACE_MODE['N']} --norm {FACE_MODE['norm']}"),
        threads: 1
        resources:
            mem_mb=1000,
            runtime=5,
        benchmark:
            "results/benchmarks/rules/face_worst_mode.tsv"
        log:
            "results/logs/figures/face_worst_mode.log",
        shell:
            # the β row goes to the log; the modes' table is written atomically by --worst-mode
            # (--force: the rule owns its output; Snakemake removes it first, a rerun by hand does not)
            _BLAS1 + "python -m infsup_contact beta {params.args} --worst-mode {output} --force > {log} 2>&1"

    rule face_figures:
        output:
            beta_pdf=FIGURE_OUT["fig10_face_beta"]["pdf"],
            beta_png=FIGURE_OUT["fig10_face_beta"]["png"],
            studies_pdf=FIGURE_OUT["fig11_face_studies"]["pdf"],
            studies_png=FIGURE_OUT["fig11_face_studies"]["png"],
        input:
            beta=table_path(FACE_STUDY, "beta"),
            edge=job_path(FACE_STUDY, "edge_dropping"),
            alpha=job_path(FACE_STUDY, "alpha"),
            modes="results/tables/face_worst_mode.csv",
            hex20=[table_path(FACE_HEX20_STUDY, "beta")] if FACE_HEX20_STUDY else [],
            style=PLOT_STYLE,
            figures="src/infsup_contact/report/figures/face.py",
        benchmark:
            "results/benchmarks/rules/face_figures.tsv"
        log:
            "results/logs/figures/face_figures.log",
        script:
            "../scripts/fig_face.py"


if ARC_FIGURE_NAMES:
    # Panel (c), config figures.arc_mode, on the most curved arc of the study, non-matching, projected: the flat
    # segment's two end modes lifted to β_h > 0 (a kernel vector would not depend on the norm; this
    # mode does, H is the study's norm)
    ARC_MODE = dict(config["figures"]["arc_mode"], radius=min(MODEL_STUDIES[ARC_STUDY].cfg["radii"]))

    rule arc_worst_mode:
        output:
            "results/tables/arc_worst_mode.csv",
        input:
            PACKAGE_SOURCES,
        params:
            args=(f"--gamma arc --radius {ARC_MODE['radius']} --coupling projection --case {ARC_MODE['case']} "
                  f"--k {ARC_MODE['k']} --N1 {ARC_MODE['N1']} --N2 {ARC_MODE['N2']} --norm H"),
        threads: 1
        resources:
            mem_mb=1000,
            runtime=5,
        benchmark:
            "results/benchmarks/rules/arc_worst_mode.tsv"
        log:
            "results/logs/figures/arc_worst_mode.log",
        shell:
            _BLAS1 + "python -m infsup_contact beta {params.args} --worst-mode {output} --force > {log} 2>&1"

    rule curved_figure:
        output:
            pdf=FIGURE_OUT["fig12_curved"]["pdf"],
            png=FIGURE_OUT["fig12_curved"]["png"],
        input:
            beta=table_path(ARC_STUDY, "beta"),
            patch=table_path(ARC_STUDY, ARC_PATCH),
            modes="results/tables/arc_worst_mode.csv",
            style=PLOT_STYLE,
            figures="src/infsup_contact/report/figures/curved.py",
        benchmark:
            "results/benchmarks/rules/curved_figure.tsv"
        log:
            "results/logs/figures/curved_figure.log",
        script:
            "../scripts/fig_curved.py"
