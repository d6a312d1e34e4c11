"""The Python API for notebooks: :func:`beta`, :func:`verdict` and :func:`certify`.

Each function is the command of the same name, called with keywords instead of flags: the
keywords are the flags' names (``N1``, ``multiplier_mesh``, ``h_route``, ...). The keywords go
straight to the request builder the command line's parsed flags go to
(:func:`infsup_contact.cli.request_of`: the flags' declared defaults, types, choices and nargs,
then the command's own checks); no command line is written or parsed. The result is the table
the command writes, as a :class:`pandas.DataFrame` with the same rows and columns. Bad
arguments raise :class:`~infsup_contact.errors.InputError` with the command's one-line
message, the offending key spelled as the keyword; nothing is computed before the whole
request is valid.

    >>> import infsup_contact as ic
    >>> ic.beta(case="T3", k=2, N1=8, N2=8, norm="H")          # doctest: +SKIP
    >>> ic.verdict(case="R5.4", k=1, N=[4, 8, 16])              # doctest: +SKIP
    >>> ic.certify("levels.yaml", expect="stable")              # doctest: +SKIP

A multiplier space defined in the notebook is ``space=`` a :class:`SpaceSpec` or a function
of no arguments returning one (as ``FILE.py:FUNC`` names one in a file): the object itself goes
into the request and is checked as a file's
(:func:`~infsup_contact.discretization.spaces.user_spaces.load_user_space`).
"""
from __future__ import annotations

# The CLI declares the flags and builds and checks a request; every import of the package's
# internals the API needs is here, so a move inside the package is fixed in these lines.
from .cli import build_parser, options, request_of
from .cli.beta import beta_frame
from .cli.verdict import verdict_row
from .cli.verdict_formats import verdict_frame
from .errors import InputError

__all__ = ["beta", "verdict", "certify", "InputError"]

_NOT_KEYWORDS = {"help", "dry_run", "format", "output", "force", "command"}
"""Flags of the commands that are about the command line, not the result."""

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


def _request(command: str, **keywords):
    """The validated request of ``command`` for the keywords given (None: the flag's default; a
    switch False: not given), built from the typed values (:func:`infsup_contact.cli.request_of`)."""
    parser = build_parser()
    allowed = set(options(command, parser)) - _NOT_KEYWORDS
    values = {}
    for key, value in keywords.items():
        if value is None:
            continue
        if key not in allowed:
            raise InputError(key, "one of " + ", ".join(sorted(allowed)))
        if value is not False or options(command, parser)[key].nargs != 0:  # a switch False: its default
            values[key] = value
    return request_of(command, values, parser=parser)
