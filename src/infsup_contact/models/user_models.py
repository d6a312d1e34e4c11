"""A model by name or from a user's file: ``membranes`` or ``path/to/file.py:NAME``.

A new model is a model file (a :class:`~.contract.Model`, usually a dozen lines around its
``side_operator``; ``examples/orthotropic_membranes.py`` is one) and one entry of the config's
model table naming it (:mod:`infsup_contact.plans.beta`). The file is imported once per process
under one guard: any exception becomes one :class:`~infsup_contact.errors.InputError` line naming
the reference, and so does a ``NAME`` that is not a :class:`~.contract.Model`.
"""
from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path

from ..errors import InputError
from .contract import Model

_LOADED: dict = {}
ALLOWED = "a registered model ({names}) or FILE.py:NAME / module:NAME naming a Model"


def _allowed() -> str:
    from . import MODELS

    return ALLOWED.format(names=", ".join(MODELS))


def _module(where: str, ref: str):
    if not where.endswith(".py"):
        return importlib.import_module(where)
    path = Path(where)
    if not path.is_file():
        raise InputError("model", f"{_allowed()}; no file {where}", got=ref)
    name = f"infsup_user_model_{abs(hash(str(path.resolve())))}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def load_model(ref: str) -> Model:
    """The :class:`~.contract.Model` named ``NAME`` in ``FILE.py`` or ``module`` (``ref`` =
    ``FILE.py:NAME``), imported once per process."""
    if ref in _LOADED:
        return _LOADED[ref]
    where, sep, attr = ref.rpartition(":")
    if not sep or not where or not attr.isidentifier():
        raise InputError("model", _allowed(), got=ref)
    try:
        model = getattr(_module(where, ref), attr, None)
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - the user's code may raise anything
        reason = " ".join(f"{type(exc).__name__}: {exc}".split())
        raise InputError("model", f"{_allowed()}; importing {where} raised {reason}", got=ref) from None
    if not isinstance(model, Model):
        raise InputError("model", f"{_allowed()}; {attr} in {where} is {type(model).__name__}, not a Model", got=ref)
    _LOADED[ref] = model
    return model


def model_named(ref) -> Model:
    """A registered model by name (:data:`~infsup_contact.models.MODELS`) or a user's (:func:`load_model`)."""
    from . import MODELS

    if isinstance(ref, str) and ref in MODELS:
        return MODELS[ref]
    if not isinstance(ref, str) or ":" not in ref:
        raise InputError("model", _allowed(), got=ref)
    return load_model(ref)
