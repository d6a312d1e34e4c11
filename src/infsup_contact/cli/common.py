"""What the subcommands share: the multiplier space of a request (--case | --space), the
model and its material flags, the norms, --dry-run and the memory check."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable

from ..errors import InputError


SPACE_HELP = ("a user-defined multiplier space: a file or module and a function returning a "
              "SpaceSpec (see examples/macro_p0.py); instead of --case")


def space_value(value):
    """The ``type`` of ``--space``: the command line's text as it is (``FILE.py:FUNC``, loaded and
    checked with the request: :func:`~infsup_contact.discretization.spaces.user_spaces.load_user_space`);
    from the Python API also a SpaceSpec or a function of no arguments returning one, the object
    itself (``takes_objects``: the request builder hands it over unconverted), checked there alike."""
    if isinstance(value, str) or callable(value):
        return value
    from ..discretization.spaces.spec import SpaceSpec  # here: it loads numpy (a string never gets here)
    from ..discretization.spaces.user_spaces import SPACE_ALLOWED

    if isinstance(value, SpaceSpec):
        return value
    raise InputError("space", SPACE_ALLOWED, got=value)


space_value.takes_objects = True


def space_file(args):
    """The file or module a request's ``--space`` names (``FILE.py:FUNC`` → FILE.py), or None: no
    space, or an object given by the Python API (no file to protect from an output)."""
    from pathlib import Path

    space = getattr(args, "space", None)
    return Path(space.rsplit(":", 1)[0]) if isinstance(space, str) else None


def _material_params() -> dict:
    """Flag name → [(model name, MaterialParam)] over every registered model."""
    from ..models import MODELS

    out = {}
    for m in MODELS.values():
        for prm in m.params:
            out.setdefault(prm.name, []).append((m.name, prm))
    return out


def add_model(p, materials: bool = True) -> None:
    """--model, every registered model's material flags (the model contract's ``params``; not
    with ``materials=False``) and mesh flags (``mesh_options``)."""
    from ..models import DEFAULT_MODEL, MODELS
    from ..models.contract import OptionalChoice

    p.add_argument("--model", default=DEFAULT_MODEL.name, choices=list(MODELS),
                   help="; ".join(f"{m.name}: {m.description}" + (" (default)" if m is DEFAULT_MODEL else "")
                                  for m in MODELS.values()))
    for name, owners in (_material_params() if materials else {}).items():
        p.add_argument(f"--{name}", type=float, default=None,
                       help="; ".join(f"{model}: {prm.help}, {prm.allowed} (default {prm.default:g})"
                                      for model, prm in owners))
    for name, owners in _mesh_options().items():
        numbers = [values for _, values in owners if isinstance(values, OptionalChoice) and values.above is not None]
        allowed = None if numbers else sorted({v for _, values in owners for v in values})
        p.add_argument(f"--{name}", default=None, choices=allowed, type=numbers[0].parse if numbers else str,
                       help="; ".join(f"{model}: {_option_help(values)}"
                                      for model, values in owners) + " (other models: not allowed)")


def _option_help(values) -> str:
    """A mesh flag's allowed values and default for ``--help``."""
    from ..models.contract import OptionalChoice

    if isinstance(values, OptionalChoice):
        return f"{values} (default: unset)"
    return f"one of {', '.join(values)} (default {values[0]})"


def _mesh_options() -> dict:
    """Mesh flag name → [(model name, allowed values)] over every registered model
    (the model contract's ``mesh_options``, e.g. ``--element`` of the 3D model)."""
    from ..models import MODELS

    out = {}
    for m in MODELS.values():
        for name, values in m.mesh_options:
            out.setdefault(name, []).append((m.name, values))
    return out


def add_dry_run(p) -> None:
    p.add_argument("--dry-run", action="store_true",
                   help="validate the request (values, files, estimated memory) and print the "
                   "memory and time estimate instead of computing")


def check_memory(est, key: str, value) -> None:
    """InputError naming ``key`` when the estimate exceeds MemAvailable (/proc/meminfo)."""
    from .. import resources

    avail = resources.available_bytes()
    if avail is not None and est.bytes > avail:
        raise InputError(key, f"a size whose estimated memory fits in the {resources.human_bytes(avail)} "
                         f"available (this request: {est.describe()})", got=value)


SYSTEM_KEEPS = ("system", "dry_run", "expect", "slope_tolerance", "beta_floor", "confidence", "help",
                "format", "output", "force")
"""Flags that mean something with ``--system``; every other one is refused there."""


# ---------------------------------------------------------------- flags a request does not use
# One rule for every subcommand: a flag the request does not use is refused, with one line
# naming the flag, who uses it and what this request is; never accepted and ignored. Each
# subcommand declares its conditional flags (:func:`declare_flag_uses`); `infsup-contact` applies
# the rule (:func:`refuse_unused`) to every request before its own checks.

@dataclass(frozen=True)
class FlagUse:
    """A flag only some requests use.

    Attributes
    ----------
    dest : str
        The option's dest (``n_ref`` for ``--n-ref``).
    used : callable
        ``used(args) -> bool``: whether this request uses it (``args`` as parsed, before the
        subcommand's checks: only argparse-validated values may be read).
    users : str
        Who uses it, for the refusal: "the manufactured scene", "--family perturbed".
    request : callable
        ``request(args) -> str``: what this request is, in its own flags ("--scene patch").
    """

    dest: str
    used: Callable
    users: str
    request: Callable


def declare_flag_uses(p, uses) -> None:
    """Declare a subcommand's conditional flags (those among its options) for
    :func:`refuse_unused`; its option defaults are kept too (a flag differing from its default
    counts as given where the command line is not at hand)."""
    dests = {a.dest for a in p.declared.options if a.option_strings}
    p.set_defaults(flag_uses=[u for u in uses if u.dest in dests],
                   option_defaults={a.dest: a.default for a in p.declared.options if a.option_strings})


def refuse_unused(args) -> None:
    """:class:`InputError` naming the first flag given that this request does not use (module
    comment above): ``args.given`` (the flags typed, noted as argv was parsed: ``cli._noting``), else the flags whose value differs
    from the default."""
    given = getattr(args, "given", None)
    if given is None:
        given = {d for d, v in getattr(args, "option_defaults", {}).items() if getattr(args, d, None) != v}
    for use in getattr(args, "flag_uses", ()):
        if use.dest in given and not use.used(args):
            raise InputError(use.dest, f"nothing here: it is used only by {use.users} (this request: {use.request(args)})",
                             got=getattr(args, use.dest))


def system_flag_uses(p) -> list:
    """With ``--system`` every option but :data:`SYSTEM_KEEPS` is unused: the manifest's matrices
    fix the spaces, meshes and norm (its 'norm' key says what G is)."""
    return [FlagUse(a.dest, lambda args: args.system is None, "requests without --system (the manifest's "
                    "matrices fix the spaces, meshes and norm)", lambda args: f"--system {args.system}")
            for a in p.declared.options if a.option_strings and a.dest not in SYSTEM_KEEPS]


def model_flag_uses() -> list:
    """The material and mesh flags of every registered model: each used by the models that
    declare it (``Model.params``, ``Model.mesh_options``)."""
    from ..models import MODELS

    def owned(name):
        return [m.name for m in MODELS.values()
                if name in m.param_names() or name in dict(m.mesh_options)]

    def request(args):
        m = MODELS[args.model]
        own = [*m.param_names(), *dict(m.mesh_options)]
        return f"--model {m.name}, whose flags are {', '.join('--' + n for n in own) or 'none'}"

    return [FlagUse(name, lambda args, name=name: args.model in owned(name), f"--model {', '.join(owned(name))}",
                    request) for name in [*_material_params(), *_mesh_options()]]


# ---------------------------------------------------------------- output
EXIT_OUTPUT = 74
"""Exit status when the output cannot be written (closed or full stdout; sysexits' EX_IOERR),
distinct from 1 (``verdict --expect`` not met) and 2 (bad input)."""
EXIT_INTERRUPTED = 130
"""Exit status after Ctrl-C (128 + SIGINT, the shell's convention)."""


class OutputError(Exception):
    """Standard output cannot take the result: closed (``>&-``), full (``> /dev/full``) or
    otherwise failing; the message is one line."""


def check_stdout() -> None:
    """Refuse a closed stdout before any computation: Python sets ``sys.stdout`` to None when
    file descriptor 1 is closed, and print() and ``to_csv(None)`` then write nothing silently."""
    import sys

    if sys.stdout is None:
        raise OutputError("standard output is closed (>&-): the result would be lost")


def _discard_stdout() -> None:
    """Point file descriptor 1 at /dev/null, so that the interpreter's final flush of what
    is still buffered does not fail a second time (a second message, a traceback)."""
    import os
    import sys

    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)
    except (OSError, ValueError, AttributeError):  # no file descriptor (pytest's capture)
        pass


def write_text(text: str) -> None:
    """Write ``text`` on stdout and flush it now, so that a failing write is seen here.

    Raises
    ------
    OutputError
        stdout closed or failing (a full disk: ENOSPC); one line naming the cause.
    BrokenPipeError
        the reader went away (``| head``): not an error of ours, the caller stops quietly.
    """
    import sys

    check_stdout()
    try:
        sys.stdout.write(text)
        sys.stdout.flush()
    except BrokenPipeError:
        _discard_stdout()
        raise
    except (OSError, ValueError) as err:  # ValueError: a closed file object
        _discard_stdout()
        reason = err.strerror if isinstance(err, OSError) and err.strerror else str(err)
        raise OutputError(f"cannot write the result to standard output ({reason})") from None


def is_stream(path) -> bool:
    """A device, pipe or open descriptor (``/dev/stdout``, ``/dev/fd/3``, a FIFO), written as it
    is: nothing to replace, no temporary file beside it. ``/dev/stdout`` of a shell redirected
    to a file resolves to that regular file, so the name decides first."""
    import stat
    from pathlib import Path

    text = str(Path(path).absolute())
    if text in ("/dev/stdout", "/dev/stderr") or text.startswith(("/dev/fd/", "/proc/self/fd/")):
        return True
    try:
        mode = os.stat(path).st_mode
        return stat.S_ISCHR(mode) or stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode)
    except OSError:
        return False



def write_result(text: str, output) -> None:
    """``text`` on stdout (``output`` None or ``-``), into a device or pipe as it is
    (``/dev/stdout``: a rename would replace the device node), else into the file ``output``
    atomically (:func:`infsup_contact.io.write_bytes_atomic`); UTF-8 whatever the locale."""
    from ..io import write_bytes_atomic

    if output in (None, "-"):
        write_text(text)
        return
    try:
        if is_stream(output):
            with open(output, "wb") as fh:
                fh.write(text.encode("utf-8"))
        else:
            write_bytes_atomic(output, text.encode("utf-8"))
    except OSError as err:
        raise OutputError(f"cannot write the result to {output} ({err.strerror or err})") from None


def write_csv(frame, float_format: str, output=None) -> None:
    """A result table as CSV on stdout (:func:`write_text`), or atomically into ``output``
    (``--output FILE``, checked before the computation: :func:`.verdict_formats.check_outputs`)."""
    write_result(frame.to_csv(index=False, float_format=float_format), output)


def material_columns(frame, args):
    """β_h rows under the model's material names: the scale columns c1, c2 renamed after the
    model's scale parameters (E1, E2 for the elastic bodies), its other parameters (ν) after
    them, and a ``model`` column first for every model but the paper's."""
    from ..models import DEFAULT_MODEL

    model = args.model_obj
    scales = {("c1", "c2")[p.side]: p.name for p in model.params if p.side is not None}
    frame = frame.rename(columns=scales)
    after = frame.columns.get_loc(scales.get("c2", "c2"))
    for prm in model.params:
        if prm.side is None:
            after += 1
            frame.insert(after, prm.name, getattr(args, prm.name))
    if model.name != DEFAULT_MODEL.name:
        frame.insert(0, "model", model.name)
    return frame
