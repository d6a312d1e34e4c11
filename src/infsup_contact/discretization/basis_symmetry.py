"""Symmetries of Γ acting on a multiplier basis: the permutation π with μ_j ∘ T = μ_π(j).

A map T of Γ onto itself that maps the cells of G_h onto cells (the point reflection of the
face, its transposition, the reflection of the segment) maps a symmetric construction's basis onto
itself. The permutation is found from the values at sample points and checked there; the callers
use it to split the face's H Gram series (:mod:`.face_triangle_symmetry`) and the large route's
pencils and kernel decisions (:mod:`infsup_contact.solvers.reflection`).
"""
from __future__ import annotations

import numpy as np

from .coupling import weighted_values

MATCH_RTOL = 1e-10
"""Largest relative mismatch of μ_j ∘ T and μ_π(j) at the sample points."""


def induced_permutation(space, x: np.ndarray, transform) -> np.ndarray | None:
    """π with μ_j(T x) = μ_π(j)(x) at the points ``x`` (n × d), T = ``transform``, or None.

    π(j) is the function whose values at x are nearest to those of μ_j ∘ T among the functions
    whose supports meet its image (sparse overlaps); accepted only if π is an involution and
    the values agree to :data:`MATCH_RTOL`."""
    ones = np.ones(len(x))
    A, B = weighted_values(space, x, ones), weighted_values(space, transform(x), ones)
    overlap = (B.T @ A).tocsr()
    overlap.sum_duplicates()
    if np.any(np.diff(overlap.indptr) == 0):
        return None
    norms = np.asarray(A.multiply(A).sum(axis=0)).ravel()
    row = np.repeat(np.arange(space.dim), np.diff(overlap.indptr))
    order = np.lexsort((norms[overlap.indices] - 2.0 * overlap.data, row))
    pi = overlap.indices[order[np.searchsorted(row[order], np.arange(space.dim))]]
    if np.unique(pi).size != space.dim or np.any(pi[pi] != np.arange(space.dim)):
        return None
    if abs(B - A[:, pi]).max() > MATCH_RTOL * np.abs(A.data).max():
        return None
    return pi
