"""Symmetries of Γ acting on a multiplier basis: the permutation π with μ_j ∘ T = μ_π(j).

A map T of Γ onto itself that maps the cells of G_h onto cells (the point reflection of the
face, its transposition, the reflection of the segment) maps a symmetric construction's basis onto
itself. The permutation is found from the values at sample points and checked there; the callers
use it to split the face's H Gram series (:mod:`.face.symmetry`) and the large route's
pencils and kernel decisions (:mod:`infsup_contact.la.reflection`).
"""
from __future__ import annotations

import hashlib
import threading
import weakref

import numpy as np
import scipy.sparse as sp

from .coupling import weighted_values

MATCH_RTOL = 1e-10
"""Largest relative mismatch of μ_j ∘ T and μ_π(j) at the sample points."""


def reflect(axis: int | None = None):
    """The map x → 1 − x of coordinate ``axis`` of points (n, d), or of every coordinate (None:
    the point reflection of the face, the reflection of the segment); its ``key`` names it for
    :func:`induced_permutation`'s cache."""
    def transform(x):
        if axis is None:
            return 1.0 - x
        y = np.array(x, dtype=float)
        y[:, axis] = 1.0 - y[:, axis]
        return y
    transform.key = ("reflect", axis)
    return transform


def axis_reflections(space, x: np.ndarray) -> tuple | None:
    """(π_x, π_y) of the face's reflections x → 1 − x and y → 1 − y (checked at the points
    ``x``, (n, 2)), or None where either does not map the basis onto itself."""
    pis = tuple(induced_permutation(space, x, reflect(axis)) for axis in (0, 1))
    return None if any(pi is None for pi in pis) else pis


def induced_permutation(space, x: np.ndarray, transform) -> np.ndarray | None:
    """π with μ_j(T x) = μ_π(j)(x) at the points ``x`` (n × d), T = ``transform``, or None.

    π(j) is the function whose values at x are nearest to those of μ_j ∘ T among the functions
    whose supports meet its image (sparse overlaps); accepted only if π is an involution and
    the values agree to :data:`MATCH_RTOL`. Kept per space for a transform with a ``key``
    (:func:`reflect`'s) and the same points (read-only): a request's route, Grams and kernel
    decision ask for the same reflections (k = 2, N = 24: 82 calls, 49 distinct)."""
    key = getattr(transform, "key", None)
    if key is None:
        return _induced_permutation(space, x, transform)
    x = np.ascontiguousarray(x, dtype=float)
    key = (key, x.shape, hashlib.blake2b(x.tobytes(), digest_size=16).digest())
    with _CACHE_LOCK:
        kept = _cache_of(space)
        if key in kept:
            return kept[key]
    pi = _induced_permutation(space, x, transform)
    if pi is not None:
        pi.flags.writeable = False
    with _CACHE_LOCK:
        _cache_of(space)[key] = pi
    return pi


_CACHE: dict = {}
"""id(space) → (a weak reference to it, {key: π}), an entry dropped with its space."""
_CACHE_LOCK = threading.Lock()


def _cache_of(space) -> dict:
    entry = _CACHE.get(id(space))
    if entry is None or entry[0]() is not space:
        entry = (weakref.ref(space), {})
        _CACHE[id(space)] = entry
        weakref.finalize(space, _CACHE.pop, id(space), None)
    return entry[1]


def _induced_permutation(space, x: np.ndarray, transform) -> np.ndarray | None:
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


def group_elements(pis) -> list:
    """The permutations P_b, b = 0 .. 2^g − 1, of the group the commuting involutions
    π_1, ..., π_g generate: P_b = Π_{i ∈ b} π_i (bit i of b)."""
    out = [np.arange(pis[0].size)]
    for pi in pis:
        out += [pi[e] for e in out]
    return out


def isotypic_bases(pis) -> tuple:
    """Orthonormal bases (Q_0, ..., Q_{2^g − 1}) (sparse, m × m_c) of the isotypic components of
    commuting involutions π_1, ..., π_g of a basis: component c is where P_b acts as the character
    χ_c(b) = (−1)^{popcount(b & c)} (bit i of c set: odd under π_i). Its columns are the orbit
    sums Σ_b χ_c(b) e_{P_b(j)} / √|orbit| over the orbits whose stabilizer χ_c leaves fixed (the
    others sum to 0), ordered by orbit size (largest first), then by the orbit's smallest index.
    For g = 1: Q_0 = (e_j + e_π(j))/√2 and the fixed points e_j, Q_1 = (e_j − e_π(j))/√2."""
    P = np.array(group_elements(pis))                      # (2^g, m)
    order, m = P.shape
    reps = np.flatnonzero(P.min(axis=0) == np.arange(m))
    orbits = P[:, reps]                                   # (2^g, orbits): the images of each rep
    size = 1 + np.count_nonzero(np.diff(np.sort(orbits, axis=0), axis=0), axis=0)
    by_size = np.lexsort((reps, -size))
    orbits, size = orbits[:, by_size], size[by_size]
    columns = np.tile(np.arange(orbits.shape[1]), order)
    out = []
    for c in range(order):
        chi = np.array([(-1.0) ** bin(b & c).count("1") for b in range(order)])
        Q = sp.csc_matrix((np.repeat(chi, orbits.shape[1]), (orbits.ravel(), columns)), shape=(m, orbits.shape[1]))
        Q.sum_duplicates()
        Q.eliminate_zeros()
        live = np.flatnonzero(np.diff(Q.indptr))
        Q = Q[:, live]
        Q.data = np.sign(Q.data) * np.sqrt(1.0 / np.repeat(size[live], np.diff(Q.indptr)))
        out.append(Q.tocsr())
    return tuple(out)

