"""How the ledger states a round-off-level quantity: against its tolerance, not by its digits.

A patch test's max relative error, an invariance check (β_h under κ scaling), the agreement of
two routes "to 1e-10": such a value is round-off when it passes, and its digits are not a
result. They change with the route that computed it (a factorization in parity blocks instead
of the whole body, another Gram route) and with the machine (OpenBLAS and MKL pick their code
paths by CPU: ``OPENBLAS_CORETYPE``, ``MKL_CBWR``), while every verdict and every β_h stays
the same. A ledger that printed them could never be byte-identical across routes or machines,
and a reader would learn nothing from them that "within the tolerance" does not say.

So :func:`within` prints the quantity against its tolerance where it passes, and its value
only where it does not (there the value is the information a reader needs). Values that are
not round-off (β_h, slopes, fitted rates, kernel counts, discretization errors) are printed as
they are.
"""
from __future__ import annotations

import math

UPPER, LOWER = "<=", ">="
"""``bound``: the quantity passes when it is at most the tolerance (an error), or at least it
(a margin that may dip below 0 by round-off)."""


def within(quantity: str, value: float, tol: float, bound: str = UPPER) -> str:
    """The evidence text of a round-off-level ``quantity`` tested against ``tol``.

    Parameters
    ----------
    quantity : str
        What is measured, as the ledger names it ("max |β_κ/β − 1|").
    value : float
        Its value (NaN or inf never passes).
    tol : float
        The tolerance it is tested against.
    bound : {"<=", ">="}
        Passes when ``value <= tol`` (an error) or ``value >= tol`` (a margin).

    Returns
    -------
    str
        ``"<quantity> <= <tol> (the tolerance)"`` when it passes; otherwise
        ``"<quantity> = <value>, not <= <tol> (the tolerance)"`` with the value to 3 digits.

    Examples
    --------
    >>> within("max |λ_h − λ|/λ", 3e-13, 1e-8)
    'max |λ_h − λ|/λ <= 1e-08 (the tolerance)'
    >>> within("max |λ_h − λ|/λ", 0.25, 1e-8)
    'max |λ_h − λ|/λ = 0.25, not <= 1e-08 (the tolerance)'
    """
    if passes(value, tol, bound):
        return f"{quantity} {bound} {tol:g} (the tolerance)"
    return f"{quantity} = {float(value):.3g}, not {bound} {tol:g} (the tolerance)"


def passes(value: float, tol: float, bound: str = UPPER) -> bool:
    """Whether :func:`within` states ``value`` as within ``tol`` (finite and on the right side)."""
    if bound not in (UPPER, LOWER):
        raise ValueError(f"bound must be {UPPER!r} or {LOWER!r}, got {bound!r}")
    value = float(value)
    return math.isfinite(value) and (value <= tol if bound == UPPER else value >= tol)
