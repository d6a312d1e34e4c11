"""Users' multiplier spaces: ``FILE.py:FUNC`` or ``module:FUNC`` → a checked registry entry.

A user space is a function of no arguments returning a
:class:`~infsup_contact.discretization.registry.SpaceSpec` whose ``build(k, breakpoints)``
returns a :class:`~infsup_contact.discretization.multipliers.MultiplierSpace` — usually from
:func:`~infsup_contact.discretization.multipliers.make_space` (Lagrange, (5.3)/(5.5)) or
:func:`~infsup_contact.discretization.multipliers.local_basis_space` (any local basis and
numbering). ``examples/macro_p0.py`` is one. Before it is registered the space is built on a
non-uniform partition for every degree it allows and checked; a malformed space gets one
:class:`~infsup_contact.errors.InputError` naming it and what is wrong.
"""
from __future__ import annotations

import dataclasses
import importlib
import importlib.util
import sys
from pathlib import Path

import numpy as np

from ..errors import InputError
from .multipliers import MultiplierSpace
from .registry import K_RANGE, SPACES, SpaceSpec, register

_LOADED: dict[str, SpaceSpec] = {}
CHECK_PARTITION = np.array([0.0, 0.13, 0.3, 0.52, 0.71, 1.0])
"""The non-uniform partition (N = 5) every user space is checked on."""


def _function(ref: str):
    """The callable named by ``path/to/file.py:func`` or ``package.module:func``."""
    where, sep, name = ref.rpartition(":")
    if not sep or not where or not name.isidentifier():
        raise InputError("space", "FILE.py:FUNC or module:FUNC", got=ref)
    try:
        if where.endswith(".py"):
            path = Path(where)
            if not path.is_file():
                raise InputError("space", f"an existing Python file (no file {where})", got=ref)
            module_name = f"infsup_user_space_{abs(hash(str(path.resolve())))}"
            spec = importlib.util.spec_from_file_location(module_name, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[module_name] = module
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(where)
    except InputError:
        raise
    except Exception as exc:  # the user's code: report it in one line, naming the space
        raise InputError("space", f"a module that imports cleanly ({type(exc).__name__}: {exc})", got=ref) from None
    func = getattr(module, name, None)
    if not callable(func):
        raise InputError("space", f"a function {name} in {where}", got=ref)
    return func


def check_space(spec: SpaceSpec, ref: str = "") -> None:
    """Build ``spec`` on :data:`CHECK_PARTITION` for every k it allows and check it.

    Checked: the build returns a MultiplierSpace on the given partition; the dimension equals
    ``spec.dimension`` where stated; basis values are finite; the basis is linearly
    independent (its L²(Γ) Gram matrix is positive definite to 1e-12 relative).

    Raises
    ------
    InputError
        key ``space``, naming the space (id and reference) and the first failure.
    """
    from .norms import gram_l2  # norms imports the space classes, not the registry

    name = f"{spec.id!r}" + (f" from {ref}" if ref else "")

    def fail(what):
        raise InputError(f"space {name}", what)

    x, n = CHECK_PARTITION, len(CHECK_PARTITION) - 1
    for k in range(max(spec.min_k, K_RANGE[0]), K_RANGE[1] + 1):
        try:
            space = spec.build(k, x.copy())
        except InputError as exc:
            fail(f"a build that succeeds for k = {k} ({exc})")
        except Exception as exc:
            fail(f"a build that succeeds for k = {k} ({type(exc).__name__}: {exc})")
        if not isinstance(space, MultiplierSpace):
            fail(f"build(k, breakpoints) returning a MultiplierSpace (got {type(space).__name__} at k = {k})")
        if not np.allclose(space.breakpoints[[0, -1]], [0.0, 1.0]):
            fail(f"a space on a partition of Γ = (0, 1) (k = {k})")
        if spec.dimension is not None and space.dim != spec.dimension(k, n):
            fail(f"dimension {spec.dimension(k, n)} as stated by its dimension(k, N) at k = {k}, N = {n} "
                 f"(the built space has {space.dim})")
        values = space.evaluate(np.linspace(0.0, 1.0, 97))
        if not np.all(np.isfinite(values)):
            fail(f"finite basis values (non-finite at k = {k})")
        ev = np.linalg.eigvalsh(gram_l2(space))
        if not np.all(np.isfinite(ev)) or ev[0] <= 1e-12 * max(ev[-1], np.finfo(float).tiny):
            fail(f"a linearly independent basis (its L² Gram matrix is singular at k = {k}, N = {n})")


def load_user_space(ref: str) -> SpaceSpec:
    """Load, check and register the space of ``ref`` (``FILE.py:FUNC`` or ``module:FUNC``).

    Loading the same reference again returns the same entry. Its ledger claims are tagged
    with its id unless it sets ``claim_tag``.
    """
    if ref in _LOADED:
        return _LOADED[ref]
    spec = _function(ref)()
    if not isinstance(spec, SpaceSpec):
        raise InputError("space", f"{ref} returning a SpaceSpec (got {type(spec).__name__})", got=ref)
    if spec.id in SPACES:
        raise InputError("space", f"an id not already registered ({', '.join(SPACES)})", got=spec.id)
    if spec.expected not in ("stable", "unstable", "unknown"):
        raise InputError(f"space {spec.id!r}", "expected = stable, unstable or unknown", got=spec.expected)
    check_space(spec, ref)
    if spec.claim_tag is None:
        spec = dataclasses.replace(spec, claim_tag=spec.id)
    _LOADED[ref] = register(spec)
    return spec


def load_user_spaces(refs) -> list:
    """:func:`load_user_space` for each reference (e.g. the config's ``spaces`` list)."""
    return [load_user_space(r) for r in refs or ()]
