"""The discrete inf-sup constant β_h of (4.5)/(5.9) for a request (:mod:`.request`).

β_h = inf_μ sup_v b(v, μ) / (‖v‖_a ‖μ‖_M), so β_h² is the smallest eigenvalue of the
generalized symmetric eigenproblem (B A⁻¹ Bᵀ) m = β² G m on the multiplier space, with
B A⁻¹ Bᵀ = Σ_i B_i X_i B_iᵀ / c_i the interface operator (:mod:`.interface_operator`, X_i from
the sides' Schur complements, :mod:`infsup_contact.la.schur`) and G the Gram matrix of the
multiplier norm. Partitions, spaces and Gram matrices come from Γ, the interface the sides'
traces live on (``trace.gamma``, :mod:`infsup_contact.discretization.gamma.interface`). How each
space's pencil is solved is its route (:func:`~.routes.choose_route`, the fast layer
:mod:`infsup_contact.la` behind it); the request was validated when it was built.
"""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..discretization.segment import multipliers

from ..discretization.spaces import registry
from ..discretization.spaces.spec import SpaceSpec
from ..discretization.gamma.coupling import coupling_matrices, trace_l2_norms
from ..discretization.segment.norms import NORMS
from ..models import DEFAULT_MODEL
from .. import progress
from .interface_operator import combine_terms, interface_terms
from .kernel import kernel_check
from .modes import worst_modes
from . import petrov_galerkin, side_by_side
from .request import NO_OPTIONS, BetaRequest, MeshOptions
from .routes import choose_route, is_large
from .side_cache import GramCache, SideCache


def beta_table(request: BetaRequest, side_cache: SideCache | None = None, modes: list | None = None) -> list:
    """β_h of (4.5) for every case, multiplier mesh, (c1, c2) and norm of a validated ``request``.

    The sides (meshes, factorizations) are built once, the couplings B_i and Gram matrices G once
    per (G_h, case), the interface operator S = Σ_i B_i X_i B_iᵀ / c_i and its pencil
    S m = β² G m per (c1, c2). A multiplier mesh whose G_h equals an earlier one's (matching meshes:
    the traces of Ω1, Ω2 and their union coincide) defines the same spaces: its rows are copies,
    with their own ``multiplier_mesh`` and zero timings. ``side_cache``: a
    :class:`~.side_cache.SideCache` shared by a sweep's pairs (default: built here).

    Rows in the order multiplier mesh, case, c pair, norm. Timing columns (seconds):
    ``t_interface`` the two sides, ``t_assemble`` the case's couplings, ``t_eig`` one eigenproblem
    (above :data:`~infsup_contact.la.bottom.DENSE_MAX_M`: the norms' share, :meth:`.routes.Route.spectra`).

    ``modes``: a list that receives the worst mode of every row, in the rows' order
    (:class:`~.modes.Mode`); None (the default) computes no vector.
    """
    r = request
    t0 = time.perf_counter()
    cache = SideCache() if side_cache is None else side_cache
    progress.note("the two sides")
    with progress.phase("sides: mesh, assembly, factorization"):
        sides = cache.pair(r.model, r.family, r.k, r.n1, r.n2, r.mesh, r.gamma, checked=True)  # Ω1, Ω2 with Γ last
    t_sides = time.perf_counter() - t0
    gamma = sides[0].trace.gamma
    p1, p2 = (s.trace.partition for s in sides)
    dim_w = gamma.trace_sum_dimension(r.k, p1, p2)                                  # dim(W1 + W2)
    trace_norms = [_trace_norms(s.trace, r.k) for s in sides]
    rows, by_partition = [], {}
    with gamma.gram_session():  # spaces on one G_h may share their Grams' series
        for multiplier_mesh in progress.steps(r.multiplier_meshes, "multiplier mesh") \
                if len(r.multiplier_meshes) > 1 else r.multiplier_meshes:
            g_h = gamma.multiplier_partition(p1, p2, multiplier_mesh)               # G_h
            key = gamma.partition_key(g_h)
            if key in by_partition:
                rows += [dict(row, multiplier_mesh=multiplier_mesh, t_assemble=0.0, t_interface=0.0, t_eig=0.0)
                         for row in by_partition[key][0]]
                if modes is not None:
                    modes += [replace(m, keys={**m.keys, "multiplier_mesh": multiplier_mesh}) for m in by_partition[key][1]]
                continue
            per_case = side_by_side.rows_by_case(  # two spaces at a time where the cores and memory allow
                r.cases, lambda case: _case_rows_and_modes(r, case, g_h, sides, dim_w, trace_norms,
                                                           modes is not None, cache.grams),
                dim_w, registry.case_name, python_bound=gamma.dim == 2,  # a face's spaces: the GIL binds
                series=lambda case: _series_key(case, r.k, g_h, gamma))
            found = None if modes is None else [m for _, case_modes in per_case for m in case_modes]
            by_partition[key] = ([row for case_rows, _ in per_case for row in case_rows], found)
            if modes is not None:
                modes += [replace(m, keys={**m.keys, "multiplier_mesh": multiplier_mesh}) for m in found]
            rows += [dict(row, multiplier_mesh=multiplier_mesh, t_interface=t_sides) for row in by_partition[key][0]]
    return rows


def _case_rows_and_modes(r: BetaRequest, case, g_h, sides, dim_w: int, trace_norms, vectors: bool,
                         grams: GramCache) -> tuple:
    """(:func:`_case_rows` of one case, its worst modes: a list of its own, empty without
    ``vectors``), so that cases run side by side (:mod:`.side_by_side`) never append to one list."""
    found = [] if vectors else None
    return _case_rows(r, case, g_h, sides, dim_w, trace_norms, found, grams), found or []


def _case_rows(r: BetaRequest, case, g_h, sides, dim_w: int, trace_norms, modes: list | None = None,
               grams: GramCache | None = None) -> list:
    """The rows of one case on G_h: M_h, its couplings B_i and Grams G (from the sweep's ``grams``
    where an earlier pair built them), its route, then per (c1, c2) the interface operator S and the
    bottom of S m = β² G m for every norm (and its worst mode, appended to ``modes`` where given).
    A Petrov–Galerkin pair (trial ≠ test space) is :mod:`.petrov_galerkin`'s."""
    if isinstance(case, SpaceSpec) and case.petrov_galerkin:                     # trial M ≠ test N
        return [_row(r, case, **fields) for fields in petrov_galerkin.pair_rows(r, case, g_h, sides, dim_w, modes,
                                                                                          grams)]
    gamma = sides[0].trace.gamma
    space = _space(case, r.k, g_h, gamma)                                          # M_h on G_h
    tc = time.perf_counter()
    progress.note("couplings B_1, B_2")
    with progress.phase("couplings"):
        couplings = coupling_matrices([s.trace for s in sides], space, r.k, sparse=is_large(space))  # B_i
    t_coupling = time.perf_counter() - tc
    grams = GramCache() if grams is None else grams
    grams = {norm: _timed(f"{norm} Grams", grams.gram, gamma, case, r.k, g_h, space, norm, r.h_route)
             for norm in r.norms}  # G per norm
    structural = gamma.proven_kernel(space, r.k, [s.trace for s in sides], dim_w)
    with progress.phase("kernel decision, Grams split and factorized"):
        route = choose_route(space, couplings, sides, grams, structural, g_h, r.k, trace_norms,
                             vectors=modes is not None)
    progress.note(f"interface operator ({route.name} route)")
    # B_i X_i B_iᵀ, in the blocks of the space's reflections where the sides know X in theirs
    # (a worst mode is a vector of the whole space: its S is whole)
    terms = _timed("interface terms", interface_terms, couplings, sides, route.split if modes is None else None)
    v1_zero = _timed("β with v1 = 0", route.betas_v1_zero, terms)
    rows = []
    for c1, c2 in r.c_pairs:
        S = combine_terms(terms, (c1, c2))
        progress.note(f"eigenproblem S m = β² G m, norm {', '.join(r.norms)}"
                      + (f", c1={c1:g} c2={c2:g}" if len(r.c_pairs) > 1 else ""))
        spectra, seconds = _timed("eigensolves", route.spectra, S, r.norms)  # S m = β² G m
        rows += [_row(r, case, c1, c2, norm, spectra[norm], route.kernel, structural, v1_zero[norm] / np.sqrt(c2),
                      space.dim, dim_w, grams[norm][1], sum(s.ndof for s in sides), t_coupling, seconds[norm])
                 for norm in r.norms]
        if modes is not None:
            modes += worst_modes(route, S, rows[-len(r.norms):], space, gamma)
    return rows


def _series_key(case, k: int, g_h, gamma):
    """The key of the Gram series ``case`` shares with other spaces on G_h (the space's
    ``series_key``: a face's cellwise spaces), else None; a space that fails to build here has
    none (its worker meets the failure again and reports it in the cases' order)."""
    if isinstance(case, SpaceSpec) and case.petrov_galerkin:
        return None
    try:
        return getattr(_space(case, k, g_h, gamma), "series_key", None)
    except Exception:  # noqa: BLE001 - only the order of the spaces depends on it
        return None


def _trace_norms(trace, k: int):
    """:func:`~infsup_contact.discretization.gamma.coupling.trace_l2_norms` of a side, the dense
    basis values it evaluates not kept on the trace where they were not before (points × n_Γ:
    290 MB a side at k = 2, N = 32; the couplings evaluate the basis at their own points)."""
    before = set(trace.basis_cache)
    norms = trace_l2_norms(trace, k)
    for key in set(trace.basis_cache) - before:
        trace.basis_cache.pop(key)
    return norms


def _timed(name: str, fn, *args):
    """fn(*args), its time counted as the phase ``name`` (:func:`~infsup_contact.progress.phase`)."""
    with progress.phase(name):
        return fn(*args)


def _row(r, case, c1, c2, norm, spec, kernel, structural, beta_v1_zero, dim_m, dim_w, info, ndof,
         t_assemble, t_eig) -> dict:
    """One row of ``infsup-contact beta`` (its columns, in order; ``multiplier_mesh`` and
    ``t_interface`` set by :func:`beta_table`; a Petrov–Galerkin pair's meaning of each:
    :mod:`.petrov_galerkin`)."""
    return dict(case=registry.case_name(case), k=r.k, family=r.family, N1=r.n1, N2=r.n2, multiplier_mesh=None,
                c1=c1, c2=c2, norm=norm, beta=spec.beta, kernel_dim=spec.kernel_dim,
                structural_kernel_dim=structural, kernel_detected=kernel.detected,
                kernel_margin_decades=kernel.margin_decades, kernel_decision=kernel.decision,
                kernel_check=kernel_check(kernel.numerical, structural), gap_over_roundoff=spec.gap,
                smallest_nonzero=spec.smallest_nonzero, beta_v1_zero=beta_v1_zero, dim_M=dim_m, dim_W=dim_w,
                n_max=info["n_max"], nmax_rel_error=info["nmax_rel_error"], ndof=ndof, t_assemble=t_assemble,
                t_interface=None, t_eig=t_eig)


def _space(case, k, partition, gamma):
    """A request's case on G_h = ``partition`` of ``gamma``: a registry entry (its id resolved and
    checked on Γ by the request, once; built with the registry's refusals of an empty space), an
    unregistered :class:`~infsup_contact.discretization.spaces.spec.SpaceSpec` (a study's variant,
    e.g. the α sweep of study/face/alpha.py), or a general triple ``(label, s, continuous, vanish)``
    (eqs. 5.3, 5.5; spaces of the segment)."""
    if isinstance(case, SpaceSpec) and registry.SPACES.get(case.id) is case:
        return registry.space_on(case, k, partition, gamma)
    if isinstance(case, SpaceSpec):
        return gamma.space(case, k, partition)
    _, s, continuous, vanish = case
    return multipliers.make_space(partition, s, continuous, vanish)


def beta_rows(family, k, n1, n2, cases=None, multiplier_mesh="omega2",
              c1=1.0, c2=1.0, norms=NORMS, h_route="logkernel", model=DEFAULT_MODEL, side_cache=None,
              mesh: MeshOptions = NO_OPTIONS, gamma=None):
    """β_h for several cases and norms on one mesh pair: :func:`beta_rows_all` with one
    multiplier mesh and one (c1, c2).

    Returns
    -------
    list of dict
        One row per (case, norm) with the columns of ``infsup-contact beta``.
    """
    return beta_rows_all(family, k, n1, n2, cases, (multiplier_mesh,), ((c1, c2),), norms,
                         h_route=h_route, model=model, side_cache=side_cache, mesh=mesh,
                         gamma=gamma)


def beta_rows_all(family, k, n1, n2, cases=None, multiplier_meshes=("omega2",), c_pairs=((1.0, 1.0),),
                  norms=NORMS, h_route="logkernel", model=DEFAULT_MODEL, side_cache=None,
                  mesh: MeshOptions = NO_OPTIONS, gamma=None):
    """:func:`beta_table` of the :class:`~.request.BetaRequest` these arguments make (validated
    here, once: a bad one raises :class:`~infsup_contact.errors.InputError` naming its key);
    ``mesh``: the mesh parameters beyond (family, N), e.g. ``MeshOptions(element="hex")``;
    ``gamma``: the request's Γ (:func:`~.request.resolve_gamma`; None: the model's flat one)."""
    request = BetaRequest(family, k, n1, n2, None if cases is None else tuple(cases), tuple(multiplier_meshes),
                          tuple(tuple(c) for c in c_pairs), tuple(norms), h_route, model, mesh, gamma)
    return beta_table(request, side_cache)


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
