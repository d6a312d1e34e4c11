"""The verdict as a gate other projects call: CSV (default), JSON or JUnit XML, on stdout or
atomically into ``--output``; the exit codes in one table.

One verdict is a :class:`VerdictResult`: the verdict row (the fields of
:func:`infsup_contact.criteria.stability.stability_verdict` and the form's own), the per-level rows of
a foreign system, the expectation and the exit code. The three renderers read only it:

* CSV is the row as ``verdict`` always printed it (lists space-separated, ``%.6g``);
* JSON is one object (``allow_nan=False``: NaN and ±inf are ``null``, numbers are numbers,
  lists are lists), with ``levels`` for ``--system``, ``criterion`` and ``exit_code``;
* JUnit XML is one ``<testsuite>`` with one ``<testcase>`` (name: the space or system,
  classname ``infsup-contact``); ``<failure>`` exactly when the exit code is 1 (``--expect``
  not met, INCONCLUSIVE included: it never matches), ``<skipped>`` for INCONCLUSIVE without an
  expectation (the question is open, and nothing failed), a pass otherwise. β_min, β_max, the
  slope and its interval, the kernel and the criterion are properties of the suite (the Ant
  JUnit schema allows ``<properties>`` there only).
"""
from __future__ import annotations

import argparse
import math
import os
import re
from dataclasses import dataclass, field

from .common import is_stream, space_file, write_result

FORMATS = ("csv", "json", "junit")
CLASSNAME = "infsup-contact"
SCHEMA = "infsup-contact-verdict/1"
"""The JSON document's ``schema``: raised when a field changes meaning or disappears."""

EXIT_CODES = (
    (0, "done: the verdict is computed and written and, where an expectation is set (--expect, or a "
        "manifest's expect:), it is the expected one; also --dry-run, and a reader that closes the pipe early"),
    (1, "the expectation is not met: the verdict differs (INCONCLUSIVE never matches); the result is written all "
        "the same"),
    (2, "bad input, nothing computed: a flag, the manifest, a matrix file or --output refused, or the estimated "
        "memory over the available memory; one line on stderr naming it"),
    (70, "an unexpected exception (a bug or an incomplete installation, never exit 1): one line naming its type and "
         "message and where to report it; INFSUP_TRACEBACK=1 adds the traceback"),
    (74, "the result cannot be written: stdout closed (>&-) or full (> /dev/full), or --output failing at the end "
         "(a full disk); one line"),
    (130, "interrupted (Ctrl-C); one line, no result written"),
)
"""``verdict``'s exit codes (the ``--help`` epilog and the table of docs/cli.md are this table)."""


@dataclass
class VerdictResult:
    """One verdict as the renderers read it.

    Attributes
    ----------
    form : str
        ``case``, ``space`` or ``system``: which of the three forms produced it.
    row : dict
        The verdict row (``verdict``, ``beta_min``, ``slope``, ``evidence``, ...).
    expect : str or None
        The expected verdict (``STABLE``/``UNSTABLE``) or None.
    criterion : dict
        ``slope_tolerance``, ``beta_floor``, ``confidence`` of the run.
    levels : list of dict or None
        The per-level rows of a foreign system (``--system``), else None.
    source : str or None
        The file the verdict is about (manifest or space file), for annotations.
    """

    form: str
    row: dict
    expect: str | None
    criterion: dict
    levels: list | None = None
    source: str | None = None
    exit_code: int = field(init=False)

    def __post_init__(self):
        self.exit_code = 0 if self.expect is None or self.row["verdict"] == self.expect else 1

    @property
    def name(self) -> str:
        return str(self.row["system"] if self.form == "system" else self.row["space"])


# ---------------------------------------------------------------- the command line
class _EpilogFormatter(argparse.HelpFormatter):
    """argparse's reflowing formatter, but the exit-code table keeps its lines."""

    def _fill_text(self, text, width, indent):
        if text.startswith("exit codes:"):
            return "\n".join(indent + line for line in text.splitlines())
        return super()._fill_text(text, width, indent)


def exit_code_table(width: int = 100) -> str:
    """:data:`EXIT_CODES` as plain text, one wrapped entry per code."""
    import textwrap

    lines = ["exit codes:"]
    for code, text in EXIT_CODES:
        lines += textwrap.wrap(text, width, initial_indent=f"  {code:>3}  ", subsequent_indent=" " * 7)
    return "\n".join(lines)


def output_path(text: str) -> str:
    """argparse ``type`` of ``--output``: refused before anything is computed when it names a
    directory or a place that cannot be created or written (:func:`check_writable_place`)."""
    from pathlib import Path

    if text == "-" or is_stream(text):  # stdout, as without --output; a device or pipe as it is
        return text
    if Path(text).is_block_device():  # a disk: never written over
        raise argparse.ArgumentTypeError(f"{text!r} is a block device (a disk): expected a file name to write")
    if not text or Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a directory or empty: expected a file name to write")
    problem = check_writable_place(Path(text).absolute().parent)
    if problem:
        raise argparse.ArgumentTypeError(f"{text!r}: {problem}")
    return text


def check_writable_place(folder) -> str | None:
    """Why a file cannot be written atomically into ``folder`` (created if missing), or None:
    its nearest existing ancestor is a file, not writable, or a filesystem where a temporary
    file cannot be created (``/proc``, ``/sys``: the rename of :mod:`infsup_contact.io` needs
    one). The probe is a temporary file created and removed at once; nothing else is written."""
    import tempfile
    from pathlib import Path

    parent = Path(folder)
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        return f"{parent} is a file, not a directory"
    if not os.access(parent, os.W_OK | os.X_OK):
        return f"the directory {parent} is not writable"
    try:
        fd, probe = tempfile.mkstemp(dir=parent, prefix=".infsup-contact-probe.")
    except OSError as err:
        return f"no file can be created in {parent} ({err.strerror or err})"
    os.close(fd)
    os.unlink(probe)
    return None


FORCE_HELP = "replace an existing FILE of --output (without it an existing file is refused, nothing computed)"


def add_output_args(p) -> None:
    """``--format``, ``--output`` and ``--force`` of ``verdict``, and the exit-code table as its epilog."""
    p.add_argument("--format", default="csv", choices=FORMATS,
                   help="csv: one row (default); json: one object, the per-level rows of --system included; "
                   "junit: JUnit XML, one testcase (a failure when --expect is not met)")
    p.add_argument("--output", metavar="FILE", type=output_path, default=None,
                   help="write the result to FILE (atomically: a temporary file renamed) instead of stdout (- : stdout); "
                   "an existing FILE only with --force")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    p.epilog = exit_code_table()
    p.formatter_class = _EpilogFormatter


def add_table_output(p) -> None:
    """``--output FILE`` and ``--force`` of a subcommand writing a table (CSV) on stdout."""
    p.add_argument("--output", metavar="FILE", type=output_path, default=None,
                   help="write the table to FILE (atomically: a temporary file renamed) instead of stdout "
                   "(- : stdout); an existing FILE only with --force")
    p.add_argument("--force", action="store_true", help=FORCE_HELP + "; with beta, also of --worst-mode")


def force_use():
    """The :class:`~.common.FlagUse` of ``--force``: used only with a file to write."""
    from .common import FlagUse

    return FlagUse("force", lambda a: _files(a) != [], "requests writing a file (--output FILE, beta's --worst-mode)",
                   lambda a: "no file written, the result on stdout")


def _files(args) -> list:
    return [(dest, getattr(args, dest)) for dest in ("output", "worst_mode")
            if getattr(args, dest, None) not in (None, "-")]


def check_outputs(args) -> None:
    """Before anything is computed: each file the request writes (``--output``, ``--worst-mode``)
    is not one of its inputs, and an existing file is replaced only with ``--force`` (a device or
    pipe, ``/dev/stdout``, is written as it is: nothing replaced; :func:`is_stream`)."""
    from ..errors import InputError

    for dest, target in _files(args):
        if dest == "output":
            check_not_an_input(target, args)
        if os.path.lexists(target) and not is_stream(target) and not getattr(args, "force", False):
            flag = "--" + dest.replace("_", "-")
            raise InputError(dest, f"a new file, or --force to replace it ({flag} never overwrites an existing "
                             "file without it)", got=f"{target} (exists)")


def emit(args, row: dict, levels=None, manifest_expect=None) -> int:
    """Write the verdict of ``args`` in ``args.format`` (to ``args.output`` or stdout), then
    the GitHub annotations and step summary where GitHub Actions asks for them; the exit code.

    ``--expect`` is the expectation; without it a manifest's ``expect:`` (``manifest_expect``)."""
    from .github import report

    expect = args.expect or manifest_expect
    form = "system" if args.system is not None else "space" if args.space is not None else "case"
    source = args.system if form == "system" else space_file(args) if form == "space" else None
    source = None if source is None else str(source)
    result = VerdictResult(form, row, None if expect is None else expect.upper(),
                           {k: getattr(args, k) for k in ("slope_tolerance", "beta_floor", "confidence")},
                           levels, source)
    if args.output not in (None, "-"):
        check_not_an_input(args.output, args)
    write_result(render(result, args.format), args.output)
    report(result)
    return result.exit_code


def check_not_an_input(output, args) -> None:
    """:class:`InputError` (key ``output``) when ``output`` is a file the verdict was computed
    from (the manifest, a level's matrix, the space file): writing it would destroy the input."""
    from pathlib import Path

    from ..errors import InputError

    inputs = [Path(args.table)] if getattr(args, "table", "-") != "-" else []
    if getattr(args, "system", None) is not None and hasattr(args, "manifest"):
        inputs = [Path(args.system)] + [p for lv in args.manifest.levels for p in (lv.A, lv.B, lv.G, lv.constrained)
                                        if isinstance(p, Path)]
    elif space_file(args) is not None:
        inputs = [space_file(args)]
    target = Path(output).resolve()
    if any(p.resolve() == target for p in inputs):
        raise InputError("output", "a file other than the inputs of the request (it would be overwritten)",
                         got=str(output))


def render(result: VerdictResult, fmt: str) -> str:
    """The result as text in ``fmt`` (:data:`FORMATS`)."""
    return {"csv": render_csv, "json": render_json, "junit": render_junit}[fmt](result)


# ---------------------------------------------------------------- the three formats
def render_csv(result: VerdictResult) -> str:
    """The verdict row as one CSV row under its header, lists space-separated."""
    return verdict_frame(result.row).to_csv(index=False, float_format="%.6g")


def verdict_frame(row: dict):
    """The verdict row as a one-row DataFrame, lists space-separated (the CSV's columns)."""
    import pandas as pd

    return pd.DataFrame([{k: " ".join(str(x) for x in v) if isinstance(v, (list, tuple)) else v
                          for k, v in row.items()}])


def plain(value):
    """``value`` as JSON takes it: numpy scalars as Python numbers, NaN and ±inf as None
    (JSON has no such numbers), tuples and arrays as lists."""
    import numpy as np

    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [plain(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def json_record(result: VerdictResult) -> dict:
    """The JSON object: the row's fields, the form, expectation, criterion, exit code and, for a
    system, the per-level rows (``h_list`` and ``routes`` as lists, ``h`` exact from the levels)."""
    record = dict(result.row)
    if result.levels is not None:
        record["h_list"] = [lv["h"] for lv in result.levels]
        record["routes"] = sorted({lv["route"] for lv in result.levels})
    record.update(schema=SCHEMA, form=result.form, expect=result.expect, criterion=result.criterion,
                  exit_code=result.exit_code)
    if result.levels is not None:
        record["levels"] = result.levels
    return plain(record)


def render_json(result: VerdictResult) -> str:
    import json

    return json.dumps(json_record(result), allow_nan=False, ensure_ascii=False, indent=2) + "\n"


PROPERTIES = ("verdict", "expect", "beta_min", "beta_max", "slope", "slope_lo", "slope_hi", "kernel_dim",
              "known_kernel", "norm", "k", "family", "multiplier_mesh", "N_list", "h_list", "stabilisation",
              "verdict_C", "beta_C_min", "slope_C")
"""Row fields written as ``<property>`` of the JUnit suite (those the row has)."""


_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]")
"""Characters XML 1.0 cannot hold at all, not even escaped (ElementTree writes them as they are)."""


def _text(value) -> str:
    """A property value or message: floats in full precision (``repr``), lists space-separated,
    characters XML cannot hold replaced by U+FFFD."""
    if isinstance(value, (list, tuple)):
        return " ".join(_text(v) for v in value)
    return _NOT_XML.sub("\ufffd", repr(float(value)) if isinstance(value, float) else str(value))


def render_junit(result: VerdictResult) -> str:
    """One ``<testsuite>`` with one ``<testcase>`` (module docstring: when it fails or is skipped)."""
    import socket
    import xml.etree.ElementTree as ET
    from datetime import datetime, timezone

    row = result.row
    failed = result.exit_code == 1
    skipped = not failed and row["verdict"] == "INCONCLUSIVE"
    seconds = f"{float(row.get('seconds', 0.0)):.3f}"
    suite = ET.Element("testsuite", name="infsup-contact verdict", tests="1", failures=str(int(failed)), errors="0",
                       skipped=str(int(skipped)), time=seconds, hostname=socket.gethostname(),
                       timestamp=datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%S"))
    props = ET.SubElement(suite, "properties")
    values = dict(row, expect=result.expect or "", **result.criterion)
    for key in [*PROPERTIES, *result.criterion]:
        if key in values:
            ET.SubElement(props, "property", name=key, value=_text(values[key]))
    case = ET.SubElement(suite, "testcase", name=_text(result.name), classname=CLASSNAME, time=seconds)
    evidence = _text(row["evidence"])
    if failed:
        fail = ET.SubElement(case, "failure", message=f"{row['verdict']}, expected {result.expect}: {evidence}",
                             type="VerdictMismatch")
        fail.text = _text(render_csv(result))
    elif skipped:
        ET.SubElement(case, "skipped", message=f"INCONCLUSIVE: {evidence}")
    ET.SubElement(case, "system-out").text = _text(render_csv(result) + _levels_text(result))
    ET.indent(suite)
    return ET.tostring(suite, encoding="unicode", xml_declaration=True) + "\n"


def _levels_text(result: VerdictResult) -> str:
    """The per-level rows of a system as CSV (nothing for --case/--space)."""
    import pandas as pd

    if not result.levels:
        return ""
    return "\n" + pd.DataFrame(result.levels).to_csv(index=False, float_format="%.6g")
