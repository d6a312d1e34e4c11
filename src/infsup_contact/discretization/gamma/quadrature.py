"""Gauss–Legendre rules, computed once per order.

numpy's ``leggauss`` solves an eigenproblem for every call; the β_h sweep asks for the same
few orders hundreds of times per mesh pair, so the rules are cached here and shared by every
module that integrates on Γ (couplings, Gram matrices, dual bases, error measures). The
arrays are read-only because they are shared.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=None)
def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss–Legendre nodes and weights on [−1, 1] (exact for degree 2n − 1)."""
    t, w = np.polynomial.legendre.leggauss(int(n))
    t.flags.writeable = w.flags.writeable = False
    return t, w


@lru_cache(maxsize=None)
def gauss_legendre_01(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss–Legendre nodes and weights on [0, 1]."""
    t, w = gauss_legendre(n)
    u, lam = 0.5 * (t + 1.0), 0.5 * w
    u.flags.writeable = lam.flags.writeable = False
    return u, lam
