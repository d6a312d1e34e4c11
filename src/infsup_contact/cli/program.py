"""The program about itself: its version (``infsup-contact --version``) and what an unexpected
exception becomes (exit :data:`EXIT_SOFTWARE`, one line).

Exit 1 means "the verdict differs from the expectation" (``verdict --expect``, the action, the
pre-commit hook): a bug must not look like that, and Python exits 1 on an uncaught exception.
So :func:`cli.main <infsup_contact.cli.main>` and ``verdict-hook`` turn any exception that is not
bad input (2), an output failure (74) or Ctrl-C (130) into exit 70 (sysexits' ``EX_SOFTWARE``,
"an internal software error") with one line on stderr; ``INFSUP_TRACEBACK=1`` prints the full
traceback too.
"""
from __future__ import annotations

import os
import sys
import traceback
from pathlib import Path

EXIT_SOFTWARE = 70
"""Exit status of an unexpected exception (a bug or a broken installation; sysexits' EX_SOFTWARE)."""
TRACEBACK_ENV = "INFSUP_TRACEBACK"
"""Set to 1: an unexpected exception prints its traceback before the one line."""
DISTRIBUTION = "infsup-contact"


def package_version() -> str:
    """The installed distribution's version (``importlib.metadata``); run from a source tree
    that is not installed, pyproject.toml's version marked so; else ``unknown``."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(DISTRIBUTION)
    except PackageNotFoundError:
        pass
    pyproject = Path(__file__).resolve().parents[3] / "pyproject.toml"
    try:
        import tomllib

        project = tomllib.loads(pyproject.read_text(encoding="utf-8")).get("project", {})
    except (OSError, ValueError):
        project = {}
    if project.get("name") == DISTRIBUTION and project.get("version"):
        return f"{project['version']} (source tree {pyproject.parent}, not installed)"
    return "unknown (not installed)"


def internal_error_line(err: BaseException, where: str = "") -> str:
    """The one line of an unexpected exception: its type and message (after ``where``, e.g. the
    manifest being checked), and what to do."""
    text = " ".join(str(err).split()) or "(no message)"
    hint = ("the installation is incomplete: reinstall infsup-contact with its dependencies "
            "(pip install infsup-contact, or make env)" if isinstance(err, ImportError) else
            "a bug: please report it to the infsup-contact issue tracker with this line and "
            "`infsup-contact --version`")
    where = f" ({where})" if where else ""
    return (f"infsup-contact: internal error{where}: {type(err).__name__}: {text} ({hint}; "
            f"{TRACEBACK_ENV}=1 prints the traceback)")


def report_internal_error(err: BaseException, where: str = "") -> int:
    """One line on stderr (the traceback first with ``INFSUP_TRACEBACK=1``); :data:`EXIT_SOFTWARE`."""
    if sys.stderr is not None:
        try:
            if os.environ.get(TRACEBACK_ENV, "") not in ("", "0"):
                traceback.print_exception(err, file=sys.stderr)
            print(internal_error_line(err, where), file=sys.stderr, flush=True)
        except OSError:
            pass
    return EXIT_SOFTWARE
