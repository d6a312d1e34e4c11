"""Gram matrices of a multiplier space for the L²(Γ) norm and the norm of M = H^{1/2}_00(Γ)'.

Bathe & Brezzi (2001), eq. (3.9), measure the multiplier in M = (H^{1/2}_00(Γ))', the dual
of the trace space of displacements vanishing at the ends of Γ = (0, 1). We use the
spectral realisation of that norm in the L²-orthonormal sine basis √2 sin(nπx):

    ‖v‖²_{H^{1/2}_00} = Σ_{n≥1} nπ v_n²,      ‖μ‖²_M = Σ_{n≥1} μ_n² / (nπ),
    μ_n = √2 ∫_0^1 μ(x) sin(nπx) dx,

(the interpolation norm halfway between L² and H¹_0, whose eigenvalues are (nπ)²).
For a basis {φ_j} of a multiplier space the M-Gram matrix is therefore

    G_ij = Σ_{n≥1} φ_{j,n} φ_{i,n} / (nπ),

an infinite series that :func:`gram_h` truncates adaptively with a Richardson-extrapolated
tail and an error estimate. :func:`gram_l2` is the exact L² mass matrix.
"""
from __future__ import annotations

import numpy as np

from ...errors import InputError
from .logkernel import gram_h_logkernel
from .multipliers import SegmentSpace, local_monomial_coefficients, local_shapes
from ..gamma.quadrature import gauss_legendre_01
from ...la.richardson import extrapolate

NORMS = ("H", "L2")

#: Largest truncation index n_max that :func:`gram_h` uses by default; if the error
#: estimate is still above ``rtol`` there, the estimate is reported as is (``capped``).
N_MAX_CAP = 2**16

#: Below this value of Ω = nπh the integration-by-parts formula cancels (its terms grow
#: like Ω^{-(s+1)} while the integral stays O(h)); Gauss–Legendre is used there instead.
IBP_SWITCH = 2.0

#: Extra Gauss points beyond s: for Ω < IBP_SWITCH the integrand p(t) sin(θ + Ω t) is
#: resolved to round-off by s + 12 points (remainder ~ Ω^{26}/26! ≪ 1e-16).
_GAUSS_EXTRA = 12

#: Upper bound on the number of doubles in one (intervals × (s+1) × n) work array, so
#: that memory stays ~ 30 MB per array whatever n_max is.
_CHUNK_ELEMENTS = 2**22


# --------------------------------------------------------------------------- L² norm
def gram_l2(space: SegmentSpace) -> np.ndarray:
    """Exact L²(Γ) mass matrix of ``space``.

    Parameters
    ----------
    space : SegmentSpace
        The multiplier space.

    Returns
    -------
    ndarray, shape (dim, dim)
        G_ij = ∫_0^1 φ_i φ_j dx, computed with s + 1 Gauss–Legendre points per interval
        (exact for the degree-2s integrand).
    """
    s = space.degree
    t, w = gauss_legendre_01(s + 1)
    vals = local_shapes(s, t)                       # (q, s+1)
    ref_mass = (vals * w[:, None]).T @ vals         # ∫_0^1 ψ_a ψ_b dt
    h = np.diff(space.breakpoints)
    local = h[:, None, None] * ref_mass[None]       # (N, s+1, s+1)
    if space.local_coefficients is not None:        # C M Cᵀ per interval
        local = np.swapaxes(space.to_local_basis(np.swapaxes(space.to_local_basis(local), 1, 2)), 1, 2)
    rows = np.broadcast_to(space.dofs[:, :, None], local.shape)
    cols = np.broadcast_to(space.dofs[:, None, :], local.shape)
    keep = (rows >= 0) & (cols >= 0)
    G = np.zeros((space.dim, space.dim))
    np.add.at(G, (rows[keep], cols[keep]), local[keep])
    return G


# --------------------------------------------------------------- sine coefficients
def sine_coefficients(space: SegmentSpace, n, switch: float = IBP_SWITCH) -> np.ndarray:
    """Sine coefficients φ_{j,n} = √2 ∫_0^1 φ_j(x) sin(nπx) dx of all basis functions.

    Per interval [a, b] (h = b − a, Ω = nπh) the integral of the local polynomial is taken
    by the exact, finite integration-by-parts formula when Ω ≥ ``switch`` and by
    (s + 12)-point Gauss–Legendre when Ω < ``switch``, where integration by parts would
    cancel catastrophically.

    Parameters
    ----------
    space : SegmentSpace
        The multiplier space.
    n : array_like of int, shape (m,)
        Sine indices (n ≥ 1; n = 0 gives zeros).
    switch : float, optional
        Threshold in Ω. ``0`` forces integration by parts everywhere (inaccurate for small
        Ω) and ``np.inf`` forces Gauss everywhere (inaccurate for large Ω); both are for
        testing.

    Returns
    -------
    ndarray, shape (dim, m)
        Column k holds the coefficients of index ``n[k]``.

    Raises
    ------
    InputError
        If ``n`` is not a 1-D array of non-negative numbers.
    """
    n = np.asarray(n, dtype=float)
    if n.ndim != 1 or not np.all(np.isfinite(n)) or np.any(n < 0):
        raise InputError("n", "a 1-D array of non-negative sine indices", got=n.shape)
    omega = np.pi * n
    return np.sqrt(2.0) * _scatter(space, space.to_local_basis(_local_sine_integrals(space, omega, switch)))


def _local_sine_integrals(space: SegmentSpace, omega: np.ndarray, switch: float) -> np.ndarray:
    """∫_{x_e}^{x_{e+1}} ψ_{e,a}(x) sin(ωx) dx for all intervals e, shapes a, ω; (N, s+1, m)."""
    h = np.diff(space.breakpoints)
    big_omega = h[:, None] * omega[None, :]           # Ω = ωh, (N, m)
    small = big_omega < switch
    # Dummy Ω = 1 where Gauss takes over: avoids 1/Ω^{s+1} overflow for tiny Ω.
    out = _ibp_integrals(space, omega, np.where(small, 1.0, big_omega))
    e_idx, n_idx = np.nonzero(small)
    if len(e_idx):
        out[e_idx, :, n_idx] = _gauss_integrals(space, omega, e_idx, n_idx)
    return out


def _ibp_integrals(space: SegmentSpace, omega: np.ndarray, big_omega: np.ndarray) -> np.ndarray:
    """Integration by parts, exact for polynomials: with x = a + h t, q(t) = p(x),

    ∫_a^b p(x) sin(ωx) dx = h Σ_{m=0}^{s} [q^{(m)}(t) F_m(ωx) / Ω^{m+1}]_{t=0}^{t=1},
    F_m(θ) = −cos(θ + mπ/2) (i.e. −cos, sin, cos, −sin, ...).
    """
    s = space.degree
    x = space.breakpoints
    theta = x[:, None] * omega[None, :]
    # cos/sin at each breakpoint computed once, so the two intervals sharing a breakpoint
    # see bit-identical values and their endpoint terms cancel exactly when scattered.
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    trig = [-cos_t, sin_t, cos_t, -sin_t]
    F = np.stack([trig[m % 4] for m in range(s + 1)], axis=1)                   # (N+1, s+1, m)
    inv_pow = big_omega[:, None, :] ** -(np.arange(s + 1)[None, :, None] + 1.0)  # (N, s+1, m)
    d0, d1 = _endpoint_derivatives(s)                                           # (s+1, s+1)
    h = np.diff(x)[:, None, None]
    return h * (d1 @ (F[1:] * inv_pow) - d0 @ (F[:-1] * inv_pow))


def _endpoint_derivatives(s: int) -> tuple[np.ndarray, np.ndarray]:
    """D0[a, m] = ψ_a^{(m)}(0), D1[a, m] = ψ_a^{(m)}(1) for the reference shapes ψ_a."""
    C = local_monomial_coefficients(s)
    d0, d1 = np.zeros((s + 1, s + 1)), np.zeros((s + 1, s + 1))
    for m in range(s + 1):
        p = np.arange(m, s + 1)
        falling = np.array([np.prod(np.arange(q - m + 1, q + 1)) for q in p], dtype=float)
        d0[:, m] = C[:, m] * falling[0]      # only the t^m term survives at t = 0
        d1[:, m] = C[:, m:] @ falling
    return d0, d1


def _gauss_integrals(space: SegmentSpace, omega, e_idx, n_idx) -> np.ndarray:
    """Gauss–Legendre integrals for the listed (interval, ω) pairs; shape (K, s+1)."""
    s = space.degree
    t, w = gauss_legendre_01(s + _GAUSS_EXTRA)
    vals = local_shapes(s, t)                                 # (q, s+1)
    a = space.breakpoints[e_idx]
    h = np.diff(space.breakpoints)[e_idx]
    om = omega[n_idx]
    sines = np.sin(om[:, None] * (a[:, None] + h[:, None] * t[None, :]))  # (K, q)
    return h[:, None] * ((sines * w[None, :]) @ vals)


def _scatter(space: SegmentSpace, local: np.ndarray) -> np.ndarray:
    """Sum local (N, s+1, m) contributions into global rows (dim, m) via ``dofs``.

    Continuous spaces share a dof between neighbouring intervals, hence the summation.
    """
    out = np.zeros((space.dim, local.shape[2]))
    for a in range(space.degree + 1):
        rows = space.dofs[:, a]
        keep = rows >= 0
        if len(np.unique(rows[keep])) == keep.sum():
            out[rows[keep]] += local[keep, a]       # fast path: distinct rows per shape
        else:
            np.add.at(out, rows[keep], local[keep, a])
    return out


# ------------------------------------------------------------------------- M norm
def gram_h(space: SegmentSpace, rtol: float = 1e-6, n_start: int | None = None,
           n_cap: int = N_MAX_CAP, switch: float = IBP_SWITCH) -> tuple[np.ndarray, dict]:
    """Gram matrix of the M = (H^{1/2}_00(Γ))' norm (Bathe & Brezzi 2001, eq. (3.9)).

    G_ij = Σ_{n≥1} φ_{i,n} φ_{j,n} / (nπ) with the sine coefficients of
    :func:`sine_coefficients`. Basis functions with jumps or nonzero endpoint values
    have φ_{j,n} ~ 1/n, so the tail after n terms is ~ C n^{-2}. Partial sums S(n) are
    accumulated at n = n0, 2n0, 4n0, ... and extrapolated (:func:`~.richardson.extrapolate`:
    R(n) = S(2n) + (S(2n) − S(n)) / 3 and a second Richardson stage), until the stated error
    — the last step between successive extrapolations in G's own metric, with a one-level
    look-ahead on the steps' ratio — is ≤ rtol. It bounds the relative change of every
    eigenvalue of a pencil with G, so of β². Smoother spaces converge faster.

    Parameters
    ----------
    space : SegmentSpace
        The multiplier space.
    rtol : float, optional
        Target of the stated relative truncation error (in G's metric: it bounds every
        eigenvalue of a pencil with G).
    n_start : int, optional
        First partial-sum length n0; default max(16, 2 (s+1) N) for N intervals, i.e.
        past the point where every interval is resolved (nπh ≳ 2(s+1)π).
    n_cap : int, optional
        Largest number of sine terms ever summed (default :data:`N_MAX_CAP`). If the
        estimate is still above ``rtol`` there, G is returned with that estimate and
        ``info["capped"] = True``.
    switch : float, optional
        Ω threshold passed to :func:`sine_coefficients`.

    Returns
    -------
    G : ndarray, shape (dim, dim)
        Symmetric positive definite Gram matrix.
    info : dict
        ``n_max`` (int, sine terms summed), ``nmax_rel_error`` (float, the stated bound on
        the relative truncation error of G in its own metric, :func:`~.richardson.extrapolate`), ``capped`` (bool), ``n_start``.

    Raises
    ------
    InputError
        For rtol ≤ 0, or n_start / n_cap < 1.
    """
    if not rtol > 0:
        raise InputError("rtol", "a positive float", got=rtol)
    n0 = max(16, 2 * (space.degree + 1) * space.n_intervals) if n_start is None else int(n_start)
    if n0 < 1 or n_cap < 1:
        raise InputError("n_start/n_cap", "positive integers", got=(n_start, n_cap))
    summed = [0, np.zeros((space.dim, space.dim))]   # S(n) of the last n asked, extended from there

    def partial(n):
        summed[1] = summed[1] + _partial_gram(space, summed[0] + 1, n, switch)
        summed[0] = n
        return summed[1]

    return extrapolate(partial, 2.0, n0, n_cap, rtol)


def _partial_gram(space: SegmentSpace, n_first: int, n_last: int, switch: float) -> np.ndarray:
    """Σ_{n=n_first}^{n_last} φ_n φ_nᵀ / (nπ), in chunks so memory stays bounded."""
    G = np.zeros((space.dim, space.dim))
    chunk = max(1, _CHUNK_ELEMENTS // (space.n_intervals * (space.degree + 1)))
    for start in range(n_first, n_last + 1, chunk):
        n = np.arange(start, min(start + chunk, n_last + 1), dtype=float)
        phi = sine_coefficients(space, n, switch) / np.sqrt(np.pi * n)[None, :]
        G += phi @ phi.T          # Φ D Φᵀ with D = diag(1/(nπ)) split symmetrically
    return G


# ----------------------------------------------------------------------- dispatch
H_ROUTES = ("logkernel", "series")
"""Two independent routes to the H^{-1/2}_00 Gram matrix: the closed-form log kernel
(:mod:`infsup_contact.discretization.segment.logkernel`, no truncation, the default) and the sine series."""

L2_INFO = {"n_max": 0, "nmax_rel_error": 0.0}
"""What an exact (untruncated) Gram reports: no series, no truncation error."""


def gram_by_norm(norm: str, l2, h, **kwargs) -> tuple[np.ndarray, dict]:
    """The one dispatch on ``norm`` ∈ :data:`NORMS` shared by every Γ (segment, face, triangles).

    Parameters
    ----------
    norm : {"H", "L2"}
        "L2": the exact L²(Γ) mass matrix; "H": the M = (H^{1/2}_00(Γ))' norm of Bathe &
        Brezzi (2001), eq. (3.9).
    l2 : callable () -> ndarray
        The L² Gram matrix (called only for "L2"; ``kwargs`` are not passed to it).
    h : callable (**kwargs) -> (ndarray, dict)
        The H Gram matrix and its info (called only for "H", with ``kwargs``).

    Returns
    -------
    G : ndarray (dim, dim)
    info : dict
        :data:`L2_INFO` (a fresh copy) for "L2", ``h``'s info for "H".

    Raises
    ------
    InputError
        Naming ``norm`` and the allowed values :data:`NORMS`, for any other ``norm``.
    """
    if norm == "L2":
        return l2(), dict(L2_INFO)
    if norm == "H":
        return h(**kwargs)
    raise InputError("norm", ", ".join(NORMS), got=norm)


def gram_h_route(space: SegmentSpace, h_route: str = "logkernel", **kwargs) -> tuple[np.ndarray, dict]:
    """The segment's H Gram matrix by ``h_route`` ∈ :data:`H_ROUTES`: the closed-form log kernel
    (no truncation; :data:`L2_INFO` reported) or the truncated, extrapolated sine series
    (:func:`gram_h`, ``kwargs`` passed on)."""
    if h_route == "logkernel":
        return gram_h_logkernel(space), dict(L2_INFO)
    if h_route == "series":
        return gram_h(space, **kwargs)
    raise InputError("h_route", ", ".join(H_ROUTES), got=h_route)


def gram(space: SegmentSpace, norm: str, h_route: str = "logkernel", **kwargs) -> tuple[np.ndarray, dict]:
    """Gram matrix of ``space`` for ``norm`` ∈ {"H", "L2"}.

    Parameters
    ----------
    space : SegmentSpace
        The multiplier space.
    norm : {"H", "L2"}
        "H": the M = (H^{1/2}_00(Γ))' norm of Bathe & Brezzi (2001), eq. (3.9), see
        :func:`gram_h_route` (``kwargs`` are passed on); "L2": the exact L²(Γ) mass matrix.
    h_route : {"logkernel", "series"}
        Route for "H": the closed-form log kernel (no truncation; ``n_max`` = 0 and
        ``nmax_rel_error`` = 0.0 are reported) or the truncated, extrapolated sine series.

    Returns
    -------
    G : ndarray, shape (dim, dim)
    info : dict
        ``n_max`` and ``nmax_rel_error`` (0 and 0.0 for "L2").

    Raises
    ------
    InputError
        For an unknown ``norm`` (:func:`gram_by_norm`) or, with "H", an unknown ``h_route``.
    """
    return gram_by_norm(norm, lambda: gram_l2(space), lambda **kw: gram_h_route(space, h_route, **kw), **kwargs)
