"""Edge dropping: β_h and the conditioning of the multiplier block when Ω2's
face covers Ω1's only partially.

Setting (membranes, −Δu_i = f_i, u_i = 0 on ∂Ω_i∖Γ, b(v, μ) = ∫_Γ (v2 − v1) μ):
Ω1 = (0, 1)³ on the N × N × N grid, its top face the secondary side; Ω2 = (0, L) × (0, 1) × (1, 2)
on the uniform N2 × N2 × N2 grid, L = (N − 1 + θ)/N, so Ω2 covers the last column of Ω1's face
cells by the fraction θ ∈ (0, 1]. Γ = (0, L) × (0, 1) × {1}. Ω1's whole top face is natural
(u1 is free on the uncovered strip too), so its Γ-side dofs are all interior nodes of its face
(those beyond L give zero couplings). The multipliers are a registered face space on Ω1's face
(multiplier mesh ``omega1``) restricted to Γ (:class:`~infsup_contact.discretization.face.spaces.clipped.ClippedFace`:
functions whose support misses Γ dropped, those of the partially covered column kept, cut).
The norms are L²(Γ) and the exact H^{1/2}_00(Γ)' of the rectangle.

Assembly is the engine's (:func:`side_pair`, :func:`interface_operator`): the bodies are
``MakeStructured3DMesh`` hexahedra of the 3D membranes model (Ω2's with the mapping x ↦ L x,
its Γ the face ``Square(width=L)``), X_i = (A_i⁻¹)_ΓΓ from the model's factorized side
operator, the couplings B_i = ∫_Γ μ_j φ_d against NGSolve's Γ basis by tensor Gauss on the
rectangles of the common refinement clipped at x = L, S by ``interface_terms`` /
``combine_terms`` and β_h by ``spectrum``. The tests check it against an independent route
(1D Kronecker assembly of the box Laplacians, ``tests/helpers/tensor_sides.py``).

The H series resolves the cut column, a sliver of width θ/N, only with n_max ≳ 1/(θ h) modes in
x: at θ = 0.001 the default cap (8192) stops it with ``h_capped`` and a normwise estimate
``h_rel_error`` ≈ 1e-4 that understates the error of β_H (3–4 % at N = 8, measured against
``--h-cap 65536``, where the series converges); θ ≥ 0.01 converges within 8192 or nearly
(β_H moves by < 1e-5 with a 4× cap). θ = 1 is the full-face
problem of :mod:`infsup_contact.models.membranes3d` with N1 = N, N2, multiplier mesh omega1.

β_h depends on the space only. For nodal (Lagrange) bases it is computed on the *nodal twin*,
the same case built on the clipped partition (x_0, …, x_{N−1}, L), which spans the restriction
(:func:`nodal_twin`) with a basis that stays well conditioned as θ → 0; for the dual bases
from the restriction itself, whose basis on the cut column degenerates (its k + 1 functions
tend to multiples of one polynomial); ``beta_*_resolved`` says whether β² is above the
pencil's round-off level (:func:`beta_on`).

Multiplier block (reported in the unscaled, the κ-scaled and the L²-normalized basis of the
restricted registry space; :func:`scaled_cond` resolves condition numbers far beyond 1/ε):

* D — the secondary mortar matrix D_jp = ∫_Γ ψ_j N_p over *all* Lagrange nodes p of Ω1's face
  (square for the nodal spaces whose dofs are those nodes); cond₂(D) = σ_max/σ_min;
* S = Σ_i B_i X_i B_iᵀ — the interface operator (Schur complement of the saddle point
  system on the multipliers, X_i = (K_i⁻¹)_ΓΓ); cond₂(S);
* G — the L²(Γ) Gram matrix of the restricted basis.

κ scaling (Popp, Wohlmuth, Gee & Wall, "Improved robustness and consistency of 3D contact
algorithms based on a dual mortar approach", CMAME 2013, eq. (36)): κ_j = ∫_Γ N_j / ∫_{Γ_s} N_j,
the covered fraction of the primal (Lagrange) shape function N_j of node j on the secondary face
Γ_s, and the multiplier of node j is divided by κ_j (MOOSE PR #33572, first order only: the
pressure Σ_j Φ_j z_j / κ_j), i.e. ψ_j → ψ_j / κ_j and the constraint row j of D and B with it.
MOOSE averages the per-element fractions ∫_{e∩Γ} N_j / ∫_e N_j over the node's elements; on
these uniform secondary grids ∫_e N_j is the same on every element of the node, so the average
is eq. (36) exactly (checked in the tests: θ² and 1/2 + θ − θ²/2 for the last two hats). Here
N_j is the Lagrange basis with the multiplier's numbering (the space itself for nodal spaces,
the continuous Q_k hat for the dual ones) and |N_j| is integrated (N_j ≥ 0 at k = 1, where this
is eq. (36) exactly). A diagonal change of basis leaves the Rayleigh quotient of β_h
unchanged: κ scaling changes conditioning, never β_h.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ...discretization.spaces import registry
from ...discretization.face.spaces.clipped import SLIVER_MIN, ClippedFace, min_covered_fraction
from ...discretization.face.spaces.tensor import FaceSpace
from ...discretization.segment.multipliers import SegmentSpace, make_space
from ...discretization.segment.norms import gram_l2
from ...discretization.gamma.quadrature import gauss_legendre_01
from ...discretization.face.shapes.square import SQUARE, Square
from ...discretization.face.partitions.tensor_grid import TensorPartition
from ...errors import InputError
from ...models import model_of_dim
from ...solvers.interface_operator import combine_terms, interface_terms
from ...solvers.spectra import gram_factor, spectrum

THETAS = (1.0, 0.5, 0.25, 0.1, 0.05, 0.01, 0.001)
"""The covered fractions of the last column swept by default."""


def theta_allowed(n: int) -> str:
    """The covered fractions the geometry of N = ``n`` resolves, for messages."""
    return (f"a covered fraction {min_covered_fraction(n):g} <= θ <= 1 at N = {n} (the cut column, θ/N wide, "
            f"at least {SLIVER_MIN:g}: a narrower one is below the resolution of the geometry)")


def check_theta(theta, n: int) -> float:
    """θ as a float in [:func:`~infsup_contact.discretization.face.spaces.clipped.min_covered_fraction`, 1];
    :class:`InputError` naming ``theta`` and the range otherwise (never θ silently taken as 0)."""
    try:
        t = float(theta)
    except (TypeError, ValueError):
        raise InputError("theta", theta_allowed(n), got=theta) from None
    if isinstance(theta, bool) or not min_covered_fraction(n) <= t <= 1.0:  # NaN fails both
        raise InputError("theta", theta_allowed(n), got=theta)
    return t


def _integrate_1d(breaks, f, n_points: int) -> np.ndarray:
    """Σ over the intervals of ``breaks`` of Gauss–Legendre sums of f(x) (n, ...) × weights."""
    t, w = gauss_legendre_01(n_points)
    a, b = breaks[:-1, None], breaks[1:, None]
    x = (a + (b - a) * t).ravel()
    return f(x), ((b - a) * w).ravel()


def _merged(*grids, upper: float = 1.0) -> np.ndarray:
    g = np.unique(np.concatenate([np.asarray(v, float) for v in grids] + [[upper]]))
    g = g[g <= upper + 1e-14]
    return g[np.concatenate([[True], np.diff(g) > 1e-13])]


def primal_twin(space: SegmentSpace) -> SegmentSpace:
    """The Lagrange basis with the numbering of ``space`` (the N_j of κ_j)."""
    return SegmentSpace(space.breakpoints, space.degree, space.continuous, space.vanish_at_ends,
                           space.dofs, space.dim)


def kappa_1d(space: SegmentSpace, L: float) -> np.ndarray:
    """κ_j = ∫_0^L |N_j| / ∫_0^1 |N_j| of the primal twin of the x factor (module docstring)."""
    twin = primal_twin(space)
    grid = _merged(space.breakpoints, [L])
    vals, w = _integrate_1d(grid, twin.evaluate, space.degree + 12)
    covered = np.where((grid[:-1, None] < L - 1e-14) * np.ones((1, space.degree + 12)), 1.0, 0.0).ravel()
    full = np.abs(vals).T @ w
    return (np.abs(vals).T @ (w * covered)) / full


def couplings(face: ClippedFace, partition: TensorPartition, values, degree: int) -> np.ndarray:
    """∫_Γ μ_j φ_d of the clipped face multipliers μ_j against functions φ_d given by
    ``values`` (points (n, 2) ↦ (n, dim)), piecewise polynomial of degree ≤ ``degree`` − s on the
    rectangles of ``partition`` (a side's trace): the tensor Gauss rule of
    :meth:`Square.quadrature <infsup_contact.discretization.face.shapes.square.Square.quadrature>` per
    rectangle of the common refinement of ``partition`` and G_h, clipped at x = L (exact)."""
    L = face.L
    xs = _merged(partition.xs, np.asarray(face.space.sx.breakpoints) * L, upper=L)
    ys = _merged(partition.ys, face.space.sy.breakpoints)
    pts, w = SQUARE.quadrature(TensorPartition(xs, ys), degree)
    mu = face.space.evaluate(pts / np.array([L, 1.0]))
    return (mu * w[:, None]).T @ values(pts)


def geometry(n: int, n2: int, theta: float):
    """(L, Ω1's breakpoints, {side: (xs, ys, zs)}) of the pair at covered fraction θ."""
    L = (n - 1 + theta) / n
    xs1 = np.linspace(0.0, 1.0, n + 1)
    return L, xs1, {1: (xs1, xs1, xs1), 2: (np.linspace(0.0, L, n2 + 1), np.linspace(0.0, 1.0, n2 + 1),
                                            np.linspace(1.0, 2.0, n2 + 1))}


@lru_cache(maxsize=2)
def _side(k: int, n: int, side: int, width: float):
    """The side operator of the 3D membranes (:func:`~infsup_contact.models.membranes3d.side_operator`,
    NGSolve Q_k hexahedra, from the model registry) of the N × N × N box of Ω_side of extent
    ``width`` in x (``MakeStructured3DMesh`` with a mapping), its Γ the face (0, width) × (0, 1)."""
    model = model_of_dim(3)
    mesh = model.mesh(model.families[0], n, side, width=width)
    return model.side_operator(mesh, k, gamma=Square(width=width))


def side_pair(k: int, n: int, n2: int, theta: float) -> tuple:
    """The side operators of Ω1 = (0, 1)³ (N cells per direction, Γ its whole top face: Ω1's face
    is natural beyond L too, its dofs there get zero couplings) and Ω2 = (0, L) × (0, 1) × (1, 2)
    (N2 cells per direction), L of :func:`geometry`. Kept for the next call (the sweep asks
    for every space at one θ in a row)."""
    return _side(k, n, 1, 1.0), _side(k, n2, 2, geometry(n, n2, theta)[0])


def interface_operator(face: ClippedFace, sides) -> np.ndarray:
    """S = Σ_i B_i X_i B_iᵀ (c1 = c2 = 1), X_i = (A_i⁻¹)_ΓΓ of the NGSolve side operators
    (:func:`side_pair`), B_i = ∫_Γ μ_j φ_d against the Γ basis of side i
    (:meth:`Square.trace_basis`, :func:`couplings`); the engine's
    :func:`~infsup_contact.solvers.interface_operator.interface_terms` and ``combine_terms``."""
    s = max(face.space.sx.degree, face.space.sy.degree)
    B = [couplings(face, side.trace.partition, lambda p, t=side.trace: t.gamma.trace_basis(t, p),
                   side.trace.fes.globalorder + s) for side in sides]
    return combine_terms(interface_terms(B, sides), (1.0, 1.0))


def _norm2(A: np.ndarray) -> float:
    return float(np.linalg.norm(A, 2))


def scaled_cond(A_n: np.ndarray, r: np.ndarray, symmetric: bool) -> float:
    """cond₂ of A = diag(r) A_n (diag(r) too when ``symmetric``), A_n of full row rank.

    ‖A‖ ‖A⁺‖ with A⁺ = A_n⁺ diag(1/r) (diag(1/r) A_n⁺ diag(1/r)): the pseudo-inverse of a
    row-scaled full-row-rank matrix is the scaled pseudo-inverse, so only A_n is inverted
    (``inf`` when A_n is singular to working precision).
    Computed so, the condition number of a badly scaled basis (cond far beyond 1/ε: the cut
    functions are O(θ) small) is as accurate as that of the normalized A_n, which a direct SVD
    of A would not be (its small singular values would drown in round-off of ‖A‖)."""
    if A_n.shape[0] > A_n.shape[1]:
        raise InputError("A_n", "a matrix of full row rank (rows <= columns)", got=A_n.shape)
    sv = np.linalg.svd(A_n, compute_uv=False)
    if sv[-1] <= max(A_n.shape) * np.finfo(float).eps * sv[0]:
        return np.inf                      # A_n (hence A) rank deficient to working precision
    inv = np.linalg.pinv(A_n, rcond=0.0)
    if symmetric:
        return _norm2(A_n * np.outer(r, r)) * _norm2(inv / np.outer(r, r))
    return _norm2(A_n * r[:, None]) * _norm2(inv / r[None, :])


def nodal_twin(full, L: float):
    """The same space built on the clipped partition (x_0, …, x_{N−1}, L), pulled back, when the
    registry basis is nodal (Lagrange: ``local_coefficients`` None): its span equals the
    restriction's (a piecewise polynomial on a sub-interval is a polynomial there, and the
    dimensions agree), with a basis that stays well conditioned as θ → 0 (its nodes move
    with L). ``None`` for the other bases (the dual ones), whose β_h is computed from the
    restriction."""
    if full.sx.local_coefficients is not None or full.sy.local_coefficients is not None:
        return None
    cut = ClippedFace.of(full, L)
    sx = cut.space.sx
    x = SegmentSpace(sx.breakpoints, sx.degree, sx.continuous, False, sx.dofs, sx.dim)
    return ClippedFace.of(FaceSpace(x, full.sy, cut.space.breakpoints), L, cut=False)


def beta_on(face: ClippedFace, base, operator, norms, h_rtol: float, cut: bool, h_cap: int | None = None) -> dict:
    """β_h in ``norms`` from the pencil of ``face`` in its L²(Γ)-normalized basis (β_h is
    invariant under any change of basis; the normalized pencil is the best conditioned
    diagonal one). ``base``: the face space ``face`` was made of (``cut`` as in
    :meth:`ClippedFace.of`), rebuilt x-normalized for the H series so that its relative error
    is per function, not relative to the largest one. ``operator``: ClippedFace ↦ its interface
    operator S (:func:`interface_operator` of :func:`side_pair`). ``h_cap``: the largest n_max of
    the H series (default that of :func:`~infsup_contact.discretization.face.norms.tensor.gram_h_face`).

    ``beta_<norm>_resolved``: β² above the pencil's round-off level
    100 · dim · ε · ‖S‖ ‖G⁻¹‖ (normalized basis); below it the digits are noise."""
    sx_dim = base.factors[0].dim
    kept_x = face.kept[::base.factors[1].dim] // base.factors[1].dim
    G_l2 = face.gram("L2")[0]
    r = np.sqrt(np.diag(G_l2))
    unit = np.outer(r, r)
    S_n = operator(face) / unit
    out = {}
    for norm in norms:
        if norm == "L2":
            G = G_l2 / unit
        elif norm == "H":
            dx = np.ones(sx_dim)
            dx[kept_x] = 1.0 / np.sqrt(np.diag(face.L * gram_l2(face.space.sx)))
            cap = {} if h_cap is None else {"n_cap": h_cap}
            G_x, info = ClippedFace.of(base, face.L, scale_x=dx, cut=cut).gram("H", rtol=h_rtol, **cap)
            d = np.repeat(dx[kept_x], base.factors[1].dim)
            G = G_x / np.outer(d, d) / unit
            out.update(n_max=info["n_max"], h_rel_error=info["nmax_rel_error"], h_capped=info["capped"])
        else:
            raise InputError("norm", "H, L2", got=norm)
        factor = gram_factor(G)
        beta = spectrum(S_n, factor=factor).beta
        noise = 100 * len(G) * np.finfo(float).eps * _norm2(S_n) / np.linalg.eigvalsh(G)[0]
        out[f"beta_{norm}"], out[f"beta_{norm}_resolved"] = beta, bool(beta ** 2 > noise)
    return out


def beta_kappa(S_n: np.ndarray, G_n: np.ndarray, rk: np.ndarray) -> dict:
    """β_h in the L²(Γ) norm from the pencil of the restricted registry basis in the κ-scaled
    basis ψ̂_j r_j/κ_j, i.e. (diag(rk) S_n diag(rk), diag(rk) G_n diag(rk)) with ``rk`` = r/κ,
    (S_n, G_n) the L²-normalized pencil: a second route to β_L2 (a diagonal change of basis
    leaves the Rayleigh quotient unchanged, so it must agree with ``beta_L2`` wherever both are
    resolved). ``beta_L2_kappa_resolved``: β² above the round-off level of the normalized
    restricted pencil (:func:`beta_on`); ``nan`` where the scaled Gram matrix is not positive
    definite to working precision."""
    scale = np.outer(rk, rk)
    noise = 100 * len(G_n) * np.finfo(float).eps * _norm2(S_n) / np.linalg.eigvalsh(G_n)[0]
    try:
        beta = spectrum(S_n * scale, factor=gram_factor(G_n * scale)).beta
    except np.linalg.LinAlgError:
        return {"beta_L2_kappa": np.nan, "beta_L2_kappa_resolved": False}
    return {"beta_L2_kappa": beta, "beta_L2_kappa_resolved": bool(noise > 0 and beta ** 2 > noise)}


def edge_row(case: str, k: int, n: int, n2: int, theta: float, norms=("H", "L2"), h_rtol: float = 1e-6,
             operator=None, h_cap: int | None = None) -> dict:
    """β_h and the multiplier-block conditioning at one covered fraction θ (module docstring).

    β_h is computed from the pencil in the L²(Γ)-normalized basis (β_h is invariant under any
    diagonal change of basis, κ scaling included; the normalized pencil is the best
    conditioned of them); the condition numbers are those of the unscaled registry basis and of
    the κ-scaled basis (:func:`scaled_cond`). ``operator``: ClippedFace ↦ S, by default
    :func:`interface_operator` with the NGSolve sides of :func:`side_pair` (the tests pass an
    independent route).

    Returns
    -------
    dict
        ``beta_H``, ``beta_L2``, ``dim_M``, ``dropped`` (unrestricted minus kept functions),
        ``cond_D``, ``cond_S``, ``cond_G`` (L² Gram) and their ``*_kappa`` versions,
        ``cond_*_unit`` (normalized basis), ``kappa_min``, ``n_max``, ``h_rel_error``, ``h_capped``,
        ``beta_L2_kappa`` (the κ-scaled restricted basis, :func:`beta_kappa`).
    """
    registry.check_case(case, k)
    for key, v in (("N", n), ("N2", n2)):
        if not isinstance(v, (int, np.integer)) or isinstance(v, bool) or v < 1:
            raise InputError(key, "an integer >= 1", got=v)
    check_theta(theta, n)
    L, xs1, _ = geometry(n, n2, theta)
    full = registry.case_space(case, k, TensorPartition(xs1, xs1), SQUARE)
    face = ClippedFace.of(full, L)
    kept_x = face.kept[::full.sy.dim] // full.sy.dim
    kappa = np.repeat(kappa_1d(full.sx, L)[kept_x], full.sy.dim)
    if operator is None:
        sides = side_pair(k, n, n2, theta)
        operator = lambda f: interface_operator(f, sides)      # noqa: E731
    t1 = make_space(xs1, k, True, False)                      # the Q_k Lagrange basis of Ω1's face
    primal = FaceSpace(t1, t1, TensorPartition(xs1, xs1))
    G_l2 = face.gram("L2")[0]
    r = np.sqrt(np.diag(G_l2))            # ψ_j = r_j ψ̂_j, ψ̂_j of unit L²(Γ) norm
    unit = np.outer(r, r)
    S_n = operator(face) / unit
    D_n = couplings(face, primal.breakpoints, primal.evaluate, k + max(full.sx.degree, full.sy.degree)) / r[:, None]
    G_n = G_l2 / unit
    row = dict(case=case, k=k, N=n, N2=n2, theta=theta, L=L, dim_M=face.dim, dropped=full.dim - face.dim,
               kappa_min=float(kappa.min()))
    for tag, rr in (("", r), ("_kappa", r / kappa), ("_unit", np.ones_like(r))):
        row[f"cond_D{tag}"] = scaled_cond(D_n, rr, False)
        row[f"cond_S{tag}"] = scaled_cond(S_n, rr, True)
        row[f"cond_G{tag}"] = scaled_cond(G_n, rr, True)
    row.update(beta_kappa(S_n, G_n, r / kappa))
    twin = nodal_twin(full, L)
    row["beta_route"] = "restricted" if twin is None else "clipped-nodal"
    row.update(beta_on(face if twin is None else twin, full if twin is None else twin.space, operator,
                       norms, h_rtol, cut=twin is None, h_cap=h_cap))
    return row
