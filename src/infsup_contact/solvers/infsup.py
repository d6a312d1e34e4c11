"""The discrete inf-sup constant β_h of (4.5)/(5.9) and the bottom of its spectrum.

β_h = inf_μ sup_v b(v, μ) / (‖v‖_a ‖μ‖_M), so β_h² is the smallest eigenvalue of the
generalized symmetric eigenproblem (B A⁻¹ Bᵀ) m = β² G m on the multiplier space,
with B A⁻¹ Bᵀ the interface operator (:mod:`infsup_contact.models.schur`) and G the Gram
matrix of the multiplier norm. Partitions, spaces and Gram matrices come from Γ, the
interface the sides' traces live on (``trace.gamma``,
:mod:`infsup_contact.discretization.gamma.interface`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg import lapack

from ..discretization.segment import meshes, multipliers
from ..discretization.spaces import registry
from ..discretization.spaces.spec import SpaceSpec
from ..discretization.gamma.coupling import coupling_matrix, trace_l2_norms
from ..errors import InputError, check_prestress
from . import bottom, reflection
from ..models.schur import combine_terms, interface_terms
from ..models import DEFAULT_MODEL
from ..models.side_cache import SideCache
from ..discretization.gamma.interface import check_choice
from ..discretization.segment.interface import SEGMENT
from ..discretization.segment.norms import NORMS
from .kernel import (GAP_DECADES, KERNEL_CRITERION, KernelDecision, bottom_kernel, coupling_kernel,  # noqa: F401
                     gap_over_roundoff, kernel_check, kernel_from_gap, scaled_couplings)

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
    L, info = lapack.dpotrf(np.asarray(G, float), lower=1, clean=1)
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
    L = gram_factor(G) if factor is None else factor
    C, info = lapack.dsygst(np.asarray(S, float), L, itype=1, lower=1)
    if info:
        raise np.linalg.LinAlgError(f"sygst failed (info {info})")
    ev, _, info = lapack.dsyevd(C, compute_v=0, lower=1)
    if info:
        raise np.linalg.LinAlgError(f"the eigenvalues did not converge (syevd info {info})")
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
    """:func:`spectrum` without a dense eigensolver (dim M > :data:`.bottom.DENSE_MAX_M`).

    The kernel (its dimension d and its basis ``kernel.vectors`` in multiplier coordinates, from
    :func:`space_kernel` with ``iterative``) is deflated and the :data:`N_BOTTOM` eigenvalues
    above it come from shift-invert Lanczos (:func:`.bottom.bottom_pencil`); λ_max for the
    round-off level from Lanczos too. ``bottom`` holds the d kernel eigenvalues as exact zeros
    (a kernel of Bᵀ is one of S), then those. Without ``kernel``, the smallest eigenvalue
    (β with v1 = 0), 0 when at round-off level. ``s_factor``: the Cholesky factor of S
    (:func:`.bottom.definite_factor`) where no kernel is deflated, shared by the norms
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


def split_spectra(split, S: np.ndarray, factors: dict, kernel: KernelDecision | None = None,
                  parts=None) -> dict:
    """:func:`bottom_spectra` on the components of a reflection-invariant pencil
    (:mod:`.reflection`): ``factors`` {norm: (L_0, L_1, ...)} of the blocks of G, ``parts`` the
    kernel's bases per component (:meth:`~.reflection.ReflectionSplit.components`). None where S is
    not reflection invariant (the caller solves it unsplit)."""
    d = 0 if kernel is None else kernel.dim
    pencils = reflection.split_pencils(split, S, factors, parts if d else None, N_BOTTOM)
    if pencils is None:
        return None
    return {norm: _spectrum_above(S.shape[0], d, values, top) for norm, (values, top) in pencils.items()}


def large_spectra(S: np.ndarray, factors, kernel: KernelDecision | None = None, split=None, parts=None) -> dict:
    """The large route's spectra of S for every norm: :func:`split_spectra` where the space has a
    reflection split (``factors`` a :class:`_Factors`) and S is invariant, else :func:`bottom_spectra`
    (``factors`` {norm: factor}, or the split space's whole factors, made on demand)."""
    if split is None:
        return bottom_spectra(S, factors, kernel)
    return split_spectra(split, S, factors.split, kernel, parts) or bottom_spectra(S, factors.whole, kernel)


def bottom_spectra(S: np.ndarray, factors: dict, kernel: KernelDecision | None = None) -> dict:
    """:func:`bottom_spectrum` of S with each Gram factor in ``factors`` ({norm: factor}).

    Where no kernel is deflated, the shift-invert operator of every norm factors S itself
    (:func:`.bottom.bottom_pencil`): one Cholesky factorization serves them all (where S is not
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
    ``factors`` then a :class:`_Factors` (the blocks', and the whole Gram's on demand)."""
    if iterative and kernel.dim:
        return {norm: 0.0 for norm in factors}
    S2 = combine_terms(terms[1:], (1.0,))
    if iterative:
        return {norm: sp_.beta for norm, sp_ in large_spectra(S2, factors, None, split).items()}
    return {norm: spectrum(S2, factor=L).beta for norm, L in factors.items()}


def check_inputs(case, k, family, n1, n2, c1, c2, norm, multiplier_mesh) -> None:
    """Validate a β_h request; raises :class:`InputError` naming the offending key."""
    if not isinstance(k, (int, np.integer)) or not 1 <= k <= 4:
        raise InputError("k", "an integer in 1..4", got=k)
    for c in case:
        registry.check_case(c, k)
    meshes.check_mesh_args(family, n1, "N1")
    meshes.check_mesh_args(family, n2, "N2")
    for key, c in (("c1", c1), ("c2", c2)):
        check_prestress(key, c)
    for nm in norm:
        if nm not in NORMS:
            raise InputError("norm", ", ".join(NORMS), got=nm)
    check_choice(multiplier_mesh)
    registry.check_pair_spaces(case, k, n1, n2, (multiplier_mesh,))  # dim M_h = 0: refused here


def _space(case, k, partition, gamma=SEGMENT):
    """A named case on G_h = ``partition`` of ``gamma``, an unregistered
    :class:`~infsup_contact.discretization.spaces.spec.SpaceSpec` (a study's variant, e.g. the α
    sweep of study/face_alpha.py), or a general triple ``(label, s, continuous, vanish)``
    (eqs. 5.3, 5.5; spaces of the segment)."""
    if isinstance(case, str):
        return registry.case_space(case, k, partition, gamma)
    if isinstance(case, SpaceSpec):
        return gamma.space(case, k, partition)
    _, s, continuous, vanish = case
    return multipliers.make_space(partition, s, continuous, vanish)


def beta_rows(family, k, n1, n2, cases=None, multiplier_mesh="omega2",
              c1=1.0, c2=1.0, norms=NORMS, h_route="logkernel", model=DEFAULT_MODEL, side_cache=None,
              **mesh_kwargs):
    """β_h for several cases and norms on one mesh pair, reusing the interface operator.

    ``cases`` are registry ids (default: every registered space defined for k) or general
    triples (see :func:`_space`); ``model`` gives the side operators (the model seam,
    :mod:`infsup_contact.models.contract`); ``side_cache`` as in :func:`beta_rows_all`.

    Returns
    -------
    list of dict
        One row per (case, norm) with the columns of ``infsup-contact beta``.
    """
    return beta_rows_all(family, k, n1, n2, cases, (multiplier_mesh,), ((c1, c2),), norms,
                         h_route=h_route, model=model, side_cache=side_cache, **mesh_kwargs)


def beta_rows_all(family, k, n1, n2, cases=None, multiplier_meshes=("omega2",), c_pairs=((1.0, 1.0),),
                  norms=NORMS, h_route="logkernel", model=DEFAULT_MODEL, side_cache=None, **mesh_kwargs):
    """:func:`beta_rows` for several multiplier meshes and prestress pairs at once.

    The meshes and the side factorizations are built once per mesh pair, the couplings and
    the Gram matrices once per (multiplier mesh, case, norm), and only the interface
    operator Σ c_i⁻¹ B_i X_i B_iᵀ and the eigenproblem per (c1, c2). Rows in the order
    multiplier mesh, case, c pair, norm.

    A multiplier mesh whose partition G_h equals an earlier one's (on matching meshes the
    traces of Ω1 and Ω2 and their union usually coincide) defines the same spaces, hence the
    same numbers: its rows are copies of the earlier ones, with their own ``multiplier_mesh``
    and zero timings.

    ``side_cache``: a :class:`~infsup_contact.models.side_cache.SideCache` the side operators
    are taken from (a sweep over pairs that share a side builds it once); default: built here.

    Timing columns (seconds): ``t_interface`` getting the two side operators (meshes and
    factorizations; about 0 for sides the cache already holds), ``t_assemble`` the case's
    couplings B_i, ``t_eig`` one eigenproblem (sygst and syevd; not the Gram matrix's
    Cholesky factor, which the c pairs share; above :data:`.bottom.DENSE_MAX_M` the norms'
    share of :func:`bottom_spectra`).
    """
    cases = registry.ids_valid_for(k) if cases is None else list(cases)
    for mm in multiplier_meshes:
        for c1, c2 in c_pairs:
            check_inputs([c for c in cases if isinstance(c, str)], k, family, n1, n2, c1, c2, norms, mm)
    t1 = time.perf_counter()
    sides = (SideCache() if side_cache is None else side_cache).pair(model, family, k, n1, n2, **mesh_kwargs)
    t2 = time.perf_counter()
    gamma = sides[0].trace.gamma
    p1, p2 = (s.trace.partition for s in sides)
    dim_w = gamma.trace_sum_dimension(k, p1, p2)
    trace_norms = [trace_l2_norms(s.trace, k) for s in sides]  # the kernel decisions' row scaling
    rows, by_partition = [], {}
    with gamma.gram_session():  # spaces on one G_h may share their Grams' series
        for multiplier_mesh in multiplier_meshes:
            g_h = gamma.multiplier_partition(p1, p2, multiplier_mesh)
            same = by_partition.get(gamma.partition_key(g_h))
            if same is not None:
                rows += [dict(r, multiplier_mesh=multiplier_mesh, t_assemble=0.0, t_interface=0.0, t_eig=0.0)
                         for r in same]
                continue
            first = len(rows)
            for case in cases:
                space = _space(case, k, g_h, gamma)
                tc = time.perf_counter()
                iterative = space.dim > bottom.DENSE_MAX_M  # the large route: sparse B, no dense eigensolver
                couplings = [coupling_matrix(s.trace, space, k, sparse=iterative) for s in sides]
                t_coupling = time.perf_counter() - tc
                grams = {norm: gamma.gram(space, norm, h_route=h_route) for norm in norms}
                structural = gamma.proven_kernel(space, k, [s.trace for s in sides], dim_w)
                split = reflection.split_of(space, gamma, g_h, k) if iterative else None
                kernel = space_kernel(couplings, sides, space, k, structural,
                                      grams["L2"][0] if "L2" in grams else None, iterative=iterative,
                                      trace_norms=trace_norms, split=split)
                terms = interface_terms(couplings, sides)
                split, parts, halves = reflection.usable(split, grams, kernel)
                factors = (_Factors(grams, halves) if split is not None
                           else {norm: gram_factor(G) for norm, (G, _) in grams.items()})
                beta_v1_zero_c1 = betas_v1_zero(terms, factors, kernel, iterative, split)
                for c1, c2 in c_pairs:
                    S = combine_terms(terms, (c1, c2))
                    if iterative:  # the norms' pencils share work: each row gets an equal share of the time
                        te = time.perf_counter()
                        spectra = large_spectra(S, factors, kernel, split, parts)
                        t_shared = (time.perf_counter() - te) / len(norms)
                    for norm in norms:
                        te = time.perf_counter()
                        info = grams[norm][1]
                        sp_ = spectra[norm] if iterative else spectrum(S, factor=factors[norm], kernel=kernel)
                        beta_v1_zero = beta_v1_zero_c1[norm] / np.sqrt(c2)
                        rows.append(dict(
                            case=registry.case_name(case), k=k, family=family, N1=n1, N2=n2,
                            multiplier_mesh=multiplier_mesh, c1=c1, c2=c2, norm=norm, beta=sp_.beta,
                            kernel_dim=sp_.kernel_dim, structural_kernel_dim=structural,
                            kernel_detected=kernel.detected, kernel_margin_decades=kernel.margin_decades,
                            kernel_decision=kernel.decision,
                            kernel_check=kernel_check(kernel.numerical, structural), gap_over_roundoff=sp_.gap,
                            smallest_nonzero=sp_.smallest_nonzero, beta_v1_zero=beta_v1_zero,
                            dim_M=space.dim, dim_W=dim_w,
                            n_max=info["n_max"], nmax_rel_error=info["nmax_rel_error"],
                            ndof=sum(s.ndof for s in sides), t_assemble=t_coupling,
                            t_interface=t2 - t1,
                            t_eig=t_shared if iterative else time.perf_counter() - te))
            by_partition[gamma.partition_key(g_h)] = rows[first:]
    return rows


class _Factors:
    """The Gram factors of a split space: ``split`` {norm: (L_0, L_1, ...)} of the blocks, ``whole``
    {norm: L} of G itself, made on first use (an S that is not invariant is solved unsplit)."""

    def __init__(self, grams: dict, halves: dict):
        self._grams = grams
        self.split = {norm: tuple(gram_factor(h) for h in hs) for norm, hs in halves.items()}

    @cached_property
    def whole(self) -> dict:
        return {norm: gram_factor(G) for norm, (G, _) in self._grams.items()}

    def __iter__(self):
        return iter(self.split)


def space_kernel(couplings, sides, space, k: int, structural: int, l2_gram=None,
                 iterative: bool = False, trace_norms=None, split=None) -> KernelDecision:
    """The kernel of Bᵀ on ``space`` (:func:`~infsup_contact.solvers.kernel.coupling_kernel`):
    the couplings scaled by the L²(Γ) norms of the sides' trace basis functions and of the
    multiplier basis functions (the diagonal of the L² Gram matrix, computed if not given);
    ``structural`` = max(dim M − dim(W1 + W2), 0) is its proven part. One decision serves
    every norm and every (c1, c2): the kernel of B A⁻¹ Bᵀ depends on neither.

    ``iterative``: the bottom singular values only
    (:func:`~infsup_contact.solvers.kernel.bottom_kernel`, for dim M > :data:`.bottom.DENSE_MAX_M`),
    W' from a rule :data:`LONGER_RULE_LARGE` longer, the couplings sparse (W sparse, the same
    entries); its ``vectors`` are returned in multiplier coordinates (a basis of the kernel of Bᵀ).
    ``trace_norms``: the sides' :func:`~.coupling.trace_l2_norms`, if already computed (they
    depend on the sides only, not on the space). ``split``: the reflections'
    (:func:`.reflection.split_bottom_kernel` decides on the components where it holds)."""
    G = sides[0].trace.gamma.gram(space, "L2")[0] if l2_gram is None else l2_gram
    rows = [trace_l2_norms(s.trace, k) for s in sides] if trace_norms is None else trace_norms
    cols = np.sqrt(np.diag(G))
    W = scaled_couplings(couplings, rows, cols)
    extra = LONGER_RULE_LARGE if iterative else LONGER_RULE
    longer = scaled_couplings([coupling_matrix(s.trace, space, k, extra_degree=extra, sparse=iterative)
                               for s in sides], rows, cols)
    if not iterative:
        return coupling_kernel(W, structural, entry_error=np.linalg.norm(W - longer))
    W, error = sp.csr_matrix(W), spla.norm(sp.csr_matrix(W - longer))
    decision = reflection.split_bottom_kernel(W, split, structural, error) if split is not None else None
    decision = bottom_kernel(W, structural, entry_error=error) if decision is None else decision
    return replace(decision, vectors=decision.vectors / cols[:, None])  # W v = 0 ⇔ Bᵀ (v / cols) = 0


LONGER_RULE = 6
"""Degree the entry-round-off rule W' of :func:`space_kernel` adds (three Gauss points more)."""
LONGER_RULE_LARGE = 2
"""The same above dim M = :data:`.bottom.DENSE_MAX_M` (one point more, 16 instead of 36 points
per cell at k = s = 2: still exact, so W − W' is still round-off only; half the cost)."""


def saddle_point_beta(A: sp.spmatrix, B: np.ndarray, G: np.ndarray) -> float:
    """β_h from the full pencil, the independent route: [[A, Bᵀ], [B, 0]] x = σ [[A, 0], [0, G]] x.

    Eliminating u gives B A⁻¹ Bᵀ m = σ(σ − 1) G m, so every β² ≥ 0 appears as the root
    σ = (1 − sqrt(1 + 4β²))/2 ≤ 0 (kernel modes at σ = 0); the other eigenvalues are ≥ 1.
    Dense; for small meshes (tests and the benchmark's dense route).
    """
    A = A.toarray() if sp.issparse(A) else np.asarray(A)
    n, m = A.shape[0], B.shape[0]
    lhs = np.block([[A, B.T], [B, np.zeros((m, m))]])
    rhs = np.block([[A, np.zeros((n, m))], [np.zeros((m, n)), G]])
    sigma = sla.eigh(lhs, rhs, eigvals_only=True)
    low = sigma[sigma < 0.5]
    return float(np.sqrt(max(np.min(low * (low - 1.0)), 0.0)))
