"""``--quiet`` and the progress of a request's computation on stderr (:mod:`infsup_contact.progress`):
every subcommand takes ``--quiet``; the reporter is installed around ``args.run`` only, after the
request's checks (a refusal stays one line) and never for ``--dry-run``."""
from __future__ import annotations

QUIET_HELP = ("no progress on stderr (by default a request running longer than a few seconds says its stage, "
              "space, mesh level and elapsed time there: a bar on a terminal, plain lines otherwise)")


def add_quiet(parser) -> None:
    """``--quiet`` on ``parser`` (every subcommand's, :func:`~infsup_contact.cli.build_parser`)."""
    parser.add_argument("--quiet", action="store_true", help=QUIET_HELP)


def _ns(values) -> str:
    return ",".join(str(v) for v in values)


def title(args) -> str:
    """The request in a few words, first in every progress line: the subcommand, model, space, k
    and mesh sizes it was given (``beta membranes3d k=2 N1=16 N2=16``)."""
    get = lambda key: getattr(args, key, None)  # noqa: E731
    if get("system") is not None:
        return f"{args.command} --system {args.system}"
    words = [args.command]
    if args.command == "contact":
        words.append(get("scene"))
    if args.command == "bench":
        words.append(get("what"))
    if args.command == "verdict-hook":
        words.append(f"{len(get('manifests') or ())} manifest(s)")
    words.append(get("model"))
    case = get("case")
    if get("space") is not None:
        words.append(args.space)
    elif case is not None:
        words.append(case if isinstance(case, str) else _ns(case))
    k = get("k")
    if k is not None:
        words.append(f"k={_ns(k) if isinstance(k, list) else k}")
    for key in ("N1", "N2"):
        if get(key) is not None and args.command in ("beta", "contact"):
            words.append(f"{key}={get(key)}")
    if get("N") is not None:
        words.append(f"N={_ns(args.N)}")
    if get("N1_offset"):
        words.append(f"N1=N{args.N1_offset:+d}")
    return " ".join(str(w) for w in words if w)


def run(args):
    """``args.run(args)`` with its progress reported on stderr unless ``--quiet``."""
    from ..progress import reporting

    with reporting(title(args), quiet=getattr(args, "quiet", False)):
        return args.run(args)
