"""The parity bases of a face space's 1D factors and its sine coefficients in them.

Where both factors of a tensor space are symmetric under x → 1 − x their bases split into even
and odd functions (:func:`axis_parity`); the double sine series of the H Gram matrix is then
block diagonal in the four products of those bases (:mod:`infsup_contact.la.face_parity`, the
linear algebra of the blocks), whose coefficients come from the factors here
(:func:`partial_gram_blocks`).
"""
from __future__ import annotations

import numpy as np

from ....la import face_parity
from ....la.threaded import concurrent_map
from ...gamma.symmetry import induced_permutation, isotypic_bases, reflect
from ...segment.norms import sine_coefficients
from ...gamma.quadrature import gauss_legendre


def axis_parity(space) -> tuple | None:
    """(Q_e, Q_o) of a 1D space (:class:`~.multipliers.MultiplierSpace`) under x → 1 − x,
    checked at 4 Gauss points per interval, or None where the reflection does not map its basis."""
    t, _ = gauss_legendre(4)
    g = np.asarray(space.breakpoints, float)
    x = (0.5 * (g[:-1, None] + g[1:, None]) + 0.5 * (g[1:, None] - g[:-1, None]) * t).ravel()
    pi = induced_permutation(space, x, reflect())
    return None if pi is None else isotypic_bases((pi,))


def tensor_parities(space) -> tuple | None:
    """((Q^x_e, Q^x_o), (Q^y_e, Q^y_o)) of a tensor space, or None (a factor not symmetric or
    with an empty parity)."""
    out = tuple(axis_parity(f) for f in space.factors)
    if any(q is None or min(Q.shape[1] for Q in q) < 1 for q in out):
        return None
    return out


def partial_gram_blocks(space, n_max: int, parities, weights_on) -> list:
    """[S_c(n_max)], c = 0..3: the blocks T_cᵀ S(n_max) T_c of :func:`~.face_norms.partial_gram`
    (module text), the weights by ``weights_on(x_lo, x_hi)`` (the exponential sum on that range,
    :class:`~.face_norms.SeparableWeights`), one for the four blocks."""
    n = np.arange(1, n_max + 1, dtype=float)
    index = (n[0::2], n[1::2])                      # odd m for even functions, even m for odd ones
    # (dim_p, len(idx)) per factor and parity p, the four side by side (numpy's kernels and the
    # sparse product release the GIL: the same bits; k = 2, N = 48, n_max 4,608: 1.6-1.9x on two cores)
    jobs = [(f, Q, idx) for f, q in zip(space.factors, parities) for Q, idx in zip(q, index)]
    flat = concurrent_map(lambda job: job[1].T @ sine_coefficients(job[0], job[2]), jobs)
    coeffs = [flat[:len(index)], flat[len(index):]]
    return face_parity.parity_blocks(coeffs, index, weights_on)
