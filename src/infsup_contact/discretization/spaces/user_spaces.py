"""Users' multiplier spaces: ``FILE.py:FUNC`` or ``module:FUNC`` (the command line), or the
:class:`SpaceSpec` or function itself (the Python API's ``space=``) → a checked registry entry.

A user space is a function of no arguments returning a
:class:`~infsup_contact.discretization.spaces.spec.SpaceSpec` whose ``build(k, breakpoints)``
returns a :class:`~infsup_contact.discretization.segment.multipliers.SegmentSpace` — usually from
:func:`~infsup_contact.discretization.segment.multipliers.make_space` (Lagrange, (5.3)/(5.5)) or
:func:`~infsup_contact.discretization.segment.multipliers.local_basis_space` (any local basis and
numbering). ``examples/macro_p0.py`` is one.

**The partition a build receives.** Spaces are built on Γ, the interface object
(:mod:`infsup_contact.discretization.gamma.interface`): the suite asks ``registry.case_space(case, k, G_h, gamma)``
and, for the paper's segment :class:`~infsup_contact.discretization.gamma.interface.Segment` — today
the only Γ — that passes G_h as it represents it, the sorted breakpoints 0 = x_0 < … < x_N = 1.
So a user's ``build(k, x)`` keeps receiving the breakpoints of G_h, a float array of shape
(N + 1,), and must return a space on exactly those breakpoints; this is the public contract and
does not change. A space for another Γ (a 2D face) would receive that interface's partition.

The user's code runs under one guard: importing the file, calling ``FUNC()``, ``dimension()``,
``degree()`` and ``build()``. Any exception it raises — SystemExit included, only
KeyboardInterrupt passes — becomes one :class:`~infsup_contact.errors.InputError` line naming
the file, the function and the exception. Before it is registered the space is built and
checked, for every degree it allows, on a non-uniform partition (:data:`CHECK_PARTITION`) and
on the uniform partition of every N the run will use (``intervals``); after registration
every build, on any partition, is still checked to live on the partition it was given and to
have the dimension it states (:func:`guarded_build`), so a space that ignores its partition
cannot compute on the wrong one.

A space's id appears in tables, file names, LaTeX and on the command line: it is a string
of letters, digits, ``-`` and ``.``, starting with a letter, at most 32 characters
(:data:`ID_PATTERN`; ``_`` is excluded: LaTeX reads it as a subscript).
"""
from __future__ import annotations

import dataclasses
import importlib
import importlib.util
import inspect
import re
import sys
from pathlib import Path

import numpy as np

from ...errors import InputError
from ..segment.multipliers import SegmentSpace
from .registry import SPACES, register
from .spec import K_RANGE, SpaceSpec

_LOADED: dict = {}
"""Reference key (:func:`_key`) → the registered SpaceSpec."""
_CHECKED: dict = {}
"""Per reference key, the interval counts N its space was fully checked on."""
_LABELS: dict = {}
"""Per reference key, the reference as messages name it."""
_OBJECTS: dict = {}
"""Per object key, the object given (kept, so that its id stays its own)."""
CHECK_PARTITION = np.array([0.0, 0.13, 0.3, 0.52, 0.71, 1.0])
"""The non-uniform partition (N = 5) every user space is checked on."""
ID_PATTERN = re.compile(r"[A-Za-z][A-Za-z0-9.-]{0,31}")
"""Allowed ids: safe in file names, LaTeX text, CSV cells and argv (no leading ``-``)."""
ID_ALLOWED = "a string of letters, digits, '-' and '.', starting with a letter, at most 32 characters"
MAX_GRAM_DIM = 1000
"""Largest space whose L² Gram matrix is checked for linear independence (dense eigvalsh)."""
SPEC_FIELDS = tuple(f.name for f in dataclasses.fields(SpaceSpec))


def _one_line(text) -> str:
    return " ".join(str(text).split())


def _describe(exc: BaseException) -> str:
    """``Type: message`` on one line; a SpaceSpec keyword error lists the keywords it takes."""
    text = f"{type(exc).__name__}: {_one_line(exc)}" if str(exc) else type(exc).__name__
    if isinstance(exc, TypeError) and "SpaceSpec" in str(exc) and "keyword" in str(exc):
        text += f" (SpaceSpec takes {', '.join(SPEC_FIELDS)})"
    return text


def run_user(ref: str, what: str, fn, *args):
    """``fn(*args)``, the user's code: any exception but KeyboardInterrupt (SystemExit too)
    becomes one InputError line naming the file/module (``ref``), the function and the exception."""
    try:
        return fn(*args)
    except KeyboardInterrupt:
        raise
    except InputError as exc:  # already one line; say where it came from
        raise InputError("space", f"{what} to succeed (it raised InputError: {exc})", got=ref) from None
    except BaseException as exc:  # noqa: BLE001 - the user's code may raise anything, SystemExit too
        raise InputError("space", f"{what} to succeed (it raised {_describe(exc)})", got=ref) from None


def _import(where: str, ref: str):
    """The module of ``path/to/file.py`` or ``package.module``, imported under the guard."""
    if where.endswith(".py"):
        path = Path(where)
        if not path.is_file():
            raise InputError("space", f"an existing Python file (no file {where})", got=ref)
        module_name = f"infsup_user_space_{abs(hash(str(path.resolve())))}"

        def load():
            spec = importlib.util.spec_from_file_location(module_name, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[module_name] = module
            spec.loader.exec_module(module)
            return module
        return run_user(ref, f"the import of {where}", load)
    return run_user(ref, f"the import of {where}", importlib.import_module, where)


SPACE_ALLOWED = "FILE.py:FUNC, module:FUNC, a SpaceSpec, or a function of no arguments returning one"
"""What a space reference may be: a file's or module's function by name (the command line), or
the SpaceSpec or function itself (the Python API, ``space=``)."""


def _function(ref: str):
    """The callable named by ``path/to/file.py:func`` or ``package.module:func``."""
    where, sep, name = ref.rpartition(":")
    if not sep or not where or not name.isidentifier():
        raise InputError("space", "FILE.py:FUNC or module:FUNC", got=ref)
    module = _import(where, ref)
    func = getattr(module, name, None)
    if not callable(func):
        raise InputError("space", f"a function {name} in {where}", got=ref)
    return _of_no_arguments(func, name, ref)


def _of_no_arguments(func, name: str, ref):
    """``func`` itself, refused (one line) when it needs arguments: the build function named
    instead of the one returning the SpaceSpec."""
    try:
        params = inspect.signature(func).parameters.values()
    except (TypeError, ValueError):  # a builtin without a signature: calling it will tell
        params = ()
    required = [p.name for p in params if p.default is p.empty
                and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
    if required:
        raise InputError("space", f"{name} to be a function of no arguments returning a SpaceSpec; it takes "
                         f"({', '.join(required)}): is it the build function? Name the function that "
                         "returns the SpaceSpec (e.g. FILE.py:space)", got=ref)
    return func


def _source(ref) -> tuple:
    """``(label, name, function of no arguments)`` of a space reference: a ``FILE.py:FUNC`` or
    ``module:FUNC`` string, a :class:`SpaceSpec` (its own function), or such a function given
    itself (labelled ``module:NAME``, as a string would name it)."""
    if isinstance(ref, str):
        return ref, ref.rpartition(":")[2], _function(ref)
    if isinstance(ref, SpaceSpec):
        return f"SpaceSpec {ref.id!r}", "the SpaceSpec", lambda: ref
    if callable(ref):
        name = getattr(ref, "__qualname__", None) or type(ref).__name__
        label = f"{getattr(ref, '__module__', None) or '?'}:{name}"
        return label, name, _of_no_arguments(ref, name, label)
    raise InputError("space", SPACE_ALLOWED, got=ref)


def check_fields(spec, ref: str) -> None:
    """The SpaceSpec itself: its type, id (:data:`ID_PATTERN`), expectation and callables."""
    if not isinstance(spec, SpaceSpec):
        raise InputError("space", f"{ref} returning a SpaceSpec (got {type(spec).__name__})", got=ref)
    if not isinstance(spec.id, str) or not ID_PATTERN.fullmatch(spec.id):
        raise InputError(f"space id from {ref}", ID_ALLOWED, got=spec.id)
    if spec.id in SPACES:
        raise InputError("space", f"an id not already registered ({', '.join(SPACES)})", got=spec.id)
    if spec.expected not in ("stable", "unstable", "unknown"):
        raise InputError(f"space {spec.id!r}", "expected = stable, unstable or unknown", got=spec.expected)
    if isinstance(spec.min_k, bool) or not isinstance(spec.min_k, (int, np.integer)) \
            or not K_RANGE[0] <= spec.min_k <= K_RANGE[1]:
        raise InputError(f"space {spec.id!r}", f"min_k an integer in {K_RANGE[0]}..{K_RANGE[1]}", got=spec.min_k)
    for field in ("build", "degree"):
        if not callable(getattr(spec, field)):
            raise InputError(f"space {spec.id!r}", f"{field} a function", got=getattr(spec, field))
    if spec.dimension is not None and not callable(spec.dimension):
        raise InputError(f"space {spec.id!r}", "dimension a function dimension(k, N) or None", got=spec.dimension)


def built_on(spec: SpaceSpec, ref: str, k: int, x: np.ndarray) -> SegmentSpace:
    """``spec.build(k, x)`` under the guard, checked to be a SegmentSpace on the partition
    ``x`` (same breakpoints, one row of dofs per interval) with the stated dimension."""
    n = len(x) - 1
    name = f"space {spec.id!r} from {ref}"
    space = run_user(ref, f"{spec.id}'s build(k={k}, breakpoints) on N = {n} intervals", spec.build, k, x.copy())
    if not isinstance(space, SegmentSpace):
        raise InputError(name, f"build(k, breakpoints) returning a SegmentSpace (got {type(space).__name__} "
                         f"at k = {k}, N = {n})")
    bp = np.asarray(space.breakpoints, dtype=float)
    if bp.shape != x.shape or not np.allclose(bp, x, rtol=0.0, atol=1e-14):
        built = f"{max(len(bp) - 1, 0)} intervals" if bp.shape != x.shape else "other breakpoints"
        raise InputError(name, f"a space on the partition it is given (at k = {k} it was given N = {n} "
                         f"intervals and built one on {built})")
    if np.shape(space.dofs)[:1] != (n,):
        raise InputError(name, f"a dof row per interval of its partition (N = {n}, dofs shape "
                         f"{np.shape(space.dofs)}, k = {k})")
    if spec.dimension is not None:
        stated = run_user(ref, f"{spec.id}'s dimension({k}, {n})", spec.dimension, k, n)
        if space.dim != stated:
            raise InputError(name, f"dimension {stated} as stated by its dimension(k, N) at k = {k}, N = {n} "
                             f"(the built space has {space.dim})")
    return space


def guarded_build(spec: SpaceSpec, ref: str):
    """``spec.build`` wrapped in :func:`built_on`: every build, in every job, is checked."""
    def build(k, breakpoints):
        return built_on(spec, ref, k, np.asarray(breakpoints, dtype=float))
    return build


def check_space(spec: SpaceSpec, ref: str = "", intervals=()) -> None:
    """Build ``spec`` for every k it allows on :data:`CHECK_PARTITION` and on the uniform
    partition of each N in ``intervals``, and check it.

    Checked: :func:`built_on` (a SegmentSpace on the given partition, of the stated
    dimension); its local degree is ``degree(k)``; basis values are finite; the basis is
    linearly independent (its L²(Γ) Gram matrix is positive definite to 1e-12 relative). A
    space of dimension 0 passes here: the N it is empty on is refused where N is given
    (:func:`~infsup_contact.discretization.spaces.registry.check_nonempty`).

    Raises
    ------
    InputError
        naming the space (id and reference) and the first failure.
    """
    from ..segment.norms import gram_l2  # norms imports the space classes, not the registry

    name = f"space {spec.id!r}" + (f" from {ref}" if ref else "")
    partitions = [CHECK_PARTITION] + [np.linspace(0.0, 1.0, int(n) + 1) for n in sorted(set(intervals)) if n >= 1]
    for k in range(max(spec.min_k, K_RANGE[0]), K_RANGE[1] + 1):
        degree = run_user(ref, f"{spec.id}'s degree({k})", spec.degree, k)
        for x in partitions:
            n = len(x) - 1
            space = built_on(spec, ref, k, x)
            if space.degree != degree:
                raise InputError(name, f"local degree {degree} as stated by its degree(k) at k = {k} "
                                 f"(the built space has {space.degree})")
            if space.dim == 0:
                continue
            values = space.evaluate(np.linspace(0.0, 1.0, 97))
            if not np.all(np.isfinite(values)):
                raise InputError(name, f"finite basis values (non-finite at k = {k}, N = {n})")
            if space.dim > MAX_GRAM_DIM:
                continue
            ev = np.linalg.eigvalsh(gram_l2(space))
            if not np.all(np.isfinite(ev)) or ev[0] <= 1e-12 * max(ev[-1], np.finfo(float).tiny):
                raise InputError(name, f"a linearly independent basis (its L² Gram matrix is singular at k = {k}, "
                                 f"N = {n})")


def load_user_space(ref, intervals=()) -> SpaceSpec:
    """Load, check and register the space of ``ref``: ``FILE.py:FUNC`` or ``module:FUNC``, or
    (the Python API) a :class:`SpaceSpec` or a function of no arguments returning one, checked
    exactly as the function a string names.

    ``intervals``: the numbers of intervals of the multiplier meshes the run will use; the
    space is checked on each (loading again with new ones checks those). Loading the same
    reference (the same string, the same object) again returns the same entry. Its ledger
    claims are tagged with its id unless it sets ``claim_tag``. Its registered ``build`` is
    :func:`guarded_build`.
    """
    intervals = {int(n) for n in intervals}
    key = _key(ref)
    if key in _LOADED:
        todo = intervals - _CHECKED[key]
        if todo:
            check_space(_LOADED[key], _LABELS[key], todo)
            _CHECKED[key] |= todo
        return _LOADED[key]
    label, name, func = _source(ref)
    spec = run_user(label, f"{name}()", func)
    check_fields(spec, label)
    check_space(spec, label, intervals)
    spec = dataclasses.replace(spec, build=guarded_build(spec, label), claim_tag=spec.claim_tag or spec.id)
    _LOADED[key] = register(spec)
    _CHECKED[key], _LABELS[key] = set(intervals), label
    if not isinstance(ref, str):
        _OBJECTS[key] = ref  # kept alive: its id is not reused while the entry is
    return spec


def _key(ref):
    """The registry key of a reference: the string, or the object's identity (a SpaceSpec may
    hold unhashable values; the same object again is the same entry)."""
    return ref if isinstance(ref, str) else ("object", id(ref))


def load_user_spaces(refs, intervals=()) -> list:
    """:func:`load_user_space` for each reference (e.g. the config's ``spaces`` list)."""
    return [load_user_space(r, intervals) for r in refs or ()]


def forget_since(before) -> None:
    """Unregister every user space loaded since the registry held the ids ``before`` (a test,
    or a long-lived process such as a notebook, restores the registry it started with)."""
    for key, spec in list(_LOADED.items()):
        if spec.id not in before:
            for table in (_LOADED, _CHECKED, _LABELS, _OBJECTS):
                table.pop(key, None)
    for case in set(SPACES) - set(before):
        del SPACES[case]


def config_case_ids(cfg, gamma_dim: int) -> list:
    """The ids a config may use on an interface of dimension ``gamma_dim`` (1: the segment of
    the 2D stages; 2: the face stage): the built-in spaces and the user spaces of its own
    ``spaces`` key (not those another config registered earlier in the same process)."""
    from .registry import space_ids

    users = {spec.id for spec in _LOADED.values()}
    own = {load_user_space(ref).id for ref in cfg.get("spaces") or []}
    return [c for c in space_ids(gamma_dim) if c not in users or c in own]
