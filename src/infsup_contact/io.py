"""Atomic output (an interrupted run never leaves a half-written file behind) and checked input
(a table missing a column, or no table at all, is one line naming the file)."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path


def _replace_atomic(path, data, mode: str) -> None:
    """Write ``data`` to ``path`` via a temporary file in the same directory and a rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, mode) as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_atomic(path, text: str) -> None:
    """Write ``text`` to ``path`` atomically (temporary file in the same directory, rename)."""
    _replace_atomic(path, text, "w")


def write_bytes_atomic(path, data: bytes) -> None:
    """:func:`write_atomic` for bytes (a pickled reference solution)."""
    _replace_atomic(path, data, "wb")


def write_csv_atomic(path, frame) -> None:
    """Write a pandas DataFrame as CSV atomically (deterministic float format)."""
    write_atomic(path, frame.to_csv(index=False, float_format="%.12g"))


# ---------------------------------------------------------------- reading tables

TABLE_COLUMNS = {
    # the columns a consumer of each workflow table relies on (the producers write them)
    "beta": ("case", "k", "family", "N1", "N2", "multiplier_mesh", "c1", "c2", "norm", "beta",
             "kernel_dim", "structural_kernel_dim", "smallest_nonzero", "beta_v1_zero", "dim_M", "dim_W",
             "ndof"),
    "contact": ("scene", "case", "k", "family", "N1", "N2", "c1", "c2", "ndof", "dim_M", "cone",
                "iterations", "energy_error", "l2_error", "lambda_l2_error", "lambda_hm12_error",
                "min_lambda_pointwise", "max_penetration", "nonunique", "kernel_dim"),
    "contact_input": ("scene", "case", "k", "family", "N1", "N2", "energy_error", "l2_error",
                      "lambda_l2_error", "lambda_hm12_error"),  # `infsup-contact rates`
    "rates": ("scene", "case", "k", "family", "measure", "slope", "stderr", "points", "h_min", "expected"),
    "claims": ("claim_id", "paper_ref", "statement", "evidence", "verdict", "predicted"),
    "gamma_profiles": ("case", "k", "N", "x", "quantity", "value"),
    "field_values": ("case", "k", "N", "side", "x", "y", "u"),
    "speed_accuracy": ("scene", "case", "k", "family", "N", "seconds", "energy_error",
                       "lambda_hm12_error", "ndof", "dim_M", "pareto_energy", "pareto_lambda"),
    "bench": ("what", "route", "k", "N", "seconds_median", "seconds_min", "seconds_max", "ratio_to_ours"),
    # elastic stage (study/elastic_beta.py)
    "elastic_beta": ("model", "case", "k", "family", "N1", "N2", "E1", "E2", "nu", "norm", "beta", "kernel_dim",
                     "structural_kernel_dim", "smallest_nonzero", "beta_membranes", "kernel_dim_membranes",
                     "bound_factor"),
    "elastic_patch": ("case", "k", "N1", "N2", "p", "kernel_dim", "lambda_max_rel_error", "lambda_end_rel_error",
                      "lambda_middle_rel_error", "u_max_rel_error", "passes"),
    "elastic_hertz": ("study", "case", "k", "N", "d", "P", "p_max", "half_width", "oscillation",
                      "p_max_rel_error", "half_width_rel_error"),
}
"""Required columns per table kind (:func:`read_table`)."""

TABLE_LABELS = {"contact_input": "a contact table (`infsup-contact contact` or results/tables/contact.csv)",
                "claims": "a claims ledger", "bench": "a bench table"}

NUMERIC_COLUMNS = {"k", "N", "N1", "N2", "c1", "c2", "beta", "kernel_dim", "dim_M", "dim_W", "ndof",
                   "energy_error", "l2_error", "lambda_l2_error", "lambda_hm12_error", "slope",
                   "stderr", "points", "h_min", "expected", "x", "y", "u", "value", "seconds",
                   "seconds_median", "seconds_min", "seconds_max"}
"""Columns that must hold numbers (NaN allowed: an empty cell is a missing value)."""


class TableError(ValueError):
    """A table that cannot be used: the message is one line naming the file and what is wrong."""

    def __init__(self, path, problem: str, allowed: str | None = None, key: str = "table"):
        self.key, self.path = key, str(path)
        super().__init__(f"table {path}: {problem}" + (f" (allowed: {allowed})" if allowed else ""))


def read_table(path, kind: str, allow_empty: bool = False):
    """Read a CSV table of ``kind`` (:data:`TABLE_COLUMNS`) and check it before use.

    Raises :class:`TableError` (one line naming the file) for a missing, unreadable or empty
    file, a file that is not CSV, missing columns (named) or non-numeric values in a numeric
    column (the first one named, with its row).
    """
    import pandas as pd

    p = Path(path)
    if not p.exists():
        raise TableError(path, "no such file")
    if p.is_dir():
        raise TableError(path, "a directory, not a CSV file")
    try:
        with open(p, "rb") as fh:
            head = fh.read(1)
    except OSError as err:
        raise TableError(path, f"not readable ({err.strerror})") from None
    if not head:
        raise TableError(path, "empty file (no header, no rows)")
    try:
        frame = pd.read_csv(p)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError, ValueError) as err:
        reason = " ".join(str(err).split())[:120]
        raise TableError(path, f"not a readable CSV table ({type(err).__name__}: {reason})") from None
    required = TABLE_COLUMNS[kind]
    missing = [c for c in required if c not in frame.columns]
    if missing:
        raise TableError(path, f"missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)} "
                         f"(has {', '.join(map(str, frame.columns[:12]))}{', …' if len(frame.columns) > 12 else ''})",
                         allowed=f"{TABLE_LABELS.get(kind, f'a {kind} table')} with the columns {', '.join(required)}")
    if len(frame) == 0 and not allow_empty:
        raise TableError(path, "no data rows (only a header)")
    for col in required:
        if col in NUMERIC_COLUMNS and not pd.api.types.is_numeric_dtype(frame[col]):
            values = pd.to_numeric(frame[col], errors="coerce")
            bad = values.isna() & frame[col].notna()
            if bad.any():
                row = int(bad.to_numpy().nonzero()[0][0])
                raise TableError(path, f"column {col} holds a non-number ({frame[col].iloc[row]!r} in data row "
                                 f"{row + 1})", allowed="numbers (or empty cells)")
            frame[col] = values
    return frame
