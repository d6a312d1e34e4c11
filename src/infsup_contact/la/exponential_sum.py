"""1/√x as a sum of exponentials: a separable form of the face norm's weight 1/(π√(m² + n²)).

From the Gamma integral, 1/√x = (1/√π) ∫_0^∞ t^{−1/2} e^{−t x} dt, and with t = e^s

    1/√x = (1/√π) ∫_ℝ e^{s/2 − e^s x} ds ≈ Σ_j w_j e^{−a_j x},   a_j = e^{s_j},  w_j = h e^{s_j/2}/√π,

the trapezoidal rule on s_j = s_lo + j h. The integrand is analytic in the strip |Im s| < π/2 and
decays at both ends, so the rule converges geometrically, like e^{−π²/h} (Trefethen & Weideman,
SIAM Rev. 56 (2014), §5), and its relative error is the same at every x (a shift of s by ln x
maps one x to another). Cutting the sum at s_lo costs at most 2 e^{s_lo/2} √x / √π relative at
the largest x, cutting it at s_hi at most e^{−x e^{s_hi}} at the smallest x: both ends are set
from the tolerance, and the error actually reached is measured on a dense sample of [x_min, x_max].

With every w_j > 0 and a relative error ≤ ε in each weight, a Gram matrix Σ w(m, n) c cᵀ built
from the sum differs from the exact one by at most ε times itself in the Loewner order, so every
eigenvalue of a pencil with it moves by at most the factor 1 ± ε (:mod:`.face.norms.tensor` uses it
at every size; its direct double sum stays the reference route of the tests).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import InputError

STEP = 0.3
"""Step h of the trapezoidal rule in s = ln t: discretization error ~ e^{−π²/h} ≈ 5e-15."""
SAMPLES = 4000
"""Log-spaced points of [x_min, x_max] on which the reached relative error is measured."""


@dataclass(frozen=True)
class ExponentialSum:
    """1/√x ≈ Σ_j weights[j] exp(−rates[j] x) on [x_min, x_max].

    Attributes
    ----------
    rates, weights : ndarray
        a_j > 0 and w_j > 0.
    x_min, x_max : float
    rel_error : float
        max |Σ w_j e^{−a_j x} √x − 1| over :data:`SAMPLES` log-spaced points and both ends.
    """

    rates: np.ndarray
    weights: np.ndarray
    x_min: float
    x_max: float
    rel_error: float

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """The sum at the points ``x``."""
        x = np.asarray(x, float)
        return np.exp(-np.multiply.outer(x, self.rates)) @ self.weights


def inverse_sqrt(x_min: float, x_max: float, rtol: float = 1e-13) -> ExponentialSum:
    """The exponential sum of 1/√x on [x_min, x_max] to relative accuracy ``rtol`` (module docstring).

    Remembered per (x_min, x_max, rtol, :data:`STEP`, :data:`SAMPLES`) (:data:`CACHED` sums, read-only arrays): the face series
    asks for the same few ranges at every level and block of every space on one G_h, and
    measuring the reached error (:data:`SAMPLES` × r exponentials) cost as much as the product.

    Raises
    ------
    InputError
        Unless 0 < x_min <= x_max and 1e-15 <= rtol < 1.
    """
    if not 0 < x_min <= x_max < np.inf:
        raise InputError("x_min/x_max", "0 < x_min <= x_max < inf", got=(x_min, x_max))
    if not 1e-15 <= rtol < 1:
        raise InputError("rtol", "a float in [1e-15, 1)", got=rtol)
    return _inverse_sqrt(float(x_min), float(x_max), float(rtol), STEP, SAMPLES)


CACHED = 64
"""Exponential sums :func:`inverse_sqrt` keeps (a few hundred terms each)."""


@lru_cache(maxsize=CACHED)
def _inverse_sqrt(x_min: float, x_max: float, rtol: float, step: float, samples: int) -> ExponentialSum:
    s_lo = 2.0 * np.log(rtol * np.sqrt(np.pi) / (2.0 * np.sqrt(x_max)))   # tail below: ≤ rtol
    s_hi = np.log(np.log(1.0 / rtol) / x_min)                              # tail above: ≤ rtol
    s = np.arange(s_lo, s_hi + step, step)
    rates, weights = np.exp(s), step * np.exp(s / 2.0) / np.sqrt(np.pi)
    x = np.geomspace(x_min, x_max, samples)
    approx = np.exp(-np.multiply.outer(x, rates)) @ weights
    err = float(np.max(np.abs(approx * np.sqrt(x) - 1.0)))
    rates.setflags(write=False)
    weights.setflags(write=False)
    return ExponentialSum(rates, weights, x_min, x_max, err)
