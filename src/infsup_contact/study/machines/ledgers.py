"""The CI ledgers of several machine paths compared byte for byte (``snakemake verify-machines``,
:mod:`.machines`): which tables, which columns must not move, and the comparison itself."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ...io import TableError, read_table_text

LEDGER_TABLES = {"results/claims.csv": "claims", "results/tables/beta.csv": "beta",
                 "results/tables/contact.csv": "contact", "results/tables/elastic_beta.csv": "elastic_beta",
                 "results/tables/elastic_nu_sweep.csv": "elastic_beta",
                 "results/tables/elastic_patch.csv": "elastic_patch", "results/tables/membranes3d_beta.csv": "face_beta",
                 "results/tables/elastic3d_beta.csv": "elastic3d_beta",
                 "results/tables/membranes3d/alpha.csv": "face_alpha",
                 "results/tables/membranes3d/patch.csv": "face_patch",
                 "results/tables/elastic3d/patch.csv": "elastic3d_patch"}
"""The CI profile's tables ``verify-machines`` compares across paths (relative to the workflow),
each with the schema it is read under: the ledger and every table of the segment's, the elastic
and the face stages that carries a kernel column."""
LEDGER_EXACT = ("verdict", "kernel_dim", "structural_kernel_dim", "kernel_detected", "kernel_decision",
                "kernel_check", "dim_M", "dim_W", "kernel_dim_membranes", "kernel_decision_membranes", "passes")
"""Columns that must be byte-identical across paths wherever a table of :data:`LEDGER_TABLES`
has them: verdicts, kernel decisions and dimensions, the patch tests' pass (errors of 1e-12
against 1e-8). ``kernel_margin_decades`` is a margin and β a number: their digits may move."""


ROW_LABEL = ("claim_id", "scene", "model", "element", "family", "case", "k", "N1", "N2", "multiplier_mesh", "norm",
             "nu", "alpha", "N")
"""Columns that name a row of a ledger table in :func:`ledger_differences`' messages (those it has)."""


def _row_label(frame: pd.DataFrame, i: int) -> str:
    cols = [c for c in ROW_LABEL if c in frame.columns] or [frame.columns[0]]
    return ", ".join(f"{c} {frame[c].iloc[i]}" for c in cols)


def ledger_differences(ledgers: dict) -> tuple[pd.DataFrame, list]:
    """Compare the CI ledgers of several paths column by column, byte for byte.

    Parameters
    ----------
    ledgers : dict
        path name → folder holding the tables of :data:`LEDGER_TABLES` (same relative paths)
        of a run on that path; the first is the reference.

    Returns
    -------
    summary : DataFrame
        One row per (table, column of :data:`LEDGER_EXACT` it has): ``rows`` and ``identical``.
    problems : list of str
        A table missing or without any exact column, rows or columns that differ between the
        ledgers, and every row whose exact column differs (table, row number, column, values).
    """
    problems, summary = [], []
    (ref_name, ref_dir), *others = ledgers.items()
    for table in LEDGER_TABLES:
        texts = {}
        for name, folder in ledgers.items():
            f = Path(folder) / table
            if not f.is_file():
                problems.append(f"{table}: missing under {name} ({f})")
                continue
            # every cell as the text written: a byte comparison, no parsing of numbers
            try:
                texts[name] = read_table_text(f, LEDGER_TABLES[table])
            except TableError as err:  # a damaged table is a difference, in one line
                problems.append(f"{table}: damaged under {name}: {err}")
        if ref_name not in texts:
            continue
        ref = texts[ref_name]
        cols = [c for c in LEDGER_EXACT if c in ref.columns]
        if not cols:
            problems.append(f"{table}: none of the exact columns ({', '.join(LEDGER_EXACT)}) under {ref_name}")
        for name, frame in texts.items():
            if name != ref_name and (list(frame.columns) != list(ref.columns) or len(frame) != len(ref)):
                problems.append(f"{table}: {name} has {len(frame)} rows × {len(frame.columns)} columns, "
                                f"{ref_name} {len(ref)} × {len(ref.columns)}")
        for col in cols:
            same = True
            for name, frame in texts.items():
                if name == ref_name or col not in frame.columns or len(frame) != len(ref):
                    same = same and name == ref_name
                    continue
                diff = np.flatnonzero(frame[col].to_numpy() != ref[col].to_numpy())
                same = same and not len(diff)
                problems += [f"{table} row {i} ({_row_label(ref, i)}): {col} {frame[col].iloc[i]} under "
                             f"{name}, {ref[col].iloc[i]} under {ref_name}" for i in diff]
            summary.append(dict(table=table, column=col, rows=len(ref), identical=same))
    return pd.DataFrame(summary, columns=["table", "column", "rows", "identical"]), problems
