# Top-level entry point: the workflow lives in workflow/ (see workflow/Snakefile).
include: "workflow/Snakefile"
# An included file's default target is not kept by Snakemake: restate it here.
workflow.default_target = "reproduce-all"
