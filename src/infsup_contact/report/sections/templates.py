"""Templates of the sections' generated tables (paper/elastic.tex, paper/face.tex).

Every table of a section is a booktabs tabular (:func:`tabular`): head lines, then blocks of
rows split by ``\\midrule``. The kinds of table — a model's β_h table, its patch-test table,
a sweep table (ν, α, θ) — differ in their rows, columns and cells, which a model declares as
data: :func:`case_table` lays out rows keyed by (block, …, case) (:func:`case_blocks`), each
row's label cells and a list of column :class:`Group` s, each group optionally under a
spanning title (the β_h table per k or per mesh, the patch table per k, the α sweep per
element). The cells of each kind are here: β_h with its kernel (:func:`beta_cell`,
:func:`kernel_cell`), the patch test's error maxima (:func:`error_cells`), a claim's verdict
(:func:`verdict_cell`) and the rows of a sweep at one parameter value (:func:`at`). The
macro blocks of a model's claims are :mod:`.sections`'.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import pandas as pd

from ..texformat import case_order, fmt_fixed, fmt_sci, latex_id

VERDICT_SHORT = {"PASS": "P", "FAIL": "F", "INCONCLUSIVE": "I"}
"""A verdict's letter in a table cell."""
NORM_TITLES = {"H": r"$\|\cdot\|_M$ = dual norm of $H^{1/2}_{00}(\Gamma)$",
               "L2": r"$\|\cdot\|_M$ = $L^2(\Gamma)$ norm (Remark 3.1)"}
"""The norms of M_h, in the order a β_h table shows them, with the title of their block."""


# --------------------------------------------------------------------------- the tabular skeleton

def row(*cells) -> str:
    """One table row: the cells joined by ``&``, ended by ``\\\\``."""
    return " & ".join(cells) + r" \\"


def multicolumn(span: int, text: str, align: str = "c") -> str:
    return rf"\multicolumn{{{span}}}{{{align}}}{{{text}}}"


def tabular(spec: str, head: Sequence[str], blocks: Sequence[Sequence[str]], after: Sequence[str] = ()) -> str:
    """A booktabs tabular: the ``head`` lines, the ``blocks`` of body lines each after a
    ``\\midrule``, and the ``after`` lines (a comment) behind ``\\end{tabular}``."""
    lines = [rf"\begin{{tabular}}{{{spec}}}", r"\toprule", *head]
    for block in blocks:
        lines += [r"\midrule", *block]
    return "\n".join(lines + [r"\bottomrule", r"\end{tabular}", *after]) + "\n"


# --------------------------------------------------------------------------- tables of keyed rows

@dataclass(frozen=True)
class Group:
    """Columns of a table under one spanning ``title`` (None: no title; its head cells stay
    blank in the title row): their ``heads`` and ``cells(key)``, a row's cells."""

    heads: tuple
    cells: Callable[[tuple], list]
    title: str | None = None


def blank(n: int) -> Group:
    """``n`` empty columns (none if ``n`` <= 0): pads a part of a table to the width of another."""
    return Group(("",) * n, lambda key: [""] * n)


def head_lines(lead: Sequence[str], groups: Sequence[Group]) -> list[str]:
    """The title row of the groups (if one has a title) and the row of column heads."""
    lines = []
    if any(g.title is not None for g in groups):
        titles = [c for g in groups for c in ([multicolumn(len(g.heads), g.title)] if g.title is not None
                                              else [""] * len(g.heads))]
        lines.append(" &" * len(lead) + " " + row(*titles))
    return lines + [row(*lead, *[h for g in groups for h in g.heads])]


def body_lines(keys: Sequence[tuple], label: Callable[[tuple], list], groups: Sequence[Group]) -> list[str]:
    """One row per key: its ``label`` cells, then every group's cells."""
    return [row(*label(key), *[c for g in groups for c in g.cells(key)]) for key in keys]


def case_table(spec: str, lead: Sequence[str], label: Callable, groups: Sequence[Group],
               blocks: Sequence[Sequence[tuple]], head_after: Sequence[str] = (), after: Sequence[str] = ()) -> str:
    """A table of keyed rows: heads ``lead`` + the groups' heads, then one block of rows per
    list of keys in ``blocks`` (:func:`case_blocks`).

    Parameters
    ----------
    spec : str
        The tabular's column specification.
    lead : sequence of str
        Heads of the label columns.
    label : callable
        key → the row's label cells (``latex_id`` of its element, case, …).
    groups : sequence of Group
        The value columns.
    blocks : sequence of sequences of keys
        The rows, block by block (a ``\\midrule`` between blocks).
    head_after, after : sequence of str
        Lines after the head (a note spanning the table) and after the tabular.
    """
    return tabular(spec, head_lines(lead, groups) + list(head_after),
                   [body_lines(keys, label, groups) for keys in blocks], after)


def case_blocks(frame: pd.DataFrame, *by: str, order: Sequence | None = None) -> list[list[tuple]]:
    """Keys ``(*values of by, case)`` of ``frame``, one block per group of ``by`` (sorted; or,
    given ``order``, per value of the one column ``by`` in that order), the cases of a block in
    the paper's order (:func:`~.texformat.case_order`)."""
    if not by:
        groups = [((), frame)]
    elif order is not None:
        groups = [((value,), frame[frame[by[0]] == value]) for value in order]
    else:
        groups = [(key if isinstance(key, tuple) else (key,), g) for key, g in frame.groupby(list(by), sort=True)]
    return [[(*key, case) for case in case_order(g.case.unique())] for key, g in groups]


def case_keys(frame: pd.DataFrame, *by: str, order: Sequence | None = None) -> list[tuple]:
    """The keys of :func:`case_blocks` in one list (one block)."""
    return [key for block in case_blocks(frame, *by, order=order) for key in block]


def beta_by_mesh_table(beta: pd.DataFrame, ns: Sequence[int], by: Sequence[str], lead: Sequence[str],
                       label: Callable) -> str:
    """The β_h table of a model's meshes: one block per norm (:data:`NORM_TITLES`) under its
    title, rows keyed by ``(*by, case)`` (:func:`case_keys`), one column per N in ``ns``
    (``--`` where that N was not run).

    Parameters
    ----------
    beta : DataFrame
        Rows with columns norm, ``by``, case, N2 and beta, one per (norm, *by, case, N2).
    ns : sequence of int
    by : sequence of str
        The key columns before the case (``("k",)``, ``("element", "k")``).
    lead, label
        Heads of the label columns and key → label cells (:func:`case_table`).
    """
    val = beta.set_index(["norm", *by, "case", "N2"]).beta
    heads, blocks = tuple(rf"$N={n}$" for n in ns), []
    for norm in [n for n in NORM_TITLES if n in set(beta.norm)]:
        cells = Group(heads, lambda key, norm=norm: [fmt_fixed(val[(norm, *key, n)], 4) if (norm, *key, n) in val.index
                                                     else "--" for n in ns])
        blocks += [[multicolumn(len(lead) + len(ns), NORM_TITLES[norm], "l") + r" \\"],
                   body_lines(case_keys(beta[beta.norm == norm], *by), label, [cells])]
    return tabular("l" * len(lead) + "r" * len(ns), [row(*lead, *heads)], blocks)


# --------------------------------------------------------------------------- cells of the kinds

def beta_cell(rows: pd.DataFrame, kernel_note: bool = False) -> str:
    """β_h of the first row to 4 decimals; ``0`` where it has a kernel (``0 [d]`` with the
    kernel dimension if ``kernel_note``); ``--`` without a row."""
    if rows.empty:
        return "--"
    r = rows.iloc[0]
    if r.kernel_dim == 0:
        return fmt_fixed(r.beta, 4)
    return f"0 [{int(r.kernel_dim)}]" if kernel_note else "0"


def kernel_cell(rows: pd.DataFrame) -> str:
    """``d (c)``: the kernel dimension of the first row and its dimension count (``--`` if none)."""
    if rows.empty:
        return "--"
    r = rows.iloc[0]
    return f"{int(r.kernel_dim)} ({int(r.structural_kernel_dim)})"


def error_cells(rows: pd.DataFrame, columns: Sequence[str]) -> list[str]:
    """The largest value of each error column over ``rows`` (the patch test's pairs), 3 digits."""
    return [fmt_sci(rows[c].max(), 2) for c in columns]


def verdict_cell(claims: pd.DataFrame, claim_id: str) -> str:
    """The claim's verdict letter, ``*`` after a finding (no prediction); ``--`` without the claim."""
    hit = claims[claims.claim_id == claim_id]
    if not len(hit):
        return "--"
    return VERDICT_SHORT.get(hit.verdict.iloc[0], "?") + ("" if hit.predicted.iloc[0] in ("PASS", "FAIL") else "*")


def at(rows: pd.DataFrame, column: str, value: float, rtol: float = 1e-5, atol: float = 1e-8) -> pd.DataFrame:
    """The rows of a sweep whose parameter ``column`` is ``value`` (to np.isclose's tolerances)."""
    return rows[np.isclose(rows[column], value, rtol=rtol, atol=atol)]


# --------------------------------------------------------------------------- lists in the text

def pair_tex(n1, n2) -> str:
    """A non-matching pair as ``$N_1{:}N_2$``."""
    return f"${int(n1)}{{:}}{int(n2)}$"


def pairs_tex(n1s, n2s) -> str:
    """The distinct pairs, sorted, as :func:`pair_tex` joined by commas."""
    return ", ".join(pair_tex(a, b) for a, b in sorted({(int(a), int(b)) for a, b in zip(n1s, n2s)}))


def ids_tex(ids) -> str:
    """The distinct ids in order of appearance, escaped, joined by commas."""
    return ", ".join(latex_id(i) for i in dict.fromkeys(ids))


def ints_tex(values) -> str:
    """The distinct integers, sorted, joined by commas."""
    return ", ".join(str(int(v)) for v in sorted(set(values)))
