"""Dual and transformed-dual mortar bases on the reference face elements (issue 28).

Standard dual basis (Wohlmuth, SIAM J. Numer. Anal. 38 (2000) 989–1012): with the element's
nodal basis N, the weights d_k = ∫ N_k, D = diag(d) and the mass matrix M_kl = ∫ N_k N_l,

    ψ = A N,   A = D M⁻¹,   so   ∫ ψ_i N_j = (D M⁻¹ M)_ij = δ_ij d_j          (biorthogonality)

and Σ_i ψ_i = 1 (M 1 = d, hence 1ᵀ A = dᵀ M⁻¹ = 1ᵀ). A needs d_k > 0: on QUAD8 the corner
weights are ∫ N_corner = −1/3 (of the area 4 of [−1, 1]²) and on TRI6 the vertex weights are
0, so their dual bases are refused (MOOSE #33558, libMesh PR #4536).

Transformed basis (Wohlmuth, Popp, Gee, Wall, Comput. Mech. 49 (2012) 735–747; Popp, Wohlmuth,
Gee, Wall, SIAM J. Sci. Comput. 34 (2012) B421–B446; the formulas below are those of 4C's
``Mortar::Element::shape_functions``, cases ``serendipity2D_modified`` / ``quad2D_modified`` /
``biquad2D_modified``): Ñ = T N with, for α ∈ [0, 1/2),

    Ñ_corner = N_corner + α Σ_{edge nodes m adjacent} N_m,    Ñ_m = (1 − 2α) N_m,

(QUAD9 as in 4C: each corner also takes α/2 · N_centre, Ñ_centre = (1 − 2α) N_centre; 4C
uses α = 0 there). Every edge node gives α to each of its two corners and keeps 1 − 2α, so
Σ Ñ = Σ N = 1; T is upper triangular in (corners | the rest) with diagonal 1 and 1 − 2α,
so det T = (1 − 2α)^(n_nodes − n_corners) ≠ 0 and span Ñ = span N for α < 1/2. The
transformed weights are d̃ = T d; the dual basis of Ñ is ψ̃ = Ã Ñ, Ã = D̃ M̃⁻¹, M̃ = T M Tᵀ.
4C uses α = 1/5 (:data:`POPP_ALPHA`).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ....errors import InputError
from .reference_elements import reference_element

POPP_ALPHA = 0.2
"""α = 1/5 of Popp et al. and 4C (continuity in mixed tet10 / hex20 meshes, 4C's comment)."""

SWEEP_ALPHAS = (0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 1.0 / 3.0, 0.4, 0.45)

ZERO_WEIGHT_RTOL = 1e-12
"""A weight ∫N_k at or below this times the reference area counts as non-positive (the TRI6
vertex weights are 0 to round-off): :func:`dual_coefficients` refuses the dual basis."""


def _check_alpha(alpha) -> float:
    try:
        a = float(alpha)
    except (TypeError, ValueError):
        raise InputError("alpha", "a number in [0, 1/2)", got=alpha) from None
    if not 0.0 <= a < 0.5:
        raise InputError("alpha", "a number in [0, 1/2) (T is singular at 1/2)", got=alpha)
    return a


def transformation(name: str, alpha: float = 0.0) -> np.ndarray:
    """T with Ñ = T N for element ``name`` (identity for QUAD4, TRI3 or α = 0)."""
    el, a = reference_element(name), _check_alpha(alpha)
    T = np.eye(el.n_nodes)
    for c0, c1, m in el.edges:
        T[[c0, c1], m] += a
        T[m, m] = 1.0 - 2.0 * a
    if name == "QUAD9":                                        # the centre node 8
        T[list(el.corners), 8] += 0.5 * a
        T[8, 8] = 1.0 - 2.0 * a
    return T


@lru_cache(maxsize=None)
def _moments(name: str) -> tuple[np.ndarray, np.ndarray]:
    """d = ∫ N and M = ∫ N Nᵀ on the reference cell, by a rule exact for the products."""
    el = reference_element(name)
    pts, w = el.quadrature(2 * el.total_degree)
    N = el.shapes(pts)
    d, M = N.T @ w, (N * w[:, None]).T @ N
    d.flags.writeable = M.flags.writeable = False
    return d, M


def weights(name: str, alpha: float = 0.0) -> np.ndarray:
    """d_k = ∫ Ñ_k over the reference cell, Ñ = T(α) N (α = 0: the plain ∫ N_k)."""
    return transformation(name, alpha) @ _moments(name)[0]


def weight_fractions(name: str, alpha: float = 0.0) -> np.ndarray:
    """:func:`weights` divided by the reference area (4 for quads, 1/2 for triangles)."""
    return weights(name, alpha) / reference_element(name).area


def mass_matrix(name: str, alpha: float = 0.0) -> np.ndarray:
    """M̃ = ∫ Ñ Ñᵀ = T M Tᵀ on the reference cell."""
    T = transformation(name, alpha)
    return T @ _moments(name)[1] @ T.T


def _raw_dual(name: str, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """(Ã, d̃) without the positivity check: Ã = D̃ M̃⁻¹."""
    d = weights(name, alpha)
    return np.diag(d) @ np.linalg.inv(mass_matrix(name, alpha)), d


def dual_coefficients(name: str, transformed: bool = False, alpha: float = POPP_ALPHA) -> np.ndarray:
    """A with ψ = A N (``transformed``: ψ̃ = Ã Ñ = Ã T N, returned as Ã T, i.e. in terms of N).

    Raises
    ------
    InputError
        If a weight ∫ N_k (or ∫ Ñ_k) is not positive: naming the element, the nodes and
        their weights, and the remedy ``transformed=True`` (with α where all are positive).
    """
    a = _check_alpha(alpha) if transformed else 0.0
    A, d = _raw_dual(name, a)
    bad = np.flatnonzero(d <= ZERO_WEIGHT_RTOL * reference_element(name).area)
    if len(bad):
        got = {int(k): round(float(d[k]), 12) for k in bad}
        fix = ("an alpha with all weights positive, e.g. the 4C alpha = 1/5" if transformed
               else "transformed=True, i.e. basis 'transformed_dual' (Popp et al., alpha = 1/5)")
        raise InputError("element", f"positive weights ∫N_k for a dual basis: {name} has "
                         f"non-positive ones at nodes {list(got)}; use {fix}", got={name: got})
    return A @ transformation(name, a)


def dual_shapes(name: str, points, transformed: bool = False, alpha: float = POPP_ALPHA) -> np.ndarray:
    """ψ (or ψ̃) at ``points`` (n, 2), shape (n, n_nodes)."""
    C = dual_coefficients(name, transformed, alpha)
    return reference_element(name).shapes(points) @ C.T


def alpha_sweep(name: str, alphas=SWEEP_ALPHAS) -> list[dict]:
    """Per α: the transformed weights, the smallest one, and cond₂(Ã) (inf if Ã is singular).

    Weights ≤ 0 are reported, not refused (the row says ``positive: False``).
    """
    rows = []
    for a in alphas:
        A, d = _raw_dual(name, _check_alpha(a))
        s = np.linalg.svd(A, compute_uv=False)
        cond = np.inf if s[-1] <= 1e-14 * s[0] else s[0] / s[-1]
        rows.append({"alpha": float(a), "weights": d, "min_weight": float(d.min()),
                     "min_fraction": float(d.min() / reference_element(name).area),
                     "cond": float(cond), "positive": bool(d.min() > 1e-12)})
    return rows
