"""The generated files of ``results/paper/`` and the check that ``paper/paper.tex`` uses only what exists.

Pure functions from the result tables (pandas DataFrames) and plain dicts (config,
provenance) to LaTeX text; no I/O (``workflow/scripts/paper_macros.py`` reads and writes).
"""
from __future__ import annotations

import re

from .macros import all_macros, macros_tex
from .tables import beta_table, claims_table, front_table, nonmatching_table, rates_table, speed_table
from .texformat import PaperTexError
from .texnames import is_generated_name

GENERATED_FILES = ("macros.tex", "claims_table.tex", "rates_table.tex", "beta_table.tex",
                   "speed_table.tex", "front_table.tex", "nonmatching_table.tex")
SOURCE_INPUTS = ("elastic", "face", "model_sections")
"""Sections of the paper kept in their own files: the model table's studies' sections
(paper/elastic.tex, paper/face.tex, with their own generated files) and the list of the generated
model subsections (``model_sections.tex``, rule model_sections)."""


def paper_files(beta, contact, rates, claims, speed, bench_beta, bench_contact, cfg, prov) -> dict[str, str]:
    """Every generated file of results/paper/ (name → text)."""
    return {"macros.tex": macros_tex(all_macros(beta, contact, rates, claims, speed, bench_beta,
                                                bench_contact, cfg, prov)),
            "claims_table.tex": claims_table(claims),
            "nonmatching_table.tex": nonmatching_table(claims),
            "rates_table.tex": rates_table(rates, cfg["contact"]["primary_scene"]),
            "beta_table.tex": beta_table(beta),
            "speed_table.tex": speed_table(speed),
            "front_table.tex": front_table(speed)}


# --------------------------------------------------------------------------- checks on paper.tex

def _strip_comments(tex: str) -> str:
    return re.sub(r"(?<!\\)%.*", "", tex)


def used_generated_macros(tex: str) -> set[str]:
    """Control words of ``tex`` that belong to the generated namespace (MACRO_PREFIXES)."""
    words = set(re.findall(r"\\([A-Za-z]+)", _strip_comments(tex)))
    return {w for w in words if is_generated_name(w)}


def used_inputs(tex: str) -> set[str]:
    return set(re.findall(r"\\input\{([^}]+)\}", _strip_comments(tex)))


def defined_macros(macros_text: str) -> set[str]:
    return set(re.findall(r"\\newcommand\{\\([A-Za-z]+)\}", macros_text))


def check_paper(tex: str, files: dict[str, str]) -> None:
    """Raise PaperTexError unless every generated macro and \\input of ``tex`` is produced."""
    missing_inputs = sorted(f for f in used_inputs(tex) if f not in files and f not in SOURCE_INPUTS)
    missing = sorted(used_generated_macros(tex) - defined_macros(files.get("macros.tex", "")))
    if missing_inputs or missing:
        raise PaperTexError(
            "paper/paper.tex uses what the tables do not provide: "
            + (f"\\input of {', '.join(missing_inputs)}; " if missing_inputs else "")
            + (f"macros {', '.join(missing)} (is that case/k/scene in the config?)" if missing else ""))
