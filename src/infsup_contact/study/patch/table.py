"""The patch test's table, one loop for every model: each (N1, N2) pair and k factorizes the
scene's two bodies once and solves every case the registry defines for that k on them; and the
kernel count every model's rows report."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ... import progress
from ...discretization.spaces import registry

KERNEL_RTOL = 1e-8
"""Generalized eigenvalues of (K, G) below this times the largest count as kernel."""


def patch_rows(pair_of, solve, cases, ks, pairs) -> list:
    """Rows of a patch table: ``solve(case, k, n1, n2, pair)`` for every (n1, n2) in ``pairs``,
    every k in ``ks`` and every case of ``cases`` defined for k, with ``pair = pair_of(k, n1,
    n2)`` built once per (pair, k) and shared by its cases (one factorization per body)."""
    rows = []
    for n1, n2 in progress.steps(pairs, "mesh pair", lambda p: f"N1={p[0]} N2={p[1]}"):
        for k in progress.steps(ks, "k") if len(ks) > 1 else ks:
            progress.note("the two bodies: mesh, stiffness, factorization")
            pair = pair_of(k, n1, n2)
            rows += [solve(case, k, n1, n2, pair) for case in progress.steps(registry.ids_valid_for(k, cases), "space")]
    return rows


def kernel_dim(K: np.ndarray, G: np.ndarray, rtol: float = KERNEL_RTOL) -> int:
    """Dimension of the kernel of the Schur complement ``K`` measured against the multiplier
    Gram matrix ``G``: eigenvalues of K x = θ G x below ``rtol`` × the largest."""
    ev = sla.eigh(K, G, eigvals_only=True)
    return int(np.sum(ev < rtol * ev[-1]))
