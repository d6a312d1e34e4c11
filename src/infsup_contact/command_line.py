"""The command line of a study module run as ``python -m infsup_contact.study.…``: a parser whose
errors are one line, and the run that turns :class:`~infsup_contact.errors.InputError` into that
line and exit status 2. Below the studies and the CLI, which both use it."""
from __future__ import annotations

import argparse

from .errors import InputError

class OneLineParser(argparse.ArgumentParser):
    """An argparse parser whose errors are one line, ``<prog>: error: <message>``, exit 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def error_line(err: Exception, flags: dict) -> str:
    """The one line of an InputError, its key spelled as the flag (``flags``: dest → flag)."""
    text = " ".join(str(err).split())
    key = getattr(err, "key", None)
    flag = flags.get(key) if key else None
    if flag and text.startswith(f"invalid {key}"):
        text = f"invalid {flag}" + text[len(f"invalid {key}"):]
    return text


def run_study(parser, argv, check, run) -> int:
    """A study module's ``python -m`` command: parse ``argv``, ``check(args)`` the whole request
    before any output, then ``run(args)``. Bad input (:class:`InputError`) is one line on stderr,
    ``<prog>: error: invalid --flag (got …): expected …``, and exit 2: never a traceback, never a
    table of its header only."""
    import sys

    args = parser.parse_args(argv)
    flags = {a.dest: max(a.option_strings, key=len) for a in parser._actions if a.option_strings}
    try:
        check(args)
        run(args)
    except InputError as err:
        print(f"{parser.prog}: error: {error_line(err, flags)}", file=sys.stderr)
        return 2
    return 0
