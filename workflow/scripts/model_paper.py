"""A model study's generated LaTeX (rule model_paper): the plan's paper files from its tables,
checked against its hand-written section where it has one, written into results/paper/{model}/
all at once (a directory renamed into place: an interrupted job leaves no half section)."""
import os
import shutil
import sys
from pathlib import Path

sys.path.insert(0, "workflow/scripts")
from _glue import fail, log_to, read_table, register_user_spaces  # noqa: E402

log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821 (the patch macros ask each space for 1 ∈ M_h)

from infsup_contact.plans import study_of  # noqa: E402
from infsup_contact.report.texformat import PaperTexError  # noqa: E402

name = snakemake.wildcards.model  # noqa: F821
study = study_of(snakemake.config, name)  # noqa: F821
frames = {key: read_table(path, kind) for key, (path, kind) in study.paper_inputs().files.items()}
try:
    files = study.paper_files(frames, dict(snakemake.params.items()))  # noqa: F821
    if study.tex_source:
        study.check_tex(Path(study.tex_source).read_text(), files)
except PaperTexError as err:
    fail(f"model_paper {name}: {err}")
out = Path(snakemake.output[0])  # noqa: F821
tmp = out.with_name(f".{out.name}.tmp")
shutil.rmtree(tmp, ignore_errors=True)
tmp.mkdir(parents=True)
for filename, text in files.items():
    (tmp / filename).write_text(text)
shutil.rmtree(out, ignore_errors=True)
os.replace(tmp, out)
print(f"{name}: {', '.join(sorted(files))}", file=sys.stderr)
