"""Atomic output (an interrupted run never leaves a half-written file behind) and checked input
(every table is read through :func:`read_table`, against its declared schema (:mod:`.table_schemas`): a damaged
table is one line naming the file and the row)."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .table_schemas import SCHEMAS, Schema


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
    """:func:`write_atomic` for bytes (a reference solution's ``.npz``)."""
    _replace_atomic(path, data, "wb")


def write_csv_atomic(path, frame) -> None:
    """Write a pandas DataFrame as CSV atomically (deterministic float format)."""
    write_atomic(path, frame.to_csv(index=False, float_format="%.12g"))


# ---------------------------------------------------------------- reading tables
# against the declared tables of :mod:`infsup_contact.table_schemas`

_TYPE_WORDS = {"int": "integers", "float": "finite numbers", "str": "non-empty text", "bool": "True or False"}


class TableError(ValueError):
    """A table that cannot be used: the message is one line naming the file and what is wrong."""

    def __init__(self, path, problem: str, allowed: str | None = None, key: str = "table"):
        self.key, self.path = key, str(path)
        super().__init__(f"table {path}: {problem}" + (f" (allowed: {allowed})" if allowed else ""))


def _read_text(path) -> tuple[str, str]:
    """The whole text of ``path`` (``-``: standard input), read once, and its display name."""
    import sys

    if str(path) == "-":
        data = sys.stdin.buffer.read() if sys.stdin is not None else b""
        name = "<stdin>"
    else:
        p, name = Path(path), str(path)
        if not p.exists():
            raise TableError(path, "no such file")
        if p.is_dir():
            raise TableError(path, "a directory, not a CSV file")
        try:
            with open(p, "rb") as fh:  # once: a pipe (/dev/stdin) cannot be read twice
                data = fh.read()
        except OSError as err:
            raise TableError(path, f"not readable ({err.strerror})") from None
    try:
        return data.decode("utf-8"), name
    except UnicodeDecodeError as err:
        raise TableError(name, f"not a text table (byte {err.start} is not UTF-8)") from None


def _records(text: str, name: str, sep: str) -> tuple[list, list]:
    """Header and the line number of each data record; refuses a cut-off last line and rows
    whose field count differs from the header's (a truncated or merged row)."""
    import csv
    import io as _io

    if not text.strip():
        raise TableError(name, "empty file (no header, no rows)")
    if not text.endswith("\n"):
        last = text.count("\n") + 1
        raise TableError(name, f"line {last} ends without a newline: the file was cut off (a truncated write?)",
                         allowed="tables as the producers write them, every line ended")
    reader = csv.reader(_io.StringIO(text), delimiter=sep)
    try:
        header = next(reader)
        lines = []
        for record in reader:
            if not record:  # a blank line (pandas skips it too)
                continue
            if len(record) != len(header):
                raise TableError(name, f"line {reader.line_num} has {len(record)} fields, the header {len(header)} "
                                 "(a truncated or damaged row)")
            lines.append(reader.line_num)
    except csv.Error as err:
        raise TableError(name, f"not a readable CSV table (line {reader.line_num}: {err})") from None
    repeated = sorted({c for c in header if header.count(c) > 1})
    if repeated:
        raise TableError(name, f"the header repeats column{'s' if len(repeated) > 1 else ''} {', '.join(repeated)}")
    return header, lines


def _check_column(frame, col: str, kind: str, name: str, lines: list):
    """The column ``col`` converted to its declared type; raises TableError naming the first
    bad cell's line."""
    import numpy as np
    import pandas as pd

    base, nullable = kind.rstrip("?"), kind.endswith("?")
    values = frame[col]
    empty = values.isna()

    def bad(mask, what):
        row = int(np.flatnonzero(mask.to_numpy())[0])
        value = frame[col].iloc[row]
        cell = "an empty cell" if empty.iloc[row] else repr(value) if isinstance(value, str) else str(value)
        raise TableError(name, f"line {lines[row]}: column {col} holds {cell}, {what}",
                         allowed=_TYPE_WORDS[base] + (" or an empty cell" if nullable else ""))

    if not nullable and empty.any():
        bad(empty, "where the producer always writes a value (a truncated or damaged row?)")
    if base == "str":
        return values
    if base == "bool":
        text = values.astype(str)
        ok = empty | text.isin(["True", "False"])
        if not ok.all():
            bad(~ok, "not True or False")
        return values
    numbers = values if pd.api.types.is_numeric_dtype(values) else pd.to_numeric(values, errors="coerce")
    if (numbers.isna() & ~empty).any():
        bad(numbers.isna() & ~empty, "not a number")
    if (~np.isfinite(numbers) & ~empty).any():
        bad(~np.isfinite(numbers) & ~empty, "not a finite number")
    if base == "int":
        frac = (numbers != np.round(numbers)) & ~empty
        if frac.any():
            bad(frac, "not an integer")
    return numbers


def _check_key(frame, schema: Schema, name: str, where: list) -> None:
    """No two rows with the same key (a row written twice, two runs joined); ``where[i]``
    says where row i comes from (``line 7``, or ``a.csv line 7`` in a join)."""
    key = [c for c in schema.key if c in frame.columns]
    if not key:
        return
    twice = frame.duplicated(subset=key, keep=False).to_numpy()
    if twice.any():
        rows = twice.nonzero()[0]
        first = frame.iloc[rows[0]]
        same = next(r for r in rows[1:] if frame.iloc[r][key].equals(first[key]))
        values = ", ".join(f"{c}={first[c]}" for c in key if first[c] == first[c])  # NaN: not part of it
        raise TableError(name, f"{where[rows[0]]} and {where[same]} have the same key ({values}): "
                         "a row repeated or two tables joined", allowed="one row per key")


def concat_tables(frames, kind: str, name: str):
    """Join tables of ``kind`` read by :func:`read_table` (in order) and check that no key
    appears twice across them; the error names both files and lines and ``name`` (the join)."""
    import pandas as pd

    where = [f"{f.attrs['source']} line {n}" for f in frames for n in f.attrs["lines"]]
    joined = pd.concat(frames, ignore_index=True)
    _check_key(joined, SCHEMAS[kind], name, where)
    return joined


class SourceLines(tuple):
    """The file line of each row of a table (``frame.attrs["lines"]``). Immutable, so a copy is
    the object itself: pandas deep-copies ``attrs`` on every derived frame, and a plain list of
    50,000 line numbers made the full ledger 35× slower."""

    def __deepcopy__(self, memo):
        return self

    def __copy__(self):
        return self


def read_table(path, kind: str, allow_empty: bool = False):
    """Read a table of ``kind`` (:data:`SCHEMAS`) and check it before use.

    Parameters
    ----------
    path : path-like or ``"-"``
        The file (read once, so ``/dev/stdin`` and a pipe work) or ``-`` for standard input.
    kind : str
        A key of :data:`SCHEMAS`.
    allow_empty : bool
        Accept a table with a header and no rows.

    Raises
    ------
    TableError
        One line naming the file and, where it applies, the line: a missing, unreadable or empty
        file; a last line without a newline (a cut-off write); a row whose field count is not the
        header's; missing columns (named); a declared column holding a value of the wrong type,
        an empty cell where the producer always writes one, or a non-finite number; two rows with
        the same key.
    """
    import io as _io

    import pandas as pd

    schema = SCHEMAS[kind]
    text, name = _read_text(path)
    header, lines = _records(text, name, schema.sep)
    missing = [c for c in schema.columns if c not in header]
    if missing:
        label = schema.label or f"a {kind} table"
        raise TableError(name, f"missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)} "
                         f"(has {', '.join(header[:12])}{', …' if len(header) > 12 else ''})",
                         allowed=f"{label} with the columns {', '.join(schema.columns)}")
    try:
        frame = pd.read_csv(_io.StringIO(text), sep=schema.sep, index_col=False)
    except (pd.errors.ParserError, ValueError) as err:
        reason = " ".join(str(err).split())[:120]
        raise TableError(name, f"not a readable CSV table ({type(err).__name__}: {reason})") from None
    if len(frame) != len(lines):  # the csv module and pandas disagree: never guess which is right
        raise TableError(name, f"{len(lines)} rows by the csv module, {len(frame)} by pandas (a damaged quote?)")
    if len(frame) == 0 and not allow_empty:
        raise TableError(name, "no data rows (only a header)")
    for col, col_kind in schema.types(frame.columns).items():
        frame[col] = _check_column(frame, col, col_kind, name, lines)
    _check_key(frame, schema, name, [f"line {n}" for n in lines])
    frame.attrs.update(source=name, lines=SourceLines(lines))  # where each row comes from (concat_tables)
    return frame


def read_table_text(path, kind: str):
    """:func:`read_table`'s checks, then every cell as the text written (no number parsed, no
    empty cell read as NaN): for byte-for-byte comparisons of tables (``verify-machines``)."""
    import io as _io

    import pandas as pd

    read_table(path, kind)
    text, _ = _read_text(path)
    return pd.read_csv(_io.StringIO(text), sep=SCHEMAS[kind].sep, index_col=False, dtype=str, keep_default_na=False)


def read_integer_list(path) -> "np.ndarray":
    """Whitespace- or comma-separated integers from a text file (a list of dof indices), or an
    ``.npy`` array; :class:`TableError` naming the file and line of the first token that is
    not an integer."""
    import numpy as np

    p = Path(path)
    if p.suffix == ".npy":
        try:
            return np.asarray(np.load(p, allow_pickle=False)).ravel()
        except (OSError, ValueError) as err:
            raise TableError(path, f"not a numpy array file ({type(err).__name__})") from None
    try:
        lines = p.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as err:
        raise TableError(path, f"not a readable text file ({type(err).__name__})") from None
    out = []
    for number, line in enumerate(lines, start=1):
        for token in line.split("#", 1)[0].replace(",", " ").split():
            try:
                out.append(int(token))
            except ValueError:
                raise TableError(path, f"line {number}: {token!r} is not an integer") from None
    return np.asarray(out, dtype=int)
