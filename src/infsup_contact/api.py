"""The Python API for notebooks: :func:`beta`, :func:`verdict` and :func:`certify`.

Each function is the command of the same name, called with keywords instead of flags: the
keywords are the flags' names (``N1``, ``multiplier_mesh``, ``h_route``, ...), the request goes
through the command line's own parser and checks (:func:`infsup_contact.cli.check`), and the
result is the table the command writes, as a :class:`pandas.DataFrame` with the same rows and
columns. Bad arguments raise :class:`~infsup_contact.errors.InputError` with the command's
one-line message, the offending key spelled as the keyword; nothing is computed before the
whole request is valid.

    >>> import infsup_contact as ic
    >>> ic.beta(case="T3", k=2, N1=8, N2=8, norm="H")          # doctest: +SKIP
    >>> ic.verdict(case="R5.4", k=1, N=[4, 8, 16])              # doctest: +SKIP
    >>> ic.certify("levels.yaml", expect="stable")              # doctest: +SKIP

A multiplier space defined in the notebook is ``space=`` a :class:`SpaceSpec` or a function
of no arguments returning one (as ``FILE.py:FUNC`` names one in a file), checked as a file's.
"""
from __future__ import annotations

import argparse
import sys
import types

# The CLI is the one place a request is parsed and checked; every import of the package's
# internals the API needs is here, so a move inside the package is fixed in these lines.
from .cli import build_parser, check, parse
from .cli.beta import beta_frame
from .cli.verdict import verdict_row
from .cli.verdict_formats import verdict_frame
from .errors import InputError

__all__ = ["beta", "verdict", "certify", "InputError"]

_NOT_KEYWORDS = {"help", "dry_run", "format", "output", "force", "command"}
"""Flags of the commands that are about the command line, not the result."""

_NOTEBOOK = "<notebook>"
"""The module name notebook spaces are registered under: ``space=f`` is ``<notebook>:f``."""
_NOTEBOOK_SPACES: dict = {}
"""id(space object) → (the object, its ``<notebook>:NAME`` reference); the object is kept so
that its id is not reused, and passing it again is the same registered space."""


def beta(case: str | None = None, k: int | None = None, N1: int | None = None, N2: int | None = None,
         **options):
    """β_h (eq. (4.5)) for one mesh pair: one row per case × norm, as ``infsup-contact beta``.

    Parameters
    ----------
    case : str, optional
        A registered space (``T3``, ``R5.4``, ``DUAL-Q9``, ...) or ``"all"`` (the default: every
        space defined for ``k``).
    k : int
        Displacement degree, 1..4 (not with ``system``).
    N1, N2 : int
        Segments on Γ of the Ω1 and Ω2 meshes (a 3D model: cells per direction on the face).
    **options
        Any other flag of ``infsup-contact beta`` by its name: ``norm`` (``"H"``, ``"L2"``,
        ``"all"``), ``family``, ``multiplier_mesh``, ``model``, ``element``, ``h_route``, ``c1``,
        ``c2``, ``seed``, ``alpha``, ``space`` (``"file.py:FUNC"``, a SpaceSpec or a function
        of no arguments returning one), ``system`` (a manifest).

    Returns
    -------
    pandas.DataFrame
        The command's CSV table: ``case``, ``k``, ``N1``, ``N2``, ``norm``, ``beta``,
        ``kernel_dim``, ... (``infsup-contact beta --help`` describes the columns).

    Raises
    ------
    InputError
        A bad keyword or value, with the command's one-line message.
    """
    options["space"] = _space_ref(options.get("space"))
    return beta_frame(_request("beta", case=case, k=k, N1=N1, N2=N2, **options))


def verdict(case: str | None = None, k: int | None = None, N=None, **options):
    """Is a multiplier space stable? β_h over a series of meshes judged STABLE, UNSTABLE or
    INCONCLUSIVE, as ``infsup-contact verdict``.

    Parameters
    ----------
    case : str, optional
        A registered space; exactly one of ``case``, ``space`` (``"file.py:FUNC"``, a
        SpaceSpec or a function of no arguments returning one) and ``system`` (a manifest, see
        :func:`certify`).
    k : int
        Displacement degree, 1..4 (with ``case`` or ``space``).
    N : sequence of int, optional
        Segments on Γ of the Ω2 meshes, at least 3 distinct (default 8, 16, 32, 64).
    **options
        Any other flag of ``infsup-contact verdict`` by its name: ``norm``, ``family``,
        ``N1_offset``, ``multiplier_mesh``, ``model``, ``element``, ``slope_tolerance``,
        ``beta_floor``, ``confidence``, ``expect`` (``"stable"`` or ``"unstable"``).

    Returns
    -------
    pandas.DataFrame
        One row: the command's CSV (``space``, ``k``, ..., ``verdict``, ``beta_min``,
        ``slope``, ...), lists space-separated. For a system, ``frame.attrs["levels"]`` holds
        the per-level rows. ``frame.attrs["expect"]`` is the expectation (``expect=``, else a
        manifest's ``expect:``, else None) and ``frame.attrs["met"]`` whether the verdict is
        it (the command's exit code 0 or 1; INCONCLUSIVE never meets one; None without one).

    Raises
    ------
    InputError
        A bad keyword or value, with the command's one-line message.
    """
    options["space"] = _space_ref(options.get("space"))
    given = [key for key, value in (("case", case), ("space", options.get("space")),
                                    ("system", options.get("system"))) if value is not None]
    if len(given) != 1:
        raise InputError("case", "exactly one of case=, space= and system=", got=given or None)
    args = _request("verdict", case=case, k=k, N=N, **options)
    row, levels = verdict_row(args)
    frame = verdict_frame(row)
    manifest = getattr(args, "manifest", None)
    expect = args.expect or getattr(manifest, "expect", None)
    frame.attrs["expect"] = None if expect is None else expect.upper()
    frame.attrs["met"] = None if expect is None else row["verdict"] == expect.upper()
    if levels is not None:
        import pandas as pd

        frame.attrs["levels"] = pd.DataFrame(levels)
    return frame


def certify(manifest, expect: str | None = None, **criterion):
    """The verdict on a saddle-point system exported by another code, as
    ``infsup-contact verdict --system MANIFEST``.

    Parameters
    ----------
    manifest : str or os.PathLike
        A ``levels.yaml`` manifest of mesh levels ``{h, A, B, G}`` (docs/foreign-systems.md).
    expect : {"stable", "unstable"}, optional
        The expected verdict (``--expect``); without it the manifest's ``expect:``, if any.
    **criterion
        ``slope_tolerance``, ``beta_floor``, ``confidence`` (defaults: the claims ledger's).

    Returns
    -------
    pandas.DataFrame
        One row (``system``, ``verdict``, ``beta_min``, ``slope``, ...);
        ``frame.attrs["levels"]`` is the per-level table (β_h, kernel, residual per level);
        ``frame.attrs["met"]``: the verdict is the expected one (None without an expectation).

    Raises
    ------
    InputError
        A bad argument, with the command's one-line message.
    """
    for key in criterion:
        if key not in _CRITERION:
            raise InputError(key, "one of " + ", ".join(sorted({"expect", *_CRITERION})) + " (certify's keywords: "
                             "the other flags of verdict do not apply to a system)")
    return verdict(system=str(manifest), expect=expect, **criterion)


_CRITERION = ("slope_tolerance", "beta_floor", "confidence")
"""The stability criterion's keywords (defaults: the claims ledger's)."""


_TYPE_NAMES = {int: "an integer", float: "a number"}


def _request(command: str, **keywords) -> argparse.Namespace:
    """The validated request of ``command`` for the keywords given (None: the flag's default)."""
    parser = build_parser()
    actions = _actions(parser, command)
    argv = [command]
    for key, value in keywords.items():
        if value is None:
            continue
        action = actions.get(key)
        if action is None or key in _NOT_KEYWORDS:
            raise InputError(key, "one of " + ", ".join(sorted(set(actions) - _NOT_KEYWORDS)))
        flag = max(action.option_strings, key=len)
        if action.nargs == 0:  # a switch: True sets it
            if not isinstance(value, bool):
                raise InputError(key, "True or False", got=value)
            argv += [flag] if value else []
            continue
        argv += [flag, *_tokens(key, value, action)]
    args = parse(parser, argv)
    check(args)
    return args


def _actions(parser: argparse.ArgumentParser, command: str) -> dict:
    """dest → argparse action of the options of ``command``."""
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[command]
    return {a.dest: a for a in sub._actions if a.option_strings}


def _tokens(key: str, value, action) -> list:
    """The command-line tokens of one keyword, checked as argparse would (so that a bad value
    raises InputError here instead of argparse's exit)."""
    if hasattr(value, "tolist"):  # numpy: a scalar (np.int64(2)) becomes its Python number, an array a list
        value = value.tolist()
    values = list(value) if isinstance(value, (list, tuple, range)) else [value]
    if action.nargs is None and len(values) != 1:
        raise InputError(key, "one value", got=value)
    if not values:
        raise InputError(key, "at least one value", got=value)
    for v in values:
        if action.type is not None:
            try:
                action.type(str(v))
            except (TypeError, ValueError):
                raise InputError(key, _TYPE_NAMES.get(action.type, action.type.__name__), got=v) from None
        if action.choices is not None and str(v) not in action.choices:
            raise InputError(key, "one of " + ", ".join(map(str, action.choices)), got=v)
    return [str(v) for v in values]


def _space_ref(space):
    """``space=`` as the command line's ``--space`` reference: a string as given; a
    :class:`SpaceSpec`, or a function of no arguments returning one, defined in the notebook,
    registered as ``<notebook>:NAME`` in a module of that name, so that the command loads and
    checks it exactly as a ``FILE.py:FUNC`` space (:mod:`~.discretization.spaces.user_spaces`)."""
    from .discretization.spaces.spec import SpaceSpec  # here: it loads numpy and scipy (0.3 s), not at import

    if space is None or isinstance(space, str):
        return space
    if not (isinstance(space, SpaceSpec) or callable(space)):
        raise InputError("space", "FILE.py:FUNC, a SpaceSpec, or a function of no arguments returning one",
                         got=space)
    known = _NOTEBOOK_SPACES.get(id(space))
    if known is not None and known[0] is space:
        return known[1]
    module = sys.modules.setdefault(_NOTEBOOK, types.ModuleType(_NOTEBOOK))
    stem = space.id if isinstance(space, SpaceSpec) else getattr(space, "__name__", "space")
    stem = "space" if str(stem).startswith("<") else stem  # a lambda
    stem = "".join(c if c.isalnum() else "_" for c in str(stem)).lstrip("0123456789") or "space"
    name, n = stem, 1
    while hasattr(module, name):
        n += 1
        name = f"{stem}_{n}"
    setattr(module, name, (lambda: space) if isinstance(space, SpaceSpec) else space)
    _NOTEBOOK_SPACES[id(space)] = (space, f"{_NOTEBOOK}:{name}")
    return _NOTEBOOK_SPACES[id(space)][1]
