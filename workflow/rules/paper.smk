# Paper stage: results tables → results/paper/*.tex (every number of the text) → paper.pdf.
# Needs TeX (latexmk, pdflatex): workflow/scripts/ensure_tex.sh installs it as root on
# Debian or prints the one line saying what to install.

# every figure of the figures stage (FIGURE_NAMES, rules/figures.smk) is in the paper
PAPER_FIGURES = [f"results/figures/{name}.pdf" for name in FIGURE_NAMES]


rule paper_macros:
    output:
        macros="results/paper/macros.tex",
        claims="results/paper/claims_table.tex",
        rates="results/paper/rates_table.tex",
        beta="results/paper/beta_table.tex",
        speed="results/paper/speed_table.tex",
        front="results/paper/front_table.tex",
        nonmatching="results/paper/nonmatching_table.tex",
    input:
        beta="results/tables/beta.csv",
        contact="results/tables/contact.csv",
        rates="results/tables/rates.csv",
        claims="results/claims.csv",
        speed="results/tables/speed_accuracy.csv",
        bench_beta="results/benchmarks/beta.csv",
        bench_contact="results/benchmarks/contact.csv",
        provenance="results/provenance.json",
        tex="paper/paper.tex",
        src=REPORT_SOURCES,
    params:
        cfg=lambda wc: {key: config[key] for key in ("claims", "contact", "infsup", "benchmarks")},
    benchmark:
        "results/benchmarks/rules/paper_macros.tsv"
    log:
        "results/logs/paper_macros.log",
    script:
        "../scripts/paper_macros.py"


rule model_paper:
    # one study of the model table: its generated LaTeX (plans/<study>.py), into results/paper/{model}/
    output:
        directory("results/paper/{model}"),
    input:
        lambda wc: [path for path, _ in MODEL_STUDIES[wc.model].paper_inputs().files.values()],
        tex=lambda wc: [MODEL_STUDIES[wc.model].tex_source] if MODEL_STUDIES[wc.model].tex_source else [],
        src=REPORT_SOURCES,
    params:
        nu_slope_cases=lambda wc: config["figures"]["nu_slope_cases"],
        claims=lambda wc: config["claims"],  # the arc's verdicts: slope tolerance, floor, confidence
    wildcard_constraints:
        model=MODEL_NAMES_RE,
    benchmark:
        "results/benchmarks/rules/model_paper/{model}.tsv"
    log:
        "results/logs/{model}/paper.log",
    script:
        "../scripts/model_paper.py"


rule model_sections:
    # \input of each generated model subsection (plans/beta.py), read by paper/paper.tex
    output:
        "results/paper/model_sections.tex",
    params:
        names=MODEL_SECTIONS,
    log:
        "results/logs/model_sections.log",
    script:
        "../scripts/model_sections.py"


rule paper_pdf:
    output:
        "results/paper/paper.pdf",
    input:
        tex="paper/paper.tex",
        bib="paper/references.bib",
        generated=rules.paper_macros.output,
        figures=PAPER_FIGURES,
        elastic_tex="paper/elastic.tex",  # the elastic section (model table: elastic)
        elastic_figure=["results/figures/fig9_elastic.pdf"] if "elastic" in MODEL_STUDIES else [],
        face_tex="paper/face.tex",  # the face section (model table: membranes3d; its elastic subsection: elastic3d)
        models=MODEL_PAPER,  # each study's generated files (rule model_paper), \input by name
        model_sections="results/paper/model_sections.tex",  # the generated model subsections (rule model_sections)
        producers=PRODUCERS_PAPER,  # "Certifying production codes" (rules/producers.smk), \InputIfFileExists in paper.tex
    benchmark:
        "results/benchmarks/rules/paper_pdf.tsv"
    log:
        "results/logs/paper_pdf.log",
    params:
        build="results/paper/build",
        # the generated files: results/paper/ and each study's folder (rule model_paper)
        texinputs=lambda wc: ":".join(["$root/results/paper", *(f"$root/{d}" for d in MODEL_PAPER),
                                       "$root/results/figures"]),
    shell:
        # ensure_tex.sh: TeX present, installed (root, Debian) or one line on what to install.
        # Then a fresh build dir; TEXINPUTS finds the generated .tex and the figures; a fixed
        # SOURCE_DATE_EPOCH makes the PDF bytes reproducible; the copy out is atomic.
        """
        bash workflow/scripts/ensure_tex.sh
        root=$PWD
        rm -rf {params.build} && mkdir -p {params.build}
        cp {input.tex} {input.bib} {input.elastic_tex} {input.face_tex} {params.build}/
        cd {params.build}
        export TEXINPUTS="{params.texinputs}:" SOURCE_DATE_EPOCH=0 FORCE_SOURCE_DATE=1
        if ! latexmk -pdf -interaction=nonstopmode -halt-on-error -file-line-error paper.tex > "$root/{log}" 2>&1; then
            echo "paper_pdf: LaTeX failed (full log: {log}); first error:" >&2
            grep -m1 -A3 -E '^([.]/)?paper[.]tex:[0-9]+:|^! ' "$root/{log}" >&2 || true
            exit 1
        fi
        cp paper.pdf "$root/{output}.tmp"
        mv "$root/{output}.tmp" "$root/{output}"
        """


rule paper_target:
    name: "paper"
    input:
        "results/paper/paper.pdf",
