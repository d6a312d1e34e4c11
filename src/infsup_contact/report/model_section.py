"""The generated subsection of a model of the model table (:mod:`infsup_contact.plans.beta`).

One page per model: what was run, how many of its claims came out as predicted, and its β_h on
matching meshes in both norms (rows: norm, element, k, case; columns: N). A pure function of the
model's β table and claims; ``paper/paper.tex`` reads ``model_sections.tex``, which
:func:`sections_index_tex` writes as one ``\\input`` per such model.
"""
from __future__ import annotations

import pandas as pd

from .texformat import PaperTexError, case_order, fmt_fixed, latex_escape, latex_id

NORM_TITLES = {"H": r"$\|\cdot\|_M$ = dual norm of $H^{1/2}_{00}(\Gamma)$",
               "L2": r"$\|\cdot\|_M$ = $L^2(\Gamma)$ norm (Remark 3.1)"}


def matching_beta_table(beta: pd.DataFrame) -> str:
    """Tabular of β_h on matching meshes: rows (norm, element, k, case), columns N."""
    b = beta[beta.N1 == beta.N2]
    if b.empty:
        raise PaperTexError("the model's β table has no matching rows")
    ns = sorted({int(n) for n in b.N2})
    val = b.set_index(["norm", "element", "k", "case", "N2"]).beta
    lines = [r"\begin{tabular}{lll" + "r" * len(ns) + "}", r"\toprule",
             r"element & $k$ & case & " + " & ".join(rf"$N={n}$" for n in ns) + r" \\"]
    for norm in [n for n in NORM_TITLES if n in set(b.norm)]:
        lines += [r"\midrule", rf"\multicolumn{{{len(ns) + 3}}}{{l}}{{{NORM_TITLES[norm]}}} \\", r"\midrule"]
        for (element, k), rows in b[b.norm == norm].groupby(["element", "k"], sort=True):
            for case in case_order(rows.case):
                cells = [fmt_fixed(val[key], 4) if (key := (norm, element, k, case, n)) in val.index else "--"
                         for n in ns]
                lines.append(f"{latex_escape(element)} & {k} & {latex_id(case)} & " + " & ".join(cells) + r" \\")
    return "\n".join(lines + [r"\bottomrule", r"\end{tabular}", ""])


def model_section_tex(name: str, entry: dict, beta: pd.DataFrame, claims: pd.DataFrame) -> str:
    """The subsection of the model-table entry ``name`` (module docstring)."""
    checked = claims[claims.predicted.isin(["PASS", "FAIL"])]
    agree = int((checked.verdict == checked.predicted).sum())
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
