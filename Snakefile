# Top-level entry point: the workflow lives in workflow/ (see workflow/Snakefile).
include: "workflow/Snakefile"
