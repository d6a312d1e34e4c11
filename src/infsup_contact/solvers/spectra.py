"""The pencil S m = β² G m of (4.5) solved on each route: its bottom, densely or by Lanczos.

β_h² is the smallest eigenvalue of the generalized symmetric eigenproblem
(B A⁻¹ Bᵀ) m = β² G m on the multiplier space (:mod:`.infsup`). Up to dim M =
:data:`~infsup_contact.la.bottom.DENSE_MAX_M` LAPACK solves it whole (:func:`spectrum`); above,
the kernel is deflated and the bottom comes from shift-invert Lanczos (:func:`bottom_spectra`,
:mod:`infsup_contact.la.bottom`), on the reflections' components where the space has a split
(:func:`split_spectra`, :mod:`infsup_contact.la.reflection`). Which route a space takes is
:func:`~.routes.choose_route`.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.linalg import lapack

from ..la import bottom, openblas, reflection
from ..la.threaded import concurrent_map
from .interface_operator import combine_terms
from .kernel import KernelDecision, gap_over_roundoff, kernel_from_gap


@dataclass(frozen=True)
class Spectrum:
    """Bottom of the spectrum of (B A⁻¹ Bᵀ) m = β² G m.

    Attributes
    ----------
    beta : float
        β_h = sqrt(smallest eigenvalue), clipped at 0; exactly 0 when a kernel decided from Bᵀ
        is passed in and is not empty (the smallest eigenvalue is round-off then).
    kernel_dim : int
        Dimension of the kernel: the :class:`~infsup_contact.solvers.kernel.KernelDecision`
        passed in, or else the pencil's own gap rule (:func:`kernel_from_gap`).
    smallest_nonzero : float
        sqrt of the first eigenvalue above the kernel (β above the kernel).
    gap : float
        That eigenvalue divided by the pencil's round-off level n ε λ_max (with no kernel:
        the smallest eigenvalue over it).
    bottom : ndarray
        The smallest eigenvalues β² (up to 8), ascending.
    """

    beta: float
    kernel_dim: int
    smallest_nonzero: float
    gap: float
    bottom: np.ndarray


def gram_factor(G: np.ndarray) -> np.ndarray:
    """Lower Cholesky factor of the Gram matrix G (LAPACK potrf, zeros above the diagonal: the
    large route's deflation and inverse use L whole), for :func:`spectrum`: one
    factorization serves every interface operator S paired with G (each (c1, c2), v1 = 0)."""
    L, info = openblas.potrf(np.asarray(G, float))  # without the GIL: blocks side by side
    if info:
        raise np.linalg.LinAlgError(f"the Gram matrix is not positive definite (potrf info {info})")
    return L


def spectrum(S: np.ndarray, G: np.ndarray | None = None, *, factor: np.ndarray | None = None,
             kernel: KernelDecision | None = None) -> Spectrum:
    """Solve S m = β² G m densely and summarize its bottom.

    The steps of LAPACK's dsygvd (``scipy.linalg.eigh(S, G)``): G = L Lᵀ (potrf), the
    standard form L⁻¹ S L⁻ᵀ (sygst), its eigenvalues (syevd), bitwise the same as eigh;
    ``factor`` (:func:`gram_factor` of G) skips the first step when G's factor is known.
    ``kernel``: the kernel decided from Bᵀ (:func:`coupling_kernel`, the reported one);
    without it the pencil's gap rule decides (:func:`kernel_from_gap`).
    """
    return _summary(_eigenvalues(S, gram_factor(G) if factor is None else factor), kernel)


def _eigenvalues(S: np.ndarray, L: np.ndarray) -> np.ndarray:
    """All eigenvalues of S x = λ L Lᵀ x, ascending (sygst, syevd: :func:`spectrum`)."""
    C, info = lapack.dsygst(np.asarray(S, float), L, itype=1, lower=1)
    if info:
        raise np.linalg.LinAlgError(f"sygst failed (info {info})")
    ev, _, info = lapack.dsyevd(C, compute_v=0, lower=1)
    if info:
        raise np.linalg.LinAlgError(f"the eigenvalues did not converge (syevd info {info})")
    return ev


def _summary(ev: np.ndarray, kernel: KernelDecision | None) -> Spectrum:
    """The :class:`Spectrum` of a whole ascending spectrum ``ev`` (:func:`spectrum`)."""
    beta = float(np.sqrt(max(ev[0], 0.0)))
    if kernel is None:
        d, gap = kernel_from_gap(ev)
    else:
        # a kernel decided from Bᵀ makes β_h = 0 exactly; the pencil's smallest eigenvalue
        # is then round-off, and its digits differ between BLAS kernels
        d, gap = kernel.dim, gap_over_roundoff(ev, kernel.dim)
        beta = 0.0 if d > 0 else beta
    above = ev[d] if d < len(ev) else np.nan
    return Spectrum(beta, d, float(np.sqrt(max(above, 0.0))), gap, ev[:8].copy())


N_BOTTOM = 1
"""Eigenvalues above the kernel the iterative route computes: λ_{d+1}, all a β row reports
(``Spectrum.bottom`` holds the d kernel zeros and it); Lanczos needs 2.4× the products for 8."""


def bottom_spectrum(S: np.ndarray, factor: np.ndarray, kernel: KernelDecision | None = None,
                    s_factor: np.ndarray | None = None) -> Spectrum:
    """:func:`spectrum` without a dense eigensolver (dim M > :data:`~infsup_contact.la.bottom.DENSE_MAX_M`).

    The kernel (its dimension d and its basis ``kernel.vectors`` in multiplier coordinates, from
    :func:`~.routes.space_kernel` with ``iterative``) is deflated and the :data:`N_BOTTOM` eigenvalues
    above it come from shift-invert Lanczos (:func:`~infsup_contact.la.bottom.bottom_pencil`); λ_max for the
    round-off level from Lanczos too. ``bottom`` holds the d kernel eigenvalues as exact zeros
    (a kernel of Bᵀ is one of S), then those. Without ``kernel``, the smallest eigenvalue
    (β with v1 = 0), 0 when at round-off level. ``s_factor``: the Cholesky factor of S
    (:func:`~infsup_contact.la.bottom.definite_factor`) where no kernel is deflated, shared by the norms
    (:func:`bottom_spectra`).
    """
    d = 0 if kernel is None else kernel.dim
    Z = None if kernel is None else kernel.vectors
    if d and (Z is None or Z.shape[1] != d):
        raise ValueError(f"a kernel of dimension {d} needs its basis (kernel.vectors, m × {d}) to be deflated")
    res = bottom.bottom_pencil(S, factor, N_BOTTOM, Z if d else None, s_factor=None if d else s_factor)
    return _spectrum_above(S.shape[0], d, res.values, res.lam_max)


def _spectrum_above(m: int, d: int, values: np.ndarray, lam_max: float) -> Spectrum:
    """The :class:`Spectrum` of an order-m pencil from its d kernel zeros, the eigenvalues
    ``values`` above them (ascending) and λ_max (:func:`bottom_spectrum`, :func:`split_spectra`)."""
    ev = np.concatenate([np.zeros(d), values])
    lam = float(values[0])
    eta = m * np.finfo(float).eps * lam_max  # the pencil's round-off level, as dense
    gap = float(max(lam, 0.0) / eta) if eta > 0 else np.inf
    lam = lam if lam > eta else 0.0  # an eigenvalue at round-off (a singular S, no kernel given) is 0
    beta = 0.0 if d else float(np.sqrt(max(lam, 0.0)))
    return Spectrum(beta, d, float(np.sqrt(max(lam, 0.0))), gap, ev[:8].copy())


def dense_split_spectra(split, S: np.ndarray, factors: dict, kernel: KernelDecision | None = None) -> dict | None:
    """:func:`spectrum` of every norm from the components' pencils of a reflection-invariant S
    (:mod:`infsup_contact.la.reflection`): the whole spectrum is the union of the blocks'
    (spec(S, G) = ∪_c spec(Q_cᵀ S Q_c, Q_cᵀ G Q_c)), each block's by the same LAPACK steps, so the
    summary (kernel count, gap, β) is that of the whole pencil, at (1/c)³ of its cost per block.
    ``factors`` {norm: (L_0, L_1, ...)} of G's blocks. None where S is not invariant to
    :data:`~infsup_contact.la.reflection.INVARIANCE_RTOL` (the caller solves it whole); dropping
    the round-off blocks moves each eigenvalue by at most their norm (Weyl)."""
    *blocks, distance = split.blocks(S)
    if distance > reflection.INVARIANCE_RTOL:
        return None
    out = {}
    for norm, Ls in factors.items():
        ev = np.sort(np.concatenate([_eigenvalues(Sb, Lb) for Sb, Lb in zip(blocks, Ls) if len(Sb)]))
        out[norm] = _summary(ev, kernel)
    return out


def split_spectra(split, S: np.ndarray, factors: dict, kernel: KernelDecision | None = None,
                  parts=None) -> dict:
    """:func:`bottom_spectra` on the components of a reflection-invariant pencil
    (:mod:`infsup_contact.la.reflection`): ``factors`` {norm: (L_0, L_1, ...)} of the blocks of G, ``parts`` the
    kernel's bases per component (:meth:`~infsup_contact.la.reflection.ReflectionSplit.components`). None where S is
    not reflection invariant (the caller solves it unsplit)."""
    d = 0 if kernel is None else kernel.dim
    pencils = reflection.split_pencils(split, S, factors, parts if d else None, N_BOTTOM)
    if pencils is None:
        return None
    return {norm: _spectrum_above(S.shape[0], d, values, top) for norm, (values, top) in pencils.items()}


def large_spectra(S: np.ndarray, factors, kernel: KernelDecision | None = None, split=None, parts=None) -> dict:
    """The large route's spectra of S for every norm: :func:`split_spectra` where the space has a
    reflection split (``factors`` a :class:`SplitFactors`) and S is invariant, else :func:`bottom_spectra`
    (``factors`` {norm: factor}, or the split space's whole factors, made on demand)."""
    if split is None:
        return bottom_spectra(S, factors, kernel)
    return split_spectra(split, S, factors.split, kernel, parts) or bottom_spectra(S, factors.whole, kernel)


def bottom_spectra(S: np.ndarray, factors: dict, kernel: KernelDecision | None = None) -> dict:
    """:func:`bottom_spectrum` of S with each Gram factor in ``factors`` ({norm: factor}).

    Where no kernel is deflated, the shift-invert operator of every norm factors S itself
    (:func:`~infsup_contact.la.bottom.bottom_pencil`): one Cholesky factorization serves them all (where S is not
    numerically definite each pencil falls back to its own floored factorization)."""
    shared = bottom.definite_factor(S) if kernel is None or not kernel.dim else None
    return {norm: bottom_spectrum(S, L, kernel, s_factor=shared) for norm, L in factors.items()}


def betas_v1_zero(terms, factors: dict, kernel: KernelDecision, iterative: bool, split=None) -> dict:
    """β with v1 = 0 at c2 = 1, for each Gram factor ({norm: factor}): the sup over (0, v2)
    only, (5.10), i.e. the pencil of B_2 X_2 B_2ᵀ alone; at other c2 it is this / sqrt(c2).

    On the large route (``iterative``) with a non-empty kernel of Bᵀ it is 0 as a consequence,
    not a computation: a kernel vector of Bᵀ is one of B_2ᵀ, hence of B_2 X_2 B_2ᵀ, so
    β(v1 = 0) <= β_h = 0 (the sup over a subset). The dense route still computes it there (the
    square root of a round-off eigenvalue, not exactly 0). ``split``: the reflections' split,
    ``factors`` then a :class:`SplitFactors` (the blocks', and the whole Gram's on demand)."""
    if iterative and kernel.dim:
        return {norm: 0.0 for norm in factors}
    S2 = combine_terms(terms[1:], (1.0,))
    if iterative:
        return {norm: sp_.beta for norm, sp_ in large_spectra(S2, factors, None, split).items()}
    if split is not None:  # the dense route in the reflections' blocks (:func:`dense_split_spectra`)
        out = dense_split_spectra(split, S2, factors.split)
        if out is not None:
            return {norm: sp_.beta for norm, sp_ in out.items()}
        factors = factors.whole
    return {norm: spectrum(S2, factor=L).beta for norm, L in factors.items()}


class SplitFactors:
    """The Gram factors of a split space: ``split`` {norm: (L_0, L_1, ...)} of the blocks, ``whole``
    {norm: L} of G itself, made on first use (an S that is not invariant is solved unsplit)."""

    def __init__(self, grams: dict, halves: dict):
        self._grams = grams
        # every block of every norm side by side (LAPACK potrf by la/openblas.py, GIL-free, one BLAS thread each:
        # the same bits; k = 2, N = 48: 8 factorizations of order ~2,350 a space)
        keys = [(norm, b) for norm, hs in halves.items() for b in range(len(hs))]
        factors = dict(zip(keys, concurrent_map(lambda key: gram_factor(halves[key[0]][key[1]]), keys)))
        self.split = {norm: tuple(factors[norm, b] for b in range(len(hs))) for norm, hs in halves.items()}

    @cached_property
    def whole(self) -> dict:
        return {norm: gram_factor(G) for norm, (G, _) in self._grams.items()}

    def __iter__(self):
        return iter(self.split)
