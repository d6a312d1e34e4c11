"""The plane-strain material law of the elastic model: admissible ν and E, and the Lamé
constants at unit Young's modulus.

Its own module so that the elastic scenes (``study.patch``, ``study.contact.hertz``) and the CLI
check and measure with it without importing the concrete model
(:mod:`infsup_contact.models.elastic`).
"""
from __future__ import annotations

from ..errors import InputError

NU_RANGE = (-1.0, 0.5)
"""Admissible Poisson ratio, −1 < ν < 1/2 (exclusive): a(·,·) is coercive exactly there."""
E_RANGE = (1e-150, 1e150)
"""Admissible Young's modulus: finite and positive (the membranes' c range, errors.C_RANGE)."""


def check_nu(value, key: str = "nu") -> float:
    """ν as a float in (−1, 1/2); :class:`InputError` naming ``key`` otherwise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(key, "a finite Poisson ratio with -1 < nu < 0.5", got=value) from None
    if isinstance(value, bool) or not NU_RANGE[0] < v < NU_RANGE[1]:  # NaN fails too
        raise InputError(key, "a finite Poisson ratio with -1 < nu < 0.5 (0.5 is incompressible: "
                         "a(.,.) is not coercive; nu <= -1 neither)", got=value)
    return v


def check_modulus(value, key: str) -> float:
    """E as a float in [1e-150, 1e150]; :class:`InputError` naming ``key`` otherwise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(key, "a finite Young's modulus in [1e-150, 1e150]", got=value) from None
    if isinstance(value, bool) or not E_RANGE[0] <= v <= E_RANGE[1]:
        raise InputError(key, "a finite Young's modulus in [1e-150, 1e150] (E > 0)", got=value)
    return v


def lame(nu: float) -> tuple:
    """(μ̂, λ̂) of plane strain at E = 1: the Lamé constants of the 3D law, which plane strain
    takes as they are (the 3D bodies, :mod:`.elastic3d`, use them too)."""
    return 1.0 / (2.0 * (1.0 + nu)), nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
