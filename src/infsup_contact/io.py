"""Atomic output (an interrupted run never leaves a half-written file behind) and checked input
(every table is read through :func:`read_table`, against its declared :data:`SCHEMAS`: a damaged
table is one line naming the file and the row)."""
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
    """:func:`write_atomic` for bytes (a reference solution's ``.npz``)."""
    _replace_atomic(path, data, "wb")


def write_csv_atomic(path, frame) -> None:
    """Write a pandas DataFrame as CSV atomically (deterministic float format)."""
    write_atomic(path, frame.to_csv(index=False, float_format="%.12g"))


# ---------------------------------------------------------------- reading tables
# Every table the package, the CLI and the workflow read is declared here: its columns (a
# consumer's required ones and the producer's optional ones), their types, and its key.
# Column types:
#   int    an integer (finite)            int?   an integer or an empty cell
#   float  a finite number                float? a number or an empty cell (NaN)
#   str    non-empty text                 str?   text or an empty cell
#   bool   True/False                     bool?  True/False or an empty cell
# A type without "?" is one the producer always writes: an empty cell there is damage (a
# truncated row, a number cut short), not a missing value. Extra columns are allowed (the
# producers add provenance and diagnostics); only the declared ones are checked.

_BETA = {"case": "str", "k": "int", "family": "str", "N1": "int", "N2": "int", "multiplier_mesh": "str",
         "c1": "float", "c2": "float", "norm": "str", "beta": "float", "kernel_dim": "int",
         "structural_kernel_dim": "int", "smallest_nonzero": "float?", "beta_v1_zero": "float?", "dim_M": "int",
         "dim_W": "int", "ndof": "int"}
_MEASURES = {"energy_error": "float", "l2_error": "float", "lambda_l2_error": "float", "lambda_hm12_error": "float"}
_ELASTIC_BETA = {"model": "str", "case": "str", "k": "int", "family": "str", "N1": "int", "N2": "int",
                 "multiplier_mesh": "str", "E1": "float", "E2": "float", "nu": "float", "norm": "str", "beta": "float",
                 "kernel_dim": "int", "structural_kernel_dim": "int", "smallest_nonzero": "float?",
                 "beta_v1_zero": "float?", "beta_membranes": "float?", "kernel_dim_membranes": "int",
                 "bound_factor": "float?"}
SERIES_COLUMNS = ("scene", "scene_kind", "case", "k", "family", "c1", "c2", "p", "q", "seed", "multiplier_mesh")
"""Columns of a contact table that define a convergence series (those present): rates are
fitted per series, and a series lists each mesh once."""


class Schema:
    """A table kind: ``columns`` (name → type, required), ``optional`` (checked when present),
    ``key`` (columns, those present, that identify a row: no two rows share them), ``label``
    (what the table is, for messages) and ``sep`` (the field separator)."""

    def __init__(self, columns: dict, optional: dict | None = None, key: tuple = (), label: str | None = None,
                 sep: str = ","):
        self.columns, self.optional, self.key, self.label, self.sep = columns, optional or {}, key, label, sep

    def types(self, present) -> dict:
        """Type of every declared column among ``present``."""
        every = {**self.optional, **self.columns}
        return {c: every[c] for c in present if c in every}


SCHEMAS = {
    "beta": Schema(_BETA, optional={"seed": "int?", "series": "str"},
                   key=("family", "case", "k", "N1", "N2", "seed", "multiplier_mesh", "c1", "c2", "norm", "series")),
    "contact": Schema({"scene": "str", "case": "str", "k": "int", "family": "str", "N1": "int", "N2": "int",
                       "c1": "float", "c2": "float", "ndof": "int", "dim_M": "int", "cone": "str", "iterations": "int",
                       **_MEASURES, "min_lambda_pointwise": "float?", "max_penetration": "float?", "nonunique": "bool",
                       "kernel_dim": "int"},
                      optional={"p": "float?", "q": "float?", "seed": "int?", "scene_kind": "str"},
                      key=("scene", "case", "k", "family", "N1", "N2", "c1", "c2", "p", "q", "seed")),
    # `infsup-contact rates`: any contact table; its series and meshes are checked by study/rates.py
    "contact_input": Schema({"scene": "str", "case": "str", "k": "int", "family": "str", "N1": "int", "N2": "int",
                             **_MEASURES},
                            optional={"c1": "float", "c2": "float", "p": "float?", "q": "float?", "seed": "int?",
                                      "scene_kind": "str", "multiplier_mesh": "str"},
                            label="a contact table (`infsup-contact contact` or results/tables/contact.csv)"),
    "rates": Schema({"scene": "str", "case": "str", "k": "int", "family": "str", "measure": "str", "slope": "float?",
                     "stderr": "float?", "points": "int", "h_min": "float", "expected": "float?"},
                    optional={"c1": "float", "c2": "float", "p": "float?", "q": "float?", "seed": "int?",
                              "scene_kind": "str", "multiplier_mesh": "str"},
                    key=(*SERIES_COLUMNS, "measure")),
    "producers": Schema({"producer": "str", "version": "str?", "space": "str", "offset": "int", "norm": "str",
                         "status": "str", "verdict": "str?", "kernel_dim": "int?", "beta_levels": "str?",
                         "kernel_levels": "str?", "h_levels": "str?", "slope": "float?", "slope_lo": "float?",
                         "slope_hi": "float?", "evidence": "str?", "seconds": "float?", "install": "str",
                         "system": "str?"}, key=("producer", "space", "offset", "norm"),
                        label="the producers table (rules/producers.smk)"),
    "claims": Schema({"claim_id": "str", "paper_ref": "str", "statement": "str", "evidence": "str", "verdict": "str",
                      "predicted": "str"}, key=("claim_id",), label="a claims ledger"),
    # no key: a sample 1e-9·h inside each end of an interval may print as its neighbour's x
    "gamma_profiles": Schema({"case": "str", "k": "int", "N": "int", "x": "float", "quantity": "str",
                              "value": "float?"}),
    "field_values": Schema({"case": "str", "k": "int", "N": "int", "side": "int", "x": "float", "y": "float",
                            "u": "float"}, key=("case", "k", "N", "side", "x", "y")),
    "speed_accuracy": Schema({"scene": "str", "case": "str", "k": "int", "family": "str", "N": "int",
                              "seconds": "float", "energy_error": "float", "lambda_hm12_error": "float",
                              "ndof": "int", "dim_M": "int", "pareto_energy": "bool", "pareto_lambda": "bool"},
                             key=("scene", "case", "k", "family", "N")),
    "bench": Schema({"what": "str", "route": "str", "k": "int", "N": "int", "seconds_median": "float",
                     "seconds_min": "float", "seconds_max": "float", "ratio_to_ours": "float?"},
                    key=("what", "route", "k", "N"), label="a bench table"),
    "mesh_quality": Schema({"family": "str", "N1": "int", "N2": "int", "side": "int", "h_max": "float",
                            "h_min": "float", "min_angle": "float"}, optional={"seed": "int?"},
                           key=("family", "N1", "N2", "side", "seed")),
    # elastic stage (study/elastic_beta.py, study/patch/segment.py, study/hertz.py)
    "elastic_beta": Schema(_ELASTIC_BETA, key=("model", "case", "k", "family", "N1", "N2", "multiplier_mesh", "E1",
                                               "E2", "nu", "norm")),
    "elastic_patch": Schema({"case": "str", "k": "int", "N1": "int", "N2": "int", "p": "float", "kernel_dim": "int",
                             "lambda_max_rel_error": "float", "lambda_end_rel_error": "float",
                             "lambda_middle_rel_error": "float", "u_max_rel_error": "float", "passes": "bool"},
                            optional={"scene": "str", "family": "str", "E1": "float", "E2": "float", "nu": "float",
                                      "delta": "float"},
                            key=("scene", "case", "k", "family", "N1", "N2", "E1", "E2", "nu", "delta")),
    "elastic_hertz": Schema({"study": "str", "case": "str", "k": "int", "N": "int", "d": "float", "P": "float",
                             "p_max": "float", "half_width": "float", "oscillation": "float",
                             "p_max_rel_error": "float?", "half_width_rel_error": "float?"},
                            optional={"R": "float", "nu": "float", "E1": "float", "E2": "float"},
                            key=("study", "case", "k", "N", "R", "d", "nu", "E1", "E2")),
    # the 3D contact face (rules/face.smk: study/beta_batches.py with models/membranes3d.py)
    "face_beta": Schema({**_BETA, "model": "str", "element": "str"},
                        key=("model", "element", "family", "case", "k", "N1", "N2", "multiplier_mesh", "c1", "c2",
                             "norm")),
    # the 3D elastic bodies on the face (rules/face_elastic.smk: study/face_elastic.py): β_h per ν
    "face_elastic_beta": Schema({**_BETA, "model": "str", "element": "str", "nu": "float"},
                                key=("model", "element", "family", "case", "k", "N1", "N2", "multiplier_mesh", "c1",
                                     "c2", "nu", "norm")),
    "face_elastic_patch": Schema({"element": "str", "case": "str", "k": "int", "N1": "int", "N2": "int",
                                  "E1": "float", "E2": "float", "nu": "float", "lambda_max_rel_error": "float",
                                  "u_max_rel_error": "float", "kernel_dim": "int", "passes": "bool"},
                                 key=("element", "case", "k", "N1", "N2", "E1", "E2", "nu")),
    # the face studies (rules/face_studies.smk: study/patch/face.py, face_alpha.py, edge_dropping.py);
    # condition numbers may be inf (singular to working precision): extra columns, not declared
    "face_patch": Schema({"element": "str", "case": "str", "k": "int", "N1": "int", "N2": "int",
                          "lambda_max_rel_error": "float", "u_max_rel_error": "float", "kernel_dim": "int",
                          "passes": "bool"}, key=("element", "case", "k", "N1", "N2")),
    "face_alpha": Schema({"element": "str", "alpha": "float", "N": "int", "norm": "str", "min_weight": "float",
                          "min_weight_gauss": "float", "accepted": "bool", "beta": "float?"},
                         key=("element", "alpha", "N", "norm")),
    "face_edge": Schema({"case": "str", "k": "int", "N": "int", "theta": "float", "beta_H": "float",
                         "beta_L2": "float", "beta_H_resolved": "bool", "beta_L2_resolved": "bool",
                         "beta_L2_kappa": "float?", "beta_L2_kappa_resolved": "bool", "fit_theta_max": "float"},
                        key=("case", "k", "N", "theta")),
    # results/benchmarks/dag.csv (bench/dag.py: per rule of a run), read by the docs' generator
    "dag": Schema({"rule": "str", "jobs": "int", "wall_s_sum": "float", "wall_s_max": "float",
                   "cpu_s_sum": "float?", "max_rss_mb": "float?"}, key=("rule",), label="a DAG timing table"),
    # Snakemake's `benchmark:` files (bench/dag.py), tab-separated
    "rule_benchmark": Schema({"s": "float"}, optional={"max_rss": "float?", "cpu_time": "float?"},
                             label="a Snakemake benchmark file", sep="\t"),
}
"""The declared tables (:func:`read_table`): one :class:`Schema` per kind."""

TABLE_COLUMNS = {kind: tuple(s.columns) for kind, s in SCHEMAS.items()}
"""Required columns per table kind (derived from :data:`SCHEMAS`)."""

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
