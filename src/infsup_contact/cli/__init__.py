"""Command line: one computation, CSV on stdout.

    infsup-contact beta --case all --k 2 --family structured --N1 16 --N2 16
    infsup-contact beta --model elastic --case T3 --k 2 --N1 16 --N2 16 --nu 0.3 --E1 1 --E2 1
    infsup-contact contact --scene manufactured --case T3 --k 2 --N1 16 --N2 16
    infsup-contact contact --model elastic --scene patch --case all --k 2 --N1 5 --N2 4
    infsup-contact contact --model membranes3d --scene face-patch --case all --k 2 --N1 4 --N2 5 --element hex
    infsup-contact beta --model elastic3d --case all --k 2 --N1 4 --N2 5 --element tet --nu 0.3
    infsup-contact contact --model elastic3d --scene elastic-face-patch --case all --k 2 --N1 4 --N2 5 --E2 3
    infsup-contact contact --model elastic --scene hertz --case T4 --k 2 --N1 32 --N2 32 --R 1 --d 0.05
    infsup-contact rates contact.csv
    infsup-contact bench --what beta --N 32 64 --k 2
    infsup-contact verdict --case T3 --k 2 --expect stable
    infsup-contact verdict --system levels.yaml --expect stable
    infsup-contact verdict --system levels.yaml --format json --output verdict.json
    infsup-contact verdict-hook a/levels.yaml b.levels.yaml
    infsup-contact export --case T3 --k 2 --N 8 16 32 --format mtx --out dir/
    infsup-contact provenance

Bad input gets one line on stderr naming the flag and exit code 2; no traceback, and no
computation: every subcommand validates the whole request first — values, the files it reads
and its estimated memory against the available memory (``resources.py``) — and ``--dry-run``
stops right there (exit 0, the estimate on stdout). ``verdict --expect`` exits with 1 when the
verdict is not the expected one. A closed or full stdout (``>&-``, ``> /dev/full``) is exit 74
with one line, Ctrl-C exit 130 with one line. Any other exception is a bug or a broken
installation: exit 70 with one line (``cli/program.py``; ``INFSUP_TRACEBACK=1`` adds the traceback),
never 1. ``infsup-contact --version`` prints the installed version.

One request builder for the command line and the Python API: argparse parses ``argv``
(:func:`parse`), and the flags typed, with their parsed values, go to the builder
(:func:`~.request.build`) the API's keywords go to (:func:`request_of`); :func:`check` then
validates the request. The flags are declared once, on the subcommands' parsers, which keep
their declarations for the builder (:func:`options`).
"""
from __future__ import annotations

import argparse
import functools
import os
import sys

from ..errors import InputError
from ..io import TableError
from . import beta, bench, contact, export, rates, reporting, verdict, verdict_hook
from .common import EXIT_INTERRUPTED, EXIT_OUTPUT, OutputError, check_stdout, refuse_unused, write_text
from .request import Declared, build
from .program import package_version, report_internal_error
from .verdict import VERDICT_DEFAULTS

__all__ = ["main", "build_parser", "validate", "flag_names", "options", "request_of", "VERDICT_DEFAULTS"]


_THREADS_ASKED: list = []
"""Whether the environment fixed the BLAS threads when the command started (set by :func:`_threads_default`)."""


def _threads_default() -> None:
    # one BLAS thread until the request is validated (set before numpy loads BLAS); a count the
    # environment fixes (Snakemake's jobs, side by side) is kept, else the request takes the idle
    # cores once it runs (_fit_blas_threads)
    # the variables of la.threaded.THREAD_VARIABLES, spelled here: importing la loads numpy
    _THREADS_ASKED[:] = [any(os.environ.get(var) for var in ("MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                                            "OMP_NUM_THREADS"))]
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        os.environ.setdefault(var, "1")


def _fit_blas_threads() -> None:
    """No thread count in the environment: MKL/PARDISO, the threaded products and the concurrent
    tasks take the cores idle now (:func:`..la.threaded.decide_threads`). More than one OpenBLAS
    thread asked for: as many as cores are idle now (:mod:`..la.openblas`: on a busy core a threaded
    OpenBLAS took 7-13× the one-thread time), said in one line."""
    if _THREADS_ASKED == [False]:
        from ..la.openblas import idle_cores
        from ..la.threaded import decide_threads, use_threads

        cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
        fit = cpus > 1 and os.environ.get("INFSUP_BLAS_FIT", "1") != "0"
        use_threads(decide_threads(None, cpus, idle_cores() if fit else None))
        return
    # (a fixed count: OpenBLAS too, fitted to the idle cores)
    try:
        asked = int(os.environ.get("OPENBLAS_NUM_THREADS", "1"))
    except ValueError:
        return
    if asked <= 1:
        return
    from ..la.openblas import fit_to_idle_cores

    used, idle = fit_to_idle_cores(asked)
    if used < asked:
        _say(f"infsup-contact: {idle:.1f} of {os.cpu_count()} cores idle: OpenBLAS runs {used} thread(s), not "
             f"{asked} (a threaded OpenBLAS waits on busy cores; INFSUP_BLAS_FIT=0 keeps {asked})")


def _reuse_freed_memory(estimate) -> None:
    """Where memory is plentiful (the estimated peak at most half the available memory), keep freed
    memory for reuse: no page faults on each new large block (k = 2, N = 32: 17 % of the CPU in the
    kernel, 3 % with it), for a higher peak (+6 % at N = 24, +18 % at N = 32); where it is not, keep
    it within a stage only (the sides, one multiplier space), given back at the stage's end (k = 2,
    N = 36: 77.9 → 20.1 s sys for a peak 10 % above glibc's; :func:`..memory.reuse_freed_memory`)."""
    from ..resources import available_bytes

    avail = available_bytes()
    if estimate is not None and avail is not None:
        from ..memory import reuse_freed_memory

        reuse_freed_memory(bounded=2 * estimate.bytes > avail)


class _Version(argparse.Action):
    """``--version``: looked up only when asked (``build_parser`` runs once per manifest of a hook)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest, nargs=0, default=default, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        write_text(f"{parser.prog} {package_version()}\n")  # stdout, as argparse's own version action
        parser.exit(0)


class _Parser(argparse.ArgumentParser):
    """The program's parser: one-line errors, and each subcommand's declarations kept where
    the request builder reads them (:class:`~.request.Declared`: its options, defaults,
    exclusive groups), so that the Python API builds a request without parsing a command line."""

    def __init__(self, *args, **kwargs):
        self.declared = Declared()  # before argparse's own --help is added
        self.commands: dict = {}
        super().__init__(*args, **kwargs)

    def error(self, message):  # one line, exit 2 — argparse's own convention
        self.exit(2, f"infsup-contact: error: {message}\n")

    def add_argument(self, *args, **kwargs):
        action = super().add_argument(*args, **kwargs)
        self.declared.options.append(action)
        return action

    def add_mutually_exclusive_group(self, **kwargs):
        return _Exclusive(self, super().add_mutually_exclusive_group(**kwargs), kwargs.get("required", False))

    def set_defaults(self, **kwargs):
        super().set_defaults(**kwargs)
        self.declared.defaults.update(kwargs)

    def add_subparsers(self, **kwargs):
        sub = super().add_subparsers(**kwargs)
        self.commands = sub.choices  # name → subcommand parser, filled as they are added
        return sub


class _Exclusive:
    """A mutually exclusive group of :class:`_Parser` whose options are declared to the builder too."""

    def __init__(self, parser: _Parser, group, required: bool):
        self._parser, self._group, self._dests = parser, group, []
        parser.declared.exclusive.append((self._dests, required))

    def add_argument(self, *args, **kwargs):
        action = self._group.add_argument(*args, **kwargs)
        self._parser.declared.options.append(action)
        self._dests.append(action.dest)
        return action

    def __getattr__(self, name):  # the rest of argparse's group, as it is
        return getattr(self._group, name)


def _add_provenance(sub) -> None:
    p = sub.add_parser("provenance", help="versions, git commit, platform, date (JSON)")
    p.set_defaults(run=lambda args: write_text(__import__("json").dumps(
        __import__("infsup_contact.provenance", fromlist=["x"]).provenance(), indent=2) + "\n"))


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="infsup-contact", description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", action=_Version, help="print the installed version and exit")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    beta.add(sub)
    contact.add(sub)
    rates.add(sub)
    bench.add(sub)
    verdict.add(sub)
    verdict_hook.add(sub)
    export.add(sub)
    _add_provenance(sub)
    for command in sub.choices.values():  # every subcommand: --quiet (no progress on stderr)
        reporting.add_quiet(command)
    todo = [parser]
    while todo:  # every action of every (sub)parser notes its dest when argparse calls it
        for action in todo.pop()._actions:
            action.__class__ = _noting(type(action))
            if isinstance(action, argparse._SubParsersAction):
                todo.extend(action.choices.values())
    return parser


@functools.cache
def _noting(kind: type) -> type:
    """``kind`` whose call (argparse's, for a flag typed on the command line only; abbreviated or
    ``--flag=value`` too) adds its dest to the namespace's ``given``: the flags typed, whatever
    their values, learned as argv is parsed, once (a subcommand's set is carried up with its
    namespace: merged, not replaced)."""

    class Noting(kind):
        def __call__(self, parser, namespace, values, option_string=None):
            before = set(getattr(namespace, "given", ()))
            super().__call__(parser, namespace, values, option_string)
            namespace.given = before | set(getattr(namespace, "given", ())) | {self.dest}

    Noting.__name__ = Noting.__qualname__ = kind.__name__
    return Noting


def flag_names(parser: argparse.ArgumentParser, command: str) -> dict:
    """dest → the flag as typed (``n_ref`` → ``--n-ref``) for the options of ``command``, and
    dest → dest for its positionals (``verdict-hook``'s ``manifests``)."""
    return {a.dest: max(a.option_strings, key=len) if a.option_strings else a.dest
            for a in parser.commands[command].declared.options if a.dest != argparse.SUPPRESS}


def options(command: str, parser: argparse.ArgumentParser | None = None) -> dict:
    """dest → the declared option (an argparse action: ``type``, ``default``, ``choices``,
    ``nargs``, ``option_strings``) of ``command``'s flags, as declared once for both the
    command line and the Python API."""
    parser = parser or build_parser()
    return {a.dest: a for a in parser.commands[command].declared.options if a.option_strings}


def request_of(command: str, values: dict, given=None, parser: argparse.ArgumentParser | None = None):
    """The validated request of ``command`` from typed values: ``values`` dest → value (the
    flags given; the others take their declared defaults) and ``given`` the dests the caller
    gave (default: those of ``values``), checked by the builder (:func:`~.request.build`:
    types, choices, nargs) then by :func:`check` (the flags the request does not use, the
    command's own checks, the outputs). No command line is parsed: the Python API's path.
    Returns the namespace the command runs; ``.estimate`` is its memory estimate (or None)."""
    parser = parser or build_parser()
    args = build(parser.commands[command].declared, command, values, set(values) if given is None else given)
    args.estimate = check(args)
    return args


def _message(err: Exception, parser, command: str) -> str:
    """The error's one line, with its key spelled as the flag the user typed."""
    from ..systems.readers import SystemFileError

    text = " ".join(str(err).split())
    key = getattr(err, "key", None)
    flag = flag_names(parser, command).get(key) if key else None
    if isinstance(err, SystemFileError) and flag:  # the flag, then the file it led to
        return f"{flag}: {text}"
    if flag and text.startswith(f"invalid {key}"):
        text = f"invalid {flag}" + text[len(f"invalid {key}"):]
    return text


def parse(parser, argv):
    """The request of a command line, unchecked: argparse parses ``argv`` once (an unknown flag, a
    bad type or choice: one line, exit 2), its actions noting the flags typed (:func:`_noting`:
    ``parsed.given``), then those flags' parsed values go through the same builder as the Python
    API's keywords (:func:`~.request.build`); :func:`check` validates it."""
    parsed = parser.parse_args(argv)
    given = parsed.given
    declared = parser.commands[parsed.command].declared
    dests = {a.dest for a in declared.options}
    return build(declared, parsed.command, {d: v for d, v in vars(parsed).items() if d in given and d in dests},
                 given)


def check(args):
    """Every subcommand's validation: first the one rule for flags the request does not use
    (:func:`~.common.refuse_unused`), then its own checks; the estimate (or None)."""
    from .verdict_formats import check_outputs

    refuse_unused(args)
    estimate = args.check(args) if hasattr(args, "check") else None
    check_outputs(args)  # after the request's checks (the inputs known), before any computation
    return estimate


verdict_hook.use_program(build_parser=build_parser, parse=parse, check=check, message=_message)


def validate(argv) -> tuple:
    """Parse and validate a command line without computing: ``(args, estimate)``; raises
    InputError/TableError (bad values) or SystemExit(2) (argparse: unknown flag, wrong type)."""
    args = parse(build_parser(), argv)
    return args, check(args)


def _say(line: str) -> None:
    """One line on stderr (nothing if stderr is closed too: the exit status still tells)."""
    if sys.stderr is not None:
        try:
            print(line, file=sys.stderr, flush=True)
        except OSError:
            pass


def main(argv=None) -> int:
    """Run one subcommand. Exit status: 0 done, 1 ``verdict --expect`` not met, 2 bad input,
    70 an unexpected exception (one line; :mod:`.program`), 74 the result could not be written
    (closed or full stdout), 130 interrupted (Ctrl-C)."""
    try:
        return _main(argv)
    except KeyboardInterrupt:  # Ctrl-C: one line, not a traceback from wherever it landed
        _say("infsup-contact: interrupted (Ctrl-C); no result written")
        return EXIT_INTERRUPTED
    except OutputError as err:  # --version's line, written while parsing (before _main's own handler)
        _say(f"infsup-contact: error: {err}")
        return EXIT_OUTPUT
    except BrokenPipeError:  # `--version | head -c1`: not an error of ours, as in _main
        return 0
    except Exception as err:  # a bug, not "the verdict differs" (1, Python's own exit code for it)
        return report_internal_error(err)


def _main(argv) -> int:
    _threads_default()
    parser = build_parser()
    args = parse(parser, argv)
    try:
        check_stdout()  # before any computation: a result nobody can read is not computed
        estimate = check(args)  # before any computation
        if getattr(args, "dry_run", False):
            from ..resources import available_bytes, human_bytes

            avail = available_bytes()
            write_text(f"dry run: valid request; estimated {estimate.describe()}"
                       + (f" (available memory {human_bytes(avail)})" if avail is not None else "") + "\n")
            return 0
        _fit_blas_threads()
        if argv is None:  # the process is this command line: in-process callers (tests, notebooks) keep glibc's malloc
            _reuse_freed_memory(estimate)
        code = reporting.run(args)  # args.run with its progress on stderr (not --quiet)
    except (InputError, TableError) as err:
        _say(f"infsup-contact: error: {_message(err, parser, args.command)}")
        return 2
    except OutputError as err:
        _say(f"infsup-contact: error: {err}")
        return EXIT_OUTPUT
    except BrokenPipeError:  # `| head` closed the pipe: not an error of ours
        return 0
    return code or 0
