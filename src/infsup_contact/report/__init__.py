"""Report: what turns tables into figures and the paper — shared figure style, the paper's macros and tables.

By concept: here the paper's own numbers and text — ``style`` / ``case_styles`` (one colour and
marker per space, from the registry), ``texnames`` / ``texformat`` (macro names, number formatting,
escaping), ``macros`` and ``tables`` (the paper's generated LaTeX), ``paper`` (the generated files and
the check of ``paper.tex``), ``consistency`` (text that stays true whatever the verdict);
``sections/`` the sections each study of the model table (and the producers) generates: one template
per kind of their tables (``templates``) and of their macro blocks (``blocks``), and per section its
declarations (``elastic``, ``face`` (membranes3d), ``elastic3d``, ``model_section`` for the table's other studies,
``producers``); ``figures/`` the figures drawn by the package.
Reads tables only; imports ``discretization`` (the registry) and nothing that computes.
"""
from .macros import all_macros, macros_tex, speed_macros
from .paper import GENERATED_FILES, SOURCE_INPUTS, check_paper, defined_macros, paper_files, used_generated_macros, used_inputs
from .tables import fastest_for_targets, front_table, front_winner, speed_rows, speed_table
from .texformat import MEASURES, SPEED_COLUMNS, PaperTexError, fmt_fixed, latex_escape, latex_id, parse_number
from .texnames import Macro, is_generated_name, macro_name, number_word, token

__all__ = ["all_macros", "macros_tex", "speed_macros", "GENERATED_FILES", "SOURCE_INPUTS", "check_paper", "defined_macros", "paper_files", "used_generated_macros", "used_inputs", "fastest_for_targets", "front_table", "front_winner", "speed_rows", "speed_table", "MEASURES", "SPEED_COLUMNS", "PaperTexError", "fmt_fixed", "latex_escape", "parse_number", "Macro", "is_generated_name", "macro_name", "number_word", "token"]
