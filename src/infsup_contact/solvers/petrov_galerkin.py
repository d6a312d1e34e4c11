"""The inf-sup constant of a Petrov–Galerkin pair: λ_h in a trial space M, b(v, μ) tested in N.

CalculiX's PGLINMORTAR interpolates the multiplier in the linear dual space (LINMORTAR) and tests the
constraint b(u, μ) = g(μ) with μ in the standard linear hats on the same vertices: trial M ≠ test N,
dim M = dim N (a registry entry with ``trial_space`` and ``test_space``,
:class:`~infsup_contact.discretization.spaces.spec.SpaceSpec`). The saddle point system
[[A, B_Mᵀ], [B_N, 0]] is well posed iff its Schur complement

    S_PG = B_N A⁻¹ B_Mᵀ = Σ_i C_i^N X_i C_i^Mᵀ / c_i

(C the couplings of each space to side i's trace, X_i its Steklov inverse, :mod:`.interface_operator`)
is invertible, and its uniform stability constant is

    γ_h = inf_{λ∈M} sup_{μ∈N} μᵀ S_PG λ / (‖λ‖_M ‖μ‖_N) = σ_min(L_N⁻¹ S_PG L_M⁻ᵀ),

G_M = L_M L_Mᵀ, G_N = L_N L_Nᵀ the Gram matrices of the row's norm (H^{-1/2}_00 or L², each space its
own). For N = M this is λ_min(S, G) = β_h² (S symmetric positive semi-definite: its singular values
are its eigenvalues), so the column ``beta`` of a pair's row is **sqrt(γ_h)**: comparable with the
symmetric rows, and β_h itself when N = M (``tests/solvers/test_petrov_galerkin.py``: the same β_h as
the symmetric route to round-off, by an independent computation). It is 0 exactly where the kernel
below is not empty, as on the symmetric route.

Kernel. S_PG is not B A⁻¹ Bᵀ: its kernel is not the kernel of one coupling, so it is decided on
S_PG itself, once per (c1, c2) (it may depend on c, unlike the symmetric one), from the singular
values s of K = L_N⁻¹ S_PG L_M⁻ᵀ in the L² norms (G well conditioned: mass matrices): a value
<= η = dim M · ε · s_max (the pencil's round-off level, :func:`~.kernel.pencil_roundoff`) counts as zero,
with the margin in decades and the ``close`` rule of :func:`~.kernel.decide`. The proven part
(``structural_kernel_dim``): ker B_Mᵀ ⊂ ker S_PG and ker B_Nᵀ ⊂ ker S_PGᵀ, so for a square S_PG
dim ker ≥ max(proven(M), proven(N)), each the interface's count for that space
(``Interface.proven_kernel``: the dimension count and, on QUAD8 faces, the tensor modes).

Columns with no meaning of their own here keep the symmetric meaning where it carries over:
``gap_over_roundoff`` = s_{d+1}/η and ``smallest_nonzero`` = sqrt(s_{d+1}) of the row's norm,
``beta_v1_zero`` = sqrt(σ_min) of side 2's term alone (v1 = 0) / sqrt(c2), ``n_max`` and
``nmax_rel_error`` the larger of the two Gram matrices'. Dense (one SVD per norm and (c1, c2)):
a pair above :data:`~infsup_contact.la.bottom.DENSE_MAX_M` is refused in one line
(:func:`check_pair_size`). The worst mode (``beta --worst-mode``) is the right singular vector of
s_min, λ_h in M's basis.

Prediction (written before the first run, HEX20 bodies, k = 2; the argument's wording made precise
after it, the predictions unchanged). With μ_j = λ_j the pairing is ∫ μ_h λ_h = Σ λ_j² ∫φ_j > 0
(biorthogonality ∫ψ_j φ_k = δ_jk ∫φ_k, D = diag ∫φ_j), and the L² projection of the dual function
Σ λ_j ψ_j onto Q1_0 is the hat function with coefficients M⁻¹Dλ (M the Q1 mass matrix; Fourier symbol
between 1 and 3). Were the traces Q1_0 only, S_PG = M X D, and μ = M⁻¹Dλ would give
μᵀ S_PG λ = (Dλ)ᵀ X (Dλ) > 0: coercive. The QUAD8 trace sees the rest of ψ_j too, so there is no
proof. Predicted: PGLIN0-Q8 (∂Γ vertices dropped) invertible, kernel 0
on matching and non-matching meshes, sqrt(γ_H) on a plateau near the symmetric β_H of LINDUAL0-Q8
and LIN0-Q8 (within a factor 2 of their geometric mean), sqrt(γ_L2) decaying like h^{1/2} as every
L² row; PGLIN-Q8 (all vertices) kernel exactly 4 on matching meshes (the corner modes of the dual
trial space, LINDUAL-Q8's proven kernel; T5's four geometric modes on the left), on non-matching
meshes no proven mode and a small, decaying γ_h.

Outcome (N = 4, 6, 8 and 4:5, 6:7, 8:9, G_h = Ω2's trace; table in docs/models.md). PGLIN0-Q8 as
predicted: kernel 0 everywhere (margins >= 12.5 decades), sqrt(γ_H) 1.281 / 1.263 / 1.258 matching and
0.90 non-matching, 0.5–1.4 % below the geometric mean of β_H(LINDUAL0-Q8) and β_H(LIN0-Q8) and between
the two in every row and both norms (not predicted); sqrt(γ_L2) falls like h^{1/2}. PGLIN-Q8: kernel 4
on matching meshes as predicted, but also 4 on the non-matching ones, against the prediction: the
corner products of the 1D end duals are orthogonal to every function linear on their corner cell and
vanishing at the corner, so to both sides' hats wherever G_h's corner cell lies inside both sides'
(G_h the finer trace); ``product_modes`` proves them (``structural_kernel_dim`` 4).
"""
from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla

from ..discretization.gamma.coupling import coupling_matrix
from ..discretization.spaces import registry
from ..errors import InputError
from ..la.bottom import DENSE_MAX_M
from .kernel import decide, gap_over_roundoff, pencil_roundoff
from .modes import Mode
from .spectra import Spectrum, gram_factor

KERNEL_NORM = "L2"
"""The norm whose reduced S_PG decides the kernel (the Gram matrices are mass matrices: well conditioned)."""


def check_pair_size(cases, k: int, n1: int, n2: int, multiplier_mesh: str) -> None:
    """:class:`InputError` (naming the N that sets G_h) for a Petrov–Galerkin pair among ``cases``
    (registry entries, checked on the request's Γ) whose dim M on the multiplier mesh exceeds
    :data:`~infsup_contact.la.bottom.DENSE_MAX_M` (solved by a dense SVD only)."""
    pairs = [spec for spec in cases if spec.petrov_galerkin and spec.dimension is not None]
    n = registry.multiplier_intervals(n1, n2, multiplier_mesh) if pairs else None  # G_h's cells: for a pair only
    for spec in pairs:
        dim = spec.dimension(k, n)
        if dim > DENSE_MAX_M:
            key = {"omega2": "N2", "omega1": "N1"}.get(multiplier_mesh, "N1, N2")
            raise InputError(key, f"a multiplier mesh with dim M <= {DENSE_MAX_M} for the Petrov–Galerkin pair "
                             f"{spec.id} (a dense SVD; dim M = {dim} on {n} x {n} cells of G_h = {multiplier_mesh})",
                             got=n2 if key == "N2" else n1 if key == "N1" else f"{n1}, {n2}")


def pair_rows(r, spec, g_h, sides, dim_w: int, modes: list | None = None, grams=None) -> list:
    """The keyword arguments of ``infsup._row`` for every (c1, c2) and norm of request ``r``, for the
    pair ``spec`` on G_h = ``g_h`` (module docstring); ``modes`` receives each row's worst mode, ``grams``
    (the sweep's :class:`~.side_cache.GramCache`, if any) the trial and test spaces' Gram matrices under their
    own registry entries."""
    gamma = sides[0].trace.gamma
    trial, test = pair_spaces(spec, r.k, g_h, gamma)
    tc = time.perf_counter()
    terms = pair_terms(trial, test, sides, r.k)
    t_coupling = time.perf_counter() - tc
    entries = [registry.SPACES[role] for role in (spec.trial_space, spec.test_space)]  # the Grams' keys
    both = {norm: [gamma.gram(space, norm, h_route=r.h_route) if grams is None
                   else grams.gram(gamma, entry, r.k, g_h, space, norm, r.h_route)
                   for entry, space in zip(entries, (trial, test))]
            for norm in dict.fromkeys(r.norms + (KERNEL_NORM,))}                 # {norm: [G_M, G_N]}
    factors = {norm: [gram_factor(G) for G, _ in pair] for norm, pair in both.items()}
    structural = max(gamma.proven_kernel(space, r.k, [side.trace for side in sides], dim_w) for space in (trial, test))
    v1_zero = {norm: _reduced_singular(terms[1], *factors[norm])[0][0] for norm in r.norms}  # side 2 alone
    fixed = dict(structural=structural, dim_m=trial.dim, dim_w=dim_w, ndof=sum(side.ndof for side in sides),
                 t_assemble=t_coupling)
    out = []
    for c1, c2 in r.c_pairs:
        S = terms[0] / c1 + terms[1] / c2
        s_kernel = _reduced_singular(S, *factors[KERNEL_NORM])
        kernel = kernel_decision(s_kernel[0], structural)
        for norm in r.norms:
            te = time.perf_counter()
            reuse = norm == KERNEL_NORM and modes is None  # the kernel's SVD is this row's: not twice
            s, vt = s_kernel if reuse else _reduced_singular(S, *factors[norm], vectors=modes is not None)
            spectrum = _spectrum(s, kernel.dim)
            info = [i for _, i in both[norm]]
            out.append(dict(fixed, c1=c1, c2=c2, norm=norm, spec=spectrum, kernel=kernel,
                            beta_v1_zero=float(np.sqrt(max(v1_zero[norm], 0.0)) / np.sqrt(c2)),
                            info={key: max(x[key] for x in info) for key in ("n_max", "nmax_rel_error")},
                            t_eig=time.perf_counter() - te))
            if modes is not None:
                keys = dict(case=spec.id, multiplier_mesh=None, c1=c1, c2=c2, norm=norm)
                modes.append(_mode(keys, spectrum.beta, vt[0], factors[norm][0], kernel.dim > 0, trial, gamma))
    return out


def pair_spaces(spec, k: int, g_h, gamma) -> tuple:
    """(M, N): the trial and test spaces of ``spec`` on G_h, the pair checked on Γ by the request
    (a refusal names the pair's id: the segment, other bodies' faces, k), each space on its own;
    :class:`InputError` if dim M ≠ dim N."""
    if registry.SPACES.get(spec.id) is spec:  # checked on Γ by the request: built with the pair's refusals
        registry.space_on(spec, k, g_h, gamma, pair=True)
    trial, test = (registry.case_space(case, k, g_h, gamma) for case in (spec.trial_space, spec.test_space))
    if trial.dim != test.dim:
        raise InputError("case", f"a Petrov–Galerkin pair with dim M = dim N ({spec.id}: dim {spec.trial_space} "
                         f"= {trial.dim}, dim {spec.test_space} = {test.dim} on this G_h)", got=spec.id)
    return trial, test


def pair_terms(trial, test, sides, k: int) -> list:
    """C_i^N X_i C_i^Mᵀ per side at unit material scale (dense; not symmetric unless N = M)."""
    out = []
    for side in sides:
        C_m, C_n = (coupling_matrix(side.trace, space, k) for space in (trial, test))
        out.append(np.asarray(C_n @ side.steklov_times(C_m.T)))
    return out


def _reduced_singular(S: np.ndarray, L_m: np.ndarray, L_n: np.ndarray, vectors: bool = False) -> tuple:
    """(singular values ascending, right singular vectors as rows in the same order or None) of
    K = L_N⁻¹ S L_M⁻ᵀ: s[0] = γ_h."""
    K = sla.solve_triangular(L_n, sla.solve_triangular(L_m, np.asarray(S, float).T, lower=True).T, lower=True)
    if not vectors:
        return np.sort(sla.svdvals(K)), None
    _, s, vt = sla.svd(K)
    return s[::-1].copy(), vt[::-1]


def _mode(keys: dict, beta: float, v: np.ndarray, L_m: np.ndarray, in_kernel: bool, trial, gamma) -> Mode:
    """The worst mode λ = L_M⁻ᵀ v (v the right singular vector of s_min), unit Euclidean norm, in M's basis."""
    vector = sla.solve_triangular(L_m, v, lower=True, trans="T")
    return Mode(keys, beta, vector / np.linalg.norm(vector), in_kernel, trial, gamma)


def kernel_decision(s: np.ndarray, structural: int):
    """The kernel of S_PG from the ascending singular values ``s`` of its L²-reduced form: the count
    <= η = n ε s_max against the proven part (:func:`~.kernel.decide`: margin and ``close``)."""
    s_max = float(s[-1])
    tol = pencil_roundoff(s, s_max)
    return decide(s, int(structural), tol, int(np.sum(s <= tol)), s_max)


def _spectrum(s: np.ndarray, d: int) -> Spectrum:
    """The row's :class:`~.spectra.Spectrum` from the singular values of K in its norm: β = sqrt(γ_h)
    (0 over a kernel), the first value above the kernel, its gap over n ε s_max."""
    above = s[d] if d < len(s) else np.nan
    beta = 0.0 if d > 0 else float(np.sqrt(max(s[0], 0.0)))
    return Spectrum(beta, d, float(np.sqrt(max(above, 0.0))), gap_over_roundoff(s, d), s[:8].copy())
