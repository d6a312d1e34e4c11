"""The verdict inside GitHub Actions: an annotation and a Markdown step summary.

When ``GITHUB_ACTIONS=true`` (the runner sets it) ``verdict`` prints one workflow command:
``::error`` when the expectation is not met or the verdict is UNSTABLE with none set,
``::warning`` for INCONCLUSIVE with none set, ``::notice`` otherwise (STABLE, or the expected
UNSTABLE). It goes to **stderr**: the runner reads workflow commands from both streams (its
``ScriptHandler`` hands stdout and stderr each to an ``OutputManager`` that parses them), so
stdout stays exactly the chosen format even in Actions, and ``--output FILE`` gives a clean
file wherever stdout is mixed with other output. Values are escaped by the rules of GitHub's
toolkit (``@actions/core``, ``command.ts``): ``%``, CR and LF in the message; ``:`` and ``,``
too in the properties (``file``, ``title``).

When ``GITHUB_STEP_SUMMARY`` names a file, a Markdown section (the verdict, β_min, the slope
and its interval, the evidence, the per-level table of a system) is appended to it.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path


def escape_data(text: str) -> str:
    """A workflow command's message: ``%``, CR, LF percent-encoded (``%`` first)."""
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def escape_property(text: str) -> str:
    """A workflow command's property value: :func:`escape_data` and ``:``, ``,``."""
    return escape_data(text).replace(":", "%3A").replace(",", "%2C")


def level(result) -> str:
    """``error``, ``warning`` or ``notice`` for a :class:`~.verdict_formats.VerdictResult`."""
    verdict = result.row["verdict"]
    if result.exit_code == 1 or (result.expect is None and verdict == "UNSTABLE"):
        return "error"
    return "warning" if verdict == "INCONCLUSIVE" else "notice"


def _workspace_path(source: str) -> str:
    """``source`` relative to ``GITHUB_WORKSPACE`` when inside it (annotations name repository
    paths), else as given."""
    workspace = os.environ.get("GITHUB_WORKSPACE")
    path = Path(source).absolute()
    if workspace:
        try:
            return path.relative_to(Path(workspace).absolute()).as_posix()
        except ValueError:
            pass
    return source


def annotation(result) -> str:
    """The workflow command line of ``result`` (no trailing newline)."""
    row = result.row
    expected = f", expected {result.expect}" if result.expect else ""
    message = (f"{row['verdict']}{expected}: β_min {row['beta_min']:.4g}, slope {row['slope']:.3g} "
               f"[{row['slope_lo']:.3g}, {row['slope_hi']:.3g}]; {row['evidence']}")
    props = []
    if result.source and Path(result.source).is_file():
        props.append(f"file={escape_property(_workspace_path(result.source))}")
    props.append(f"title={escape_property(f'infsup-contact verdict: {result.name}')}")
    return f"::{level(result)} {','.join(props)}::{escape_data(message)}"


def _cell(value) -> str:
    """A Markdown table cell: one line, ``|`` escaped."""
    text = f"{value:.4g}" if isinstance(value, float) else str(value)
    return " ".join(text.split()).replace("|", "\\|")


def summary(result) -> str:
    """The Markdown section appended to ``$GITHUB_STEP_SUMMARY``."""
    row = result.row
    mark = {"error": "❌", "warning": "⚠️", "notice": "✅"}[level(result)]
    lines = [f"### {mark} infsup-contact verdict: {_cell(result.name)} — {row['verdict']}", "",
             "| verdict | expected | β_min | slope | slope interval | kernel_dim | exit code |",
             "|---|---|---|---|---|---|---|",
             f"| {row['verdict']} | {result.expect or '—'} | {_cell(row['beta_min'])} | {_cell(row['slope'])} | "
             f"[{_cell(row['slope_lo'])}, {_cell(row['slope_hi'])}] | {row['kernel_dim']} | {result.exit_code} |",
             "", f"Evidence: {_cell(row['evidence'])}", ""]
    if result.levels:
        cols = ("level", "h", "n", "m", "beta", "kernel_dim", "kernel_decision", "route")
        lines += ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
        lines += ["| " + " | ".join(_cell(lv[c]) for c in cols) + " |" for lv in result.levels]
        lines.append("")
    return "\n".join(lines) + "\n"


def report(result, environ=None) -> None:
    """The annotation on stderr when GitHub Actions runs us, the summary appended to
    ``$GITHUB_STEP_SUMMARY`` when it is set; a summary that cannot be written is one note (the
    verdict and its exit code stand)."""
    environ = os.environ if environ is None else environ
    if environ.get("GITHUB_ACTIONS") == "true" and sys.stderr is not None:
        print(annotation(result), file=sys.stderr, flush=True)
    target = environ.get("GITHUB_STEP_SUMMARY")
    if target:
        try:
            with open(target, "a", encoding="utf-8") as fh:
                fh.write(summary(result))
        except OSError as err:
            if sys.stderr is not None:
                print(f"infsup-contact: note: GITHUB_STEP_SUMMARY {target}: not written ({err.strerror or err})",
                      file=sys.stderr)


# ---------------------------------------------------------------- the composite action's helpers
OUTPUTS = ("verdict", "beta_min", "slope")
"""The action's outputs, read from the JSON result (``action.yml``)."""


def output_lines(json_path) -> str:
    """``key=value`` lines for ``$GITHUB_OUTPUT`` from a ``verdict --format json`` file (a
    null is an empty value; every value is one line: a word or a number)."""
    import json

    record = json.loads(Path(json_path).read_text(encoding="utf-8"))
    return "".join(f"{key}={'' if record[key] is None else record[key]}\n" for key in OUTPUTS)


def manifest_with_norm(path, norm: str) -> Path:
    """A copy of the manifest ``path`` with its ``norm`` key set to ``norm`` (the action's
    ``norm`` input), written next to it (its matrix paths are relative to it) as a hidden file
    ``.<file>.norm-<norm>.yaml``; ``name`` kept (it defaults to the file's stem). The
    original is checked first, so an error names the user's file."""
    import yaml

    from ..io import write_atomic
    from ..systems.manifest import NORMS, load_manifest
    from ..systems.readers import SystemFileError
    from ..yaml_limits import load

    if norm not in NORMS:
        raise SystemFileError(path, f"norm override {norm!r} is not one of {', '.join(NORMS)}", key="norm")
    manifest = load_manifest(path)
    data = load(Path(path).read_text())
    data.update(norm=norm, name=manifest.name)
    target = Path(path).parent / f".{Path(path).name}.norm-{norm}.yaml"
    write_atomic(target, yaml.safe_dump(data, sort_keys=False))
    return target


def main(argv=None) -> int:
    """``python -m infsup_contact.cli.github outputs RESULT.json`` | ``with-norm LEVELS.yaml NORM``:
    the action's two helpers; an error is one line on stderr, exit 2 (70: an unexpected exception)."""
    from ..errors import InputError

    argv = sys.argv[1:] if argv is None else argv
    try:
        if len(argv) == 2 and argv[0] == "outputs":
            sys.stdout.write(output_lines(argv[1]))
        elif len(argv) == 3 and argv[0] == "with-norm":
            print(manifest_with_norm(argv[1], argv[2]))
        else:
            raise InputError("arguments", "outputs RESULT.json | with-norm LEVELS.yaml NORM", got=" ".join(argv))
    except (InputError, OSError, ValueError, KeyError) as err:
        print(f"infsup-contact: error: {' '.join(str(err).split())}", file=sys.stderr)
        return 2
    except Exception as err:  # a bug: 70 as the command line's (never 1, "the verdict differs")
        from .program import report_internal_error

        return report_internal_error(err)
    return 0


if __name__ == "__main__":
    sys.exit(main())
