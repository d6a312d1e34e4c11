"""The generated subsection of a model of the model table (:mod:`infsup_contact.plans.beta`).

One page per model: what was run, how many of its claims came out as predicted, and its β_h on
matching meshes in both norms (rows: norm, element, k, case; columns: N). A pure function of the
model's β table and claims; ``paper/paper.tex`` reads ``model_sections.tex``, which
:func:`sections_index_tex` writes as one ``\\input`` per such model.
"""
from __future__ import annotations

import pandas as pd

from .sections import n_as_predicted, predicted
from .templates import beta_by_mesh_table
from .texformat import PaperTexError, latex_escape, latex_id

def matching_beta_table(beta: pd.DataFrame) -> str:
    """Tabular of β_h on matching meshes: rows (norm, element, k, case), columns N
    (:func:`~.templates.beta_by_mesh_table`)."""
    b = beta[beta.N1 == beta.N2]
    if b.empty:
        raise PaperTexError("the model's β table has no matching rows")
    return beta_by_mesh_table(b, sorted({int(n) for n in b.N2}), ("element", "k"), ("element", "$k$", "case"),
                              lambda key: [latex_escape(key[0]), str(key[1]), latex_id(key[2])])


def model_section_tex(name: str, entry: dict, beta: pd.DataFrame, claims: pd.DataFrame) -> str:
    """The subsection of the model-table entry ``name`` (module docstring)."""
    checked, agree = predicted(claims), n_as_predicted(claims)
    model = latex_id(str(beta.model.iloc[0]))
    return "\n".join([
        rf"\subsection{{The model \texttt{{{latex_id(name)}}}}}\label{{sec:model-{name}}}",
        rf"Model \texttt{{{model}}} of the model table (\texttt{{config: models.{latex_id(name)}}}): $\beta_h$ "
        rf"of {len(set(beta.case))} multiplier spaces, $k \in \{{{', '.join(map(str, sorted(set(beta.k))))}\}}$, "
        rf"{len(beta)} rows. Of its {len(claims)} ledger claims, {len(checked)} carry a prediction and "
        rf"{agree} came out as predicted.",
        r"\begin{center}", r"\small", matching_beta_table(beta), r"\end{center}", ""])


def sections_index_tex(names) -> str:
    """``model_sections.tex``: one ``\\input`` per generated model subsection (empty without any)."""
    return "".join(rf"\input{{{name}}}" + "\n" for name in names)
