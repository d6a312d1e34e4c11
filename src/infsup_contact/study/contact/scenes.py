"""Load cases ("scenes") for the two-membrane model problem of Bathe & Brezzi (2001).

The model problem (paper Section 3): Ω1 = (0,1)×(0,1), Ω2 = (0,1)×(1,2), common edge
Γ = (0,1)×{1}, u_i = 0 on ∂Ω_i∖Γ, energy a(u,v) = Σ c_i ∫ ∇u_i·∇v_i (3.2)–(3.4), gap
g(v) = v2 − v1 on Γ (3.5), constraint g(u) ≥ 0 (3.6), mixed form (3.12).

Sign convention for the multiplier.  Integrating (3.12) by parts with the outward
normals n1 = +e_y, n2 = −e_y on Γ gives

    λ = −c1 ∂u1/∂y = −c2 ∂u2/∂y   on Γ,

so that λ ≥ 0 is a compressive contact pressure.  The paper's (3.13) prints the opposite
sign; that is an erratum (with (3.13) as printed, λ ≥ 0 would pull the membranes
together).  Everything in this module uses the sign above.

Scenes
------
``manufactured``
    Exact solution with contact zone (0, a) and a gap opening on (a, 1), see
    :func:`manufactured`.  Smooth (p = q = 3) or low-regularity (p = q = 1.75).
``membranes``
    The physical load case of the paper's Fig. 4: Ω1 pushed up, Ω2 pushed down by
    f0(x) = 4(1 − 2x); no closed-form solution, see :func:`membranes`.

All fields are NGSolve CoefficientFunctions in ``ngsolve.x, ngsolve.y`` (global
coordinates, so Ω2 lives at 1 < y < 2); Γ data are numpy callables of x.
"""
from __future__ import annotations

import inspect
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from ngsolve import CoefficientFunction, IfPos, cos, pi, sin, x, y

from ...errors import InputError, check_prestress
from .registry import MANUFACTURED, MEMBRANES, scene_data

#: Regularity threshold: λ'' ~ (a − x)₊^(p−2) and g'' ~ (x − a)₊^(q−2) are in L² iff the
#: exponent exceeds 1.5, i.e. f = −c Δu ∈ L²(Ω) as required by (3.7).
MIN_EXPONENT = 1.5


# --------------------------------------------------------------------------- helpers
def _pos_pow(s: CoefficientFunction, e: float) -> CoefficientFunction:
    """(s)₊^e as a CoefficientFunction, valid for non-integer and negative e.

    The inner IfPos replaces the base by 1 where s ≤ 0, so ``pow`` never sees a zero or
    negative base: NGSolve evaluates both IfPos branches, and a NaN/inf from the
    discarded branch would otherwise leak into products (and into ``Diff``).
    """
    return IfPos(s, IfPos(s, s, 1.0) ** e, 0.0)


def _np_pos_pow(s: np.ndarray, e: float) -> np.ndarray:
    """numpy twin of :func:`_pos_pow` (same safe-base trick, no warnings)."""
    s = np.asarray(s, dtype=float)
    return np.where(s > 0, np.where(s > 0, s, 1.0) ** e, 0.0)


def _positive(key: str, value) -> float:
    """Validate a prestress c1, c2 (finite, in :data:`~infsup_contact.errors.C_RANGE`)."""
    return check_prestress(key, value)


def _exponent(key: str, value) -> float:
    """Validate a regularity exponent p or q > 1.5 (f ∈ L²)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(key, f"a real number > {MIN_EXPONENT}", got=value) from None
    if not (math.isfinite(v) and v > MIN_EXPONENT):
        raise InputError(key, f"a real number > {MIN_EXPONENT} (so that f is in L2)", got=value)
    return v


def _contact_end(value) -> float:
    """Validate the end a of the contact zone (0, a), 0 < a < 1."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError("a", "a real number in (0, 1)", got=value) from None
    if not (math.isfinite(v) and 0.0 < v < 1.0):
        raise InputError("a", "a real number in (0, 1)", got=value)
    return v


# ---------------------------------------------------------------- manufactured scene
@dataclass(frozen=True)
class ManufacturedSolution:
    """Exact solution of the model problem (3.12) with a known contact zone.

    Attributes
    ----------
    c1, c2 : float
        Membrane prestresses of (3.2).
    p, q : float
        Exponents of λ(x) = x (a − x)₊^p and g(x) = (x − a)₊^q (1 − x).
    a : float
        End of the contact zone (0, a) ⊂ Γ.
    u1, u2 : CoefficientFunction
        Exact displacements on Ω1 (0 < y < 1) and Ω2 (1 < y < 2).
    grad_u1, grad_u2 : CoefficientFunction, dim 2
        Exact gradients (∂x, ∂y), derived by hand.
    f1, f2 : CoefficientFunction
        Loads f_i = −c_i Δu_i, derived by hand.
    lam : callable
        λ(x) on Γ (numpy); equals −c_i ∂_y u_i at y = 1.
    gap : callable
        g(x) = u2 − u1 on Γ (numpy).
    contact_set : tuple of float
        The open interval (0, a) where λ > 0 and g = 0.
    name : str
        ``"manufactured"``.
    """

    c1: float
    c2: float
    p: float
    q: float
    a: float
    u1: CoefficientFunction
    u2: CoefficientFunction
    grad_u1: CoefficientFunction
    grad_u2: CoefficientFunction
    f1: CoefficientFunction
    f2: CoefficientFunction
    lam: Callable[[np.ndarray], np.ndarray]
    gap: Callable[[np.ndarray], np.ndarray]
    contact_set: tuple
    name: str = field(default=MANUFACTURED.id)

    @property
    def has_exact(self) -> bool:
        """Whether exact u, λ are available (True here)."""
        return True


def _gamma_profiles(p: float, q: float, a: float) -> dict:
    """Trace profiles along x and their first two derivatives, as CFs.

    t1 = sin(πx) is the trace of u1 on Γ, λ = x s^p with s = (a − x)₊, and
    g = r^q (1 − x) with r = (x − a)₊.  Derivatives by the product/chain rule
    (s' = −1, r' = +1 where positive):

    λ'  = s^p − p x s^(p−1)
    λ'' = −2p s^(p−1) + p(p−1) x s^(p−2)
    g'  = q r^(q−1) (1 − x) − r^q
    g'' = q(q−1) r^(q−2) (1 − x) − 2q r^(q−1)
    """
    s, r = a - x, x - a
    lam = x * _pos_pow(s, p)
    dlam = _pos_pow(s, p) - p * x * _pos_pow(s, p - 1)
    ddlam = -2 * p * _pos_pow(s, p - 1) + p * (p - 1) * x * _pos_pow(s, p - 2)
    gap = _pos_pow(r, q) * (1 - x)
    dgap = q * _pos_pow(r, q - 1) * (1 - x) - _pos_pow(r, q)
    ddgap = q * (q - 1) * _pos_pow(r, q - 2) * (1 - x) - 2 * q * _pos_pow(r, q - 1)
    t1, dt1, ddt1 = sin(pi * x), pi * cos(pi * x), -pi**2 * sin(pi * x)
    return dict(lam=(lam, dlam, ddlam), t1=(t1, dt1, ddt1),
                t2=(t1 + gap, dt1 + dgap, ddt1 + ddgap))


def _membrane_field(t, lam, c, phi, psi):
    """u = t(x) φ(y) − (λ(x)/c) ψ(y), its gradient and f = −c Δu.

    ``t``, ``lam`` are (value, d/dx, d²/dx²) triples of CFs in x; ``phi``, ``psi`` are
    (value, d/dy, d²/dy²) triples of CFs in y.  Separable form, so
    Δu = t'' φ + t φ'' − (λ'' ψ + λ ψ'')/c.
    """
    u = t[0] * phi[0] - lam[0] / c * psi[0]
    grad = CoefficientFunction((t[1] * phi[0] - lam[1] / c * psi[0],
                                t[0] * phi[1] - lam[0] / c * psi[1]))
    f = -c * (t[2] * phi[0] + t[0] * phi[2]) + lam[2] * psi[0] + lam[0] * psi[2]
    return u, grad, f


def manufactured(c1=1.0, c2=1.0, p=3.0, q=3.0, a=1 / math.sqrt(5)) -> ManufacturedSolution:
    """Manufactured solution of (3.12) with contact on (0, a) and a gap on (a, 1).

    u1 = t1(x)(2y − y²) − (λ(x)/c1)(y² − y)            on Ω1,
    u2 = t2(x)(1 − (y−1)²) − (λ(x)/c2)(y − 1)(2 − y)    on Ω2,

    with t1 = sin(πx), t2 = t1 + g, λ = x (a − x)₊^p, g = (x − a)₊^q (1 − x).
    The y-profiles are chosen so that (i) u_i = 0 on ∂Ω_i∖Γ (3.1): the profiles vanish at
    y = 0 resp. y = 2 and t1, λ, g vanish at x = 0, 1; (ii) on Γ (y = 1) the first
    profile is 1 with zero slope and the second is 0 with slope ±1, so u2 − u1 = g and
    −c_i ∂_y u_i = λ (the sign-corrected (3.13)).  Since λ g = 0, λ ≥ 0, g ≥ 0, the pair
    (u, λ) satisfies the complementarity (3.14) and solves (3.12) with f_i = −c_i Δu_i.

    Parameters
    ----------
    c1, c2 : float > 0
        Prestresses of (3.2).
    p, q : float > 1.5
        Regularity exponents; λ'' and g'' (hence f) are in L² iff p, q > 1.5.  Defaults
        3 (smooth); p = q = 1.75 is the low-regularity variant.
    a : float in (0, 1)
        End of the contact zone; default 1/√5 (irrational, so it is never a mesh node).

    Returns
    -------
    ManufacturedSolution

    Raises
    ------
    InputError
        For c_i ≤ 0, p or q ≤ 1.5, or a outside (0, 1).
    """
    c1, c2 = _positive("c1", c1), _positive("c2", c2)
    p, q, a = _exponent("p", p), _exponent("q", q), _contact_end(a)
    prof = _gamma_profiles(p, q, a)
    # y-profiles (value, d/dy, d²/dy²); see the docstring for why these.
    phi1, psi1 = (2 * y - y * y, 2 - 2 * y, -2.0), (y * y - y, 2 * y - 1, 2.0)
    phi2 = (1 - (y - 1) * (y - 1), -2 * (y - 1), -2.0)
    psi2 = ((y - 1) * (2 - y), 3 - 2 * y, -2.0)
    u1, g1, f1 = _membrane_field(prof["t1"], prof["lam"], c1, phi1, psi1)
    u2, g2, f2 = _membrane_field(prof["t2"], prof["lam"], c2, phi2, psi2)

    def lam(xs):
        xs = np.asarray(xs, dtype=float)
        return xs * _np_pos_pow(a - xs, p)

    def gap(xs):
        xs = np.asarray(xs, dtype=float)
        return _np_pos_pow(xs - a, q) * (1 - xs)

    return ManufacturedSolution(c1=c1, c2=c2, p=p, q=q, a=a, u1=u1, u2=u2,
                                grad_u1=g1, grad_u2=g2, f1=f1, f2=f2,
                                lam=lam, gap=gap, contact_set=(0.0, a))


# ------------------------------------------------------------------- membranes scene
@dataclass(frozen=True)
class MembraneScene:
    """Loads of the paper's Fig. 4 set-up; no exact solution.

    Attributes
    ----------
    c1, c2 : float
        Prestresses of (3.2).
    f0 : CoefficientFunction
        Load profile f0(x).
    f1, f2 : CoefficientFunction
        f1 = +f0 on Ω1 (pushes Ω1 up into Ω2), f2 = −f0 on Ω2 (pushes Ω2 down).
    name : str
        ``"membranes"``.
    """

    c1: float
    c2: float
    f0: CoefficientFunction
    f1: CoefficientFunction
    f2: CoefficientFunction
    name: str = field(default=MEMBRANES.id)

    @property
    def has_exact(self) -> bool:
        """Whether exact u, λ are available (False here)."""
        return False


def _load_profile(f0) -> CoefficientFunction:
    """Turn ``f0`` (None, number, CoefficientFunction or callable of x) into a CF."""
    if f0 is None:
        # Changes sign at x = 1/2: the membranes are pressed together on one half of Γ
        # and pulled apart on the other, so both contact and separation occur.
        return 4 * (1 - 2 * x)
    if isinstance(f0, CoefficientFunction):
        return f0
    if isinstance(f0, (int, float)) and not isinstance(f0, bool) and math.isfinite(f0):
        return CoefficientFunction(float(f0))
    if callable(f0):
        cf = f0(x)
        if isinstance(cf, CoefficientFunction):
            return cf
        if isinstance(cf, (int, float)) and not isinstance(cf, bool):
            return CoefficientFunction(float(cf))
    raise InputError("f0", "None, a finite number, an ngsolve CoefficientFunction, "
                     "or a callable mapping ngsolve.x to one", got=f0)


def membranes(c1=1.0, c2=1.0, f0=None) -> MembraneScene:
    """Opposing transverse loads on the two membranes (paper Fig. 4).

    Parameters
    ----------
    c1, c2 : float > 0
        Prestresses of (3.2).
    f0 : None, float, CoefficientFunction or callable, optional
        Load profile; a callable is applied to ``ngsolve.x``.  Default 4(1 − 2x).

    Returns
    -------
    MembraneScene
        With f1 = +f0 (Ω1) and f2 = −f0 (Ω2): where f0 > 0 the membranes are pushed
        against each other and contact (g = 0, λ > 0) is expected, where f0 < 0 they
        separate.
    """
    c1, c2 = _positive("c1", c1), _positive("c2", c2)
    prof = _load_profile(f0)
    return MembraneScene(c1=c1, c2=c2, f0=prof, f1=prof, f2=-prof)


# ------------------------------------------------------------------------ dispatcher
def scene(name: str, **params):
    """Build the data of the scene ``name`` (a registered scene with data,
    :func:`~.scene_registry.data_scene_ids`) with keyword ``params``.

    Raises
    ------
    InputError
        For an unknown scene name or a parameter the scene does not take.
    """
    return scene_data(name, **params)


__all__ = ["ManufacturedSolution", "MembraneScene", "manufactured", "membranes", "scene"]
