"""The worst mode of the pencil (4.5): the multiplier that comes closest to escaping the coupling.

β_h² is the smallest eigenvalue of S m = β² G m (:mod:`.infsup`); its eigenvector m is the worst
mode, and μ_h = Σ_j m_j μ_j the multiplier it stands for. Where the kernel of Bᵀ is not empty
(β_h = 0) the mode is a kernel vector from the kernel decision itself (:func:`~.routes.space_kernel`
asked for its vectors): the right singular vector of the smallest singular value of the scaled
coupling W, mapped back to multiplier coordinates. Elsewhere it is the eigenvector of the smallest
eigenvalue, from the route that solved the pencil: LAPACK on the dense route, the shift-invert
Lanczos of :func:`~infsup_contact.la.bottom.bottom_pencil` above
:data:`~infsup_contact.la.bottom.DENSE_MAX_M` (on the whole pencil also where the reflections split
it: one vector, not the components').

Nothing here runs unless a caller asks for modes (``beta --worst-mode``); β_h alone never computes
a vector.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy.linalg import lapack

from ..la import bottom

MODE_SAMPLES = 6
"""Subdivisions of each cell of G_h at which a mode is sampled (``gamma.sample``): sixths, so that
the centroids of triangles (thirds: the Kuhn triangles of a tensor grid, the P_6 lattice of a
triangulation) are sample points and a discontinuous P_0 mode is seen inside its cells."""


@dataclass(frozen=True)
class Mode:
    """The worst mode of one β row.

    Attributes
    ----------
    keys : dict
        The row's keys, in the table's column order: case, multiplier_mesh, c1, c2, norm for a
        request (:func:`worst_modes`); system, level, h, norm for a foreign system's level.
    beta : float
        The row's β_h.
    vector : ndarray, shape (dim M,)
        m, the coefficients of μ_h in the space's basis (Euclidean norm 1).
    in_kernel : bool
        Whether m is a kernel vector of Bᵀ (β_h = 0) rather than an eigenvector above it.
    space, gamma
        M_h and the interface it lives on (what :func:`mode_on_gamma` evaluates).
    size : tuple
        Γ's extent per coordinate where ``space`` lives on its pull-back to the unit interval or
        square (a foreign system's Γ of length L, or a × b); the sample points are scaled by it.
    """

    keys: dict
    beta: float
    vector: np.ndarray
    in_kernel: bool
    space: object
    gamma: object
    size: tuple = (1.0, 1.0)


def worst_modes(route, S: np.ndarray, rows: list, space, gamma) -> list:
    """The :class:`Mode` of each β row of one space and one S (its ``norm`` picks the Gram);
    ``multiplier_mesh`` is set by the caller (:func:`~.infsup.beta_table`)."""
    out = []
    for row in rows:
        vector, in_kernel = mode_vector(route, S, row["norm"])
        keys = {key: row[key] for key in ("case", "multiplier_mesh", "c1", "c2", "norm")}
        out.append(Mode(keys, row["beta"], vector, in_kernel, space, gamma))
    return out


def mode_vector(route, S: np.ndarray, norm: str) -> tuple:
    """(m, in_kernel): the worst mode of S m = β² G m on ``route`` (:class:`~.routes.Route`,
    chosen with ``vectors=True`` where its kernel is not empty) for the Gram of ``norm``."""
    kernel = route.kernel
    if kernel.dim:
        if kernel.vectors is None:
            raise ValueError("a kernel mode needs the kernel's vectors: choose the route with vectors=True")
        return _unit(kernel.vectors[:, 0]), True
    factors = getattr(route.factors, "whole", route.factors)  # a split route's: G's own factors
    L = factors[norm]
    if route.iterative:
        return _unit(bottom.bottom_pencil(S, L, 1, vectors=True).vectors[:, 0]), False
    return _unit(dense_bottom_vector(S, L)), False


def dense_bottom_vector(S: np.ndarray, L: np.ndarray) -> np.ndarray:
    """The eigenvector of the smallest eigenvalue of S x = λ G x, G = L Lᵀ (L from
    :func:`~.spectra.gram_factor`): the standard form C = L⁻¹ S L⁻ᵀ (LAPACK sygst, as the dense
    route's :func:`~.spectra.spectrum`), its bottom eigenvector y (syevr), x = L⁻ᵀ y."""
    C, info = lapack.dsygst(np.asarray(S, float), L, itype=1, lower=1)
    if info:
        raise np.linalg.LinAlgError(f"sygst failed (info {info})")
    _, y = sla.eigh(C, lower=True, subset_by_index=[0, 0], driver="evr")
    return sla.solve_triangular(L, y[:, 0], lower=True, trans="T")


def _unit(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, float).ravel()
    return v / np.linalg.norm(v)


def mode_on_gamma(mode: Mode, per_cell: int = MODE_SAMPLES) -> tuple:
    """(points, μ_h): the mode sampled on Γ (``gamma.sample`` of its G_h, scaled by ``mode.size``;
    shape (n,) on the segment, (n, 2) on the face) and μ_h = Σ_j m_j μ_j there (``space.evaluate``), normalized by
    :func:`normalized`."""
    x = mode.gamma.sample(mode.space.breakpoints, per_cell)
    mu = normalized(mode.space.evaluate(x) @ mode.vector)
    size = np.asarray(mode.size, float)
    return (x * size[0] if np.ndim(x) == 1 else x * size[:2]), mu


def normalized(values: np.ndarray) -> np.ndarray:
    """``values`` over its peak: max |μ_h| = 1, the largest entry +1. An eigenvector's sign and
    scale are arbitrary; the peak is the first sample point whose modulus is within
    :data:`PEAK_RTOL` of the largest, so that ties (a ±1 checkerboard) fall the same way whatever
    the round-off."""
    values = np.asarray(values, float)
    size = np.max(np.abs(values))
    if size == 0.0:
        raise ValueError("the mode vanishes at every sample point")
    peak = values[np.flatnonzero(np.abs(values) >= (1.0 - PEAK_RTOL) * size)[0]]
    return values / peak


PEAK_RTOL = 1e-8
"""Relative distance from max |μ_h| within which sample values tie for the peak (:func:`normalized`)."""
