"""The generated subsection of a model of the model table (:mod:`infsup_contact.plans.beta`).

One page per model: what was run, how many of its claims came out as predicted, and its β_h on
matching meshes in both norms (rows: norm, element, k, case; columns: N). A pure function of the
model's β table and claims; ``paper/paper.tex`` reads ``model_sections.tex``, which
:func:`sections_index_tex` writes as one ``\\input`` per such model.
"""
from __future__ import annotations

import pandas as pd

from .sections import n_as_predicted, predicted
from .templates import Group, body_lines, case_keys, multicolumn, row, tabular
from .texformat import PaperTexError, fmt_fixed, latex_escape, latex_id

NORM_TITLES = {"H": r"$\|\cdot\|_M$ = dual norm of $H^{1/2}_{00}(\Gamma)$",
               "L2": r"$\|\cdot\|_M$ = $L^2(\Gamma)$ norm (Remark 3.1)"}


def matching_beta_table(beta: pd.DataFrame) -> str:
    """Tabular of β_h on matching meshes: rows (norm, element, k, case), columns N."""
    b = beta[beta.N1 == beta.N2]
    if b.empty:
        raise PaperTexError("the model's β table has no matching rows")
    ns = sorted({int(n) for n in b.N2})
    val = b.set_index(["norm", "element", "k", "case", "N2"]).beta
    heads, blocks = tuple(rf"$N={n}$" for n in ns), []
    for norm in [n for n in NORM_TITLES if n in set(b.norm)]:
        cells = Group(heads, lambda key, norm=norm: [fmt_fixed(val[(norm, *key, n)], 4) if (norm, *key, n) in val.index
                                                     else "--" for n in ns])
        blocks += [[multicolumn(len(ns) + 3, NORM_TITLES[norm], "l") + r" \\"],
                   body_lines(case_keys(b[b.norm == norm], "element", "k"),
                              lambda key: [latex_escape(key[0]), str(key[1]), latex_id(key[2])], [cells])]
    return tabular("lll" + "r" * len(ns), [row("element", "$k$", "case", *heads)], blocks)


def model_section_tex(name: str, entry: dict, beta: pd.DataFrame, claims: pd.DataFrame) -> str:
    """The subsection of the model-table entry ``name`` (module docstring)."""
    checked, agree = predicted(claims), n_as_predicted(claims)
    model = latex_escape(str(beta.model.iloc[0]))
    return "\n".join([
        rf"\subsection{{The model \texttt{{{latex_escape(name)}}}}}\label{{sec:model-{name}}}",
        rf"Model \texttt{{{model}}} of the model table (\texttt{{config: models.{latex_escape(name)}}}): $\beta_h$ "
        rf"of {len(set(beta.case))} multiplier spaces, $k \in \{{{', '.join(map(str, sorted(set(beta.k))))}\}}$, "
        rf"{len(beta)} rows. Of its {len(claims)} ledger claims, {len(checked)} carry a prediction and "
        rf"{agree} came out as predicted.",
        r"\begin{center}", r"\small", matching_beta_table(beta), r"\end{center}", ""])


def sections_index_tex(names) -> str:
    """``model_sections.tex``: one ``\\input`` per generated model subsection (empty without any)."""
    return "".join(rf"\input{{{name}}}" + "\n" for name in names)
