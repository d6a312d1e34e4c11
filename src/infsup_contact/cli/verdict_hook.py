"""``infsup-contact verdict-hook MANIFEST...``: the pre-commit hook's entry point
(``.pre-commit-hooks.yaml``, id ``infsup-contact-verdict``).

Each manifest given is checked as ``verdict --system`` checks it (the same parser, validation
and memory gate) and its verdict compared with the manifest's ``expect:`` key, ``stable`` when
it has none: a commit of a manifest whose verdict is UNSTABLE, INCONCLUSIVE or not the declared
one is stopped. One line per manifest on stdout; a manifest refused is one line on stderr and
the others are still checked. Exit code: 70 if checking one raised an unexpected exception
(one line for it, the others still checked: :mod:`.program`), else 2 if any was refused, else 1
if any verdict differs from its expectation, else 0 (the codes of ``verdict``).
"""
from __future__ import annotations

import sys

from ..errors import InputError
from ..io import TableError
from .common import declare_flag_uses, write_text
from .program import report_internal_error
from .verdict import VERDICT_DEFAULTS

_PROGRAM = {}
"""The command-line program the hook runs ``verdict`` through: ``build_parser``, ``parse``,
``check``, ``message`` (:func:`use_program`, called by the package that registers the hook: the
hook does not import its own package, which imports it)."""


def use_program(**functions) -> None:
    """Give the hook the program's ``build_parser``, ``parse``, ``check`` and ``message``."""
    _PROGRAM.update(functions)


DEFAULT_EXPECT = "stable"
"""A manifest without ``expect:`` is expected STABLE (a hook that passed UNSTABLE would gate nothing)."""


def add(sub) -> None:
    p = sub.add_parser(
        "verdict-hook", help="pre-commit hook: verdict --system on each manifest given, exit 1 if a verdict "
        "is not the manifest's expect: (default stable)",
        description=__doc__.split("\n\n", 1)[1].replace("\n", " ").replace("``", ""))
    p.add_argument("manifests", nargs="+", metavar="LEVELS.yaml", help="the manifests to check (pre-commit "
                   "passes the changed files matching the hook's files: pattern)")
    for key in ("slope_tolerance", "beta_floor", "confidence"):
        p.add_argument("--" + key.replace("_", "-"), dest=key, type=float, default=VERDICT_DEFAULTS[key],
                       help=f"as verdict's (default {VERDICT_DEFAULTS[key]:g})")
    p.add_argument("--dry-run", action="store_true",
                   help="check each manifest (files, shapes, memory) as verdict --system --dry-run does, "
                   "without computing a verdict")
    declare_flag_uses(p, [])  # every flag applies to every manifest: none conditional
    p.set_defaults(run=run_hook, check=check_hook)


def check_hook(args):
    """The criterion, once; with ``--dry-run`` also every manifest as ``verdict --system
    --dry-run`` checks it (the first refused one is the error), and the largest estimate."""
    from ..study.verdict import check_criterion

    check_criterion(args.slope_tolerance, args.beta_floor, args.confidence)
    if not args.dry_run:
        return None  # a real run checks each manifest itself and goes on after a refused one
    from ..systems.readers import SystemFileError

    build_parser, check, parse = _PROGRAM["build_parser"], _PROGRAM["check"], _PROGRAM["parse"]

    estimates = []
    for path in args.manifests:
        try:
            estimates.append(check(parse(build_parser(), ["verdict", f"--system={path}"])))
        except SystemFileError as err:
            err.key = "manifests"  # the positional that named the file, as verdict names --system
            raise
    return max(estimates, key=lambda e: e.bytes)


def check_one(path: str, criterion: dict) -> tuple[int, str]:
    """(exit code, line) of one manifest: 0 or 1 and its verdict line; 2 and the error line
    (70 from :func:`run_hook`, where an unexpected exception is caught)."""
    from ..systems.levels import system_verdict

    build_parser, check, parse = _PROGRAM["build_parser"], _PROGRAM["check"], _PROGRAM["parse"]

    argv = ["verdict", f"--system={path}", *(f"--{k.replace('_', '-')}={v!r}" for k, v in criterion.items())]
    parser = build_parser()
    try:
        args = parse(parser, argv)
        check(args)  # verdict's own validation: files, shapes, criterion, memory
        row, _ = system_verdict(args.manifest, tol=args.slope_tolerance, floor=args.beta_floor,
                                confidence=args.confidence, notes=sys.stderr)
    except (InputError, TableError) as err:
        return 2, f"infsup-contact: error: {_PROGRAM['message'](err, parser, 'verdict')}"
    expect = args.manifest.expect or DEFAULT_EXPECT
    ok = row["verdict"] == expect.upper()
    line = (f"{path}: {row['verdict']} ({'as expected' if ok else 'expected ' + expect.upper()}); "
            f"β_min {row['beta_min']:.4g}, slope {row['slope']:.3g} [{row['slope_lo']:.3g}, {row['slope_hi']:.3g}]")
    return (0, line) if ok else (1, f"{line}; {row['evidence']}")


def run_hook(args) -> int:
    criterion = {k: getattr(args, k) for k in ("slope_tolerance", "beta_floor", "confidence")}
    worst = 0
    from ..progress import steps

    for path in steps(args.manifests, "manifest"):
        try:
            code, line = check_one(path, criterion)
        except Exception as err:  # a bug is not "the verdict differs" (1): its own code, next manifest
            worst = max(worst, report_internal_error(err, where=path))
            continue
        if code == 2:
            print(line, file=sys.stderr, flush=True)
        else:
            write_text(line + "\n")
        worst = max(worst, code)
    return worst
