"""Dual (biorthogonal) mortar multipliers on G_h.

Let {φ_j} be the nodal basis of the trace space W_h on G_h: continuous P_k on equispaced
Lagrange nodes. The dual basis {ψ_j} is discontinuous piecewise P_k, supported where φ_j is,
with

    ∫_Γ ψ_i φ_j = δ_ij ∫_Γ φ_j                                              (biorthogonality)

(Wohlmuth, SIAM J. Numer. Anal. 38 (2000) 989–1012). It is built interval by interval: on an
interval whose local nodes L all carry a basis function, ψ_{e,a} = Σ_b (D M⁻¹)_{ab} φ_{e,b}
with the local mass matrix M_ab = ∫_e φ_a φ_b and D = diag(∫_e φ_a): then
∫_e ψ_a φ_b = (D M⁻¹ M)_ab = δ_ab ∫_e φ_b, and summing over the intervals of supp φ_j gives
the global relation. Both M and D scale with the interval length, so D M⁻¹ is the same on
every interval.

Next to Γ's ends, where W_h vanishes (``DUAL``), the endpoint node carries no basis
function. The standard modification keeps one dual function per live node there and takes
them from P_{|L|−1}, |L| the number of live local nodes (P_{k−1} on an end interval):
ψ_a = Σ_p α_ap t^p with Σ_p α_ap ∫_e t^p φ_b = δ_ab ∫_e φ_b for a, b ∈ L. The matrix
∫ t^p φ_b (p < |L|, b ∈ L) is invertible because the live φ_b span t·P_{|L|−1} (or
(1 − t)·P_{|L|−1}, or t(1 − t)·P_{|L|−2} on a single interval) and ∫ t q² > 0. Since P_{|L|−1}
contains the constants, Σ_j ψ_j = 1 still holds: for k = 1 the end functions are the
constant 1 and ψ = 2φ_a − φ_b elsewhere. Without the end condition (``DUAL-ALL``) every
node, the ends included, gets the interior construction: dim = Nk + 1, the dual counterpart
of Rem 5.2.

Biorthogonality needs ∫ φ_j > 0: the closed Newton–Cotes weights of the equispaced nodes,
positive for k = 1..7 (checked by :func:`nodal_integrals`).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ...errors import InputError
from .multipliers import SegmentSpace, local_shapes, make_space, reference_nodes
from ..gamma.quadrature import gauss_legendre_01


@lru_cache(maxsize=None)
def _reference_moments(k: int, powers: int) -> tuple[np.ndarray, np.ndarray]:
    """T[p, b] = ∫_0^1 t^p φ_b(t) dt (p < ``powers``) and M[a, b] = ∫_0^1 φ_a φ_b, exact
    (cached: the same few per degree serve every interval of every mesh)."""
    t, w = gauss_legendre_01(k + 1)
    phi = local_shapes(k, t)                                  # (q, k+1)
    mono = t[:, None] ** np.arange(max(powers, 1))[None, :]   # (q, p)
    T, M = (mono * w[:, None]).T @ phi, (phi * w[:, None]).T @ phi
    T.flags.writeable = M.flags.writeable = False
    return T, M


def nodal_integrals(k: int) -> np.ndarray:
    """∫_0^1 φ_b for the equispaced Lagrange basis of degree k (the Newton–Cotes weights).

    Raises
    ------
    InputError
        If a weight is not positive (k ≥ 8 has negative ones): no dual basis exists then.
    """
    d = _reference_moments(k, 1)[0][0]
    if np.any(d <= 0):
        raise InputError("k", "a degree whose equispaced Lagrange basis has positive integrals (k <= 7)", got=k)
    return d


def local_dual_coefficients(k: int, live) -> np.ndarray:
    """C with ψ_a = Σ_b C[a, b] φ_b on one interval, for the live local nodes ``live``.

    All k + 1 nodes live: C = D M⁻¹. Otherwise ψ_a ∈ P_{|L|−1} (see the module docstring).
    Rows of dead nodes are zero. Shape (k + 1, k + 1).
    """
    return _local_dual_coefficients(int(k), tuple(int(a) for a in np.asarray(live, dtype=int))).copy()


@lru_cache(maxsize=None)
def _local_dual_coefficients(k: int, live: tuple) -> np.ndarray:
    """:func:`local_dual_coefficients`, cached: an interval has one of a few live patterns."""
    live = np.asarray(live, dtype=int)
    d = nodal_integrals(k)
    C = np.zeros((k + 1, k + 1))
    if len(live) == k + 1:
        M = _reference_moments(k, 1)[1]
        C[:] = np.diag(d) @ np.linalg.inv(M)
        C.flags.writeable = False
        return C
    T, _ = _reference_moments(k, len(live))                    # (|L|, k+1)
    alpha = np.diag(d[live]) @ np.linalg.inv(T[:, live])        # ψ_a = Σ_p α[a, p] t^p
    # t^p in the Lagrange basis: its nodal values (interpolation is exact on P_k)
    mono_in_lagrange = reference_nodes(k)[None, :] ** np.arange(len(live))[:, None]
    C[live] = alpha @ mono_in_lagrange
    C.flags.writeable = False
    return C


def dual_space(breakpoints, k: int, vanish_at_ends: bool) -> SegmentSpace:
    """The dual basis of W_h on ``breakpoints``: ``DUAL`` (vanish_at_ends) or ``DUAL-ALL``."""
    if not isinstance(k, (int, np.integer)) or k < 1:
        raise InputError("k", "an integer >= 1", got=k)
    base = make_space(breakpoints, k, True, vanish_at_ends)    # the numbering of W_h's nodes
    C = np.empty((base.n_intervals, k + 1, k + 1))
    for e, row in enumerate(base.dofs):
        live = np.flatnonzero(row >= 0)
        # an interval without a live node (one interval, k = 1, ends vanishing) has no dual function
        C[e] = local_dual_coefficients(k, live) if len(live) else 0.0
    return SegmentSpace(base.breakpoints, k, False, vanish_at_ends, base.dofs, base.dim, C)
