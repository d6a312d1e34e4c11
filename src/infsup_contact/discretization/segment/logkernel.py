"""Truncation-free Gram matrix of the dual norm of H^{1/2}_00(Γ), Γ = (0, 1).

The norm used by Bathe & Brezzi (2001), eq. (3.9), for the multipliers is the dual norm
of H^{1/2}_00(Γ). With the orthonormal sine basis √2 sin(nπx) of L²(Γ) it reads

    ‖μ‖²_M = Σ_{n≥1} μ_n² / (nπ),        μ_n = √2 ∫_Γ μ(x) sin(nπx) dx.

Writing μ_n² = ∬ μ(x) μ(y) [cos(nπ(x−y)) − cos(nπ(x+y))] dx dy and summing with the
series identity Σ_{n≥1} cos(nθ)/n = −ln|2 sin(θ/2)| (θ ∉ 2πℤ) gives the closed form

    ‖μ‖²_M = (1/π) ∬_{Γ×Γ} μ(x) μ(y) k(x, y) dx dy,
    k(x, y) = ln| sin(π(x+y)/2) / sin(π(x−y)/2) |.

This module assembles G_ij = (1/π) ∬ φ_i φ_j k for a :class:`SegmentSpace` without
truncating the series; :mod:`norms` computes the same matrix by the truncated series.

Quadrature
----------
k is log-singular on the diagonal x = y and at the corners (0, 0) and (1, 1). It splits as

    k = −ln|x − y| + ln(x + y) + ln(2 − x − y) + S(x, y),
    S = ln sinc(t/2) − ln(2 − t) − ln sinc((x − y)/2),   t = min(x + y, 2 − x − y),

(numpy's sinc(u) = sin(πu)/(πu)); S is analytic on a complex neighbourhood of
[0, 1]² (its nearest singularities are x − y = ±2 and x + y ∈ {−2, 4}), and using t
only serves accurate evaluation near x + y = 2 (S is symmetric in x + y ↔ 2 − x − y).

For each interval pair (I, J):

* *Admissible pairs*, whose distance δ = min(dist(I, J), dist(I, −J), dist(I, 2 − J))
  to all singular sets satisfies δ ≥ max(|I|, |J|): tensor Gauss–Legendre on the full
  kernel k; the order is chosen from the Bernstein-ellipse parameter ρ of
  r = 1 + δ / max(|I|, |J|) so that ρ^{−(2q − s − 1)} ≲ 1e-16; pairs are grouped by
  order and each group is one batched matrix product.
* *Near pairs* (the rest: identical, adjacent, corner and badly size-graded pairs):
  S by tensor Gauss (r = 1 + 1/max(|I|, |J|)), and each log term ln|ℓ(x, y)| with ℓ
  linear by the exact reduction to one dimension,

      ∬_{I×J} P(x) Q(y) ln|ℓ| dx dy = ∫ ln|z| W(z) dz,
      W(z) = ∫_{x ∈ I, y(x, z) ∈ J} P(x) Q(y(x, z)) dx,

  where W is a polynomial of degree ≤ 2s + 1 on each piece between the values of ℓ at
  the corners of I × J (and 0). W is evaluated by Gauss–Legendre in x (exact); the
  outer integral on a piece [A, B] (in |z|) uses an interpolatory rule exact for
  polynomial × ln z on [0, B] (minus the same on [0, A], the polynomial continued) when
  A < B − A, and Gauss–Legendre (ln z analytic, ρ ≥ 3 + √8) otherwise. This is exact
  up to rounding for the polynomial × log terms.

References
----------
K.J. Bathe, F. Brezzi, Stability of finite element mixed interpolations for contact
problems, Rend. Lincei Mat. Appl. 12 (2001) 167–183, eq. (3.9).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ...errors import InputError
from .multipliers import SegmentSpace, local_shapes
from ..gamma.quadrature import gauss_legendre_01

__all__ = ["gram_h_logkernel", "log_kernel"]

_LOG_INV_TOL = np.log(1e16)  # target ρ^{-m} ≲ 1e-16 for Gauss on analytic integrands
_CHUNK = 4_000_000  # max kernel evaluations per batched block

# the three log terms: (σx, σy, c0, coefficient in k) for ln|σx x + σy y + c0|
_LOG_TERMS = ((-1.0, 1.0, 0.0, -1.0),  # −ln|y − x|
              (1.0, 1.0, 0.0, 1.0),  # +ln(x + y)
              (-1.0, -1.0, 2.0, 1.0))  # +ln(2 − x − y)


def log_kernel(x, y):
    """The kernel k(x, y) = ln|sin(π(x+y)/2) / sin(π(x−y)/2)| on (0, 1)².

    Parameters
    ----------
    x, y : array_like
        Points of (0, 1), broadcast against each other.

    Returns
    -------
    ndarray
        k(x, y); +inf on the diagonal.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    s = x + y
    t = np.minimum(s, (1.0 - x) + (1.0 - y))  # sin(πs/2) = sin(πt/2), accurate near s = 2
    with np.errstate(divide="ignore"):
        return np.log(np.sin(0.5 * np.pi * t)) - np.log(np.sin(0.5 * np.pi * np.abs(x - y)))


def _smooth_remainder(x, y):
    """S = k + ln|x − y| − ln(x + y) − ln(2 − x − y), analytic on [0, 1]²."""
    t = np.minimum(x + y, (1.0 - x) + (1.0 - y))
    return np.log(np.sinc(0.5 * t)) - np.log(2.0 - t) - np.log(np.sinc(0.5 * (x - y)))


@lru_cache(maxsize=None)
def _log_rule01(n: int):
    """Interpolatory rule on the n Gauss–Legendre nodes of [0, 1] for the weight ln u.

    Returns nodes u, Gauss weights λ and log weights m with
    Σ m_i p(u_i) = ∫_0^1 ln(u) p(u) du exactly for deg p ≤ n − 1. Built from the
    Lagrange basis ℓ_i = λ_i Σ_k (2k+1) P̃_k(u_i) P̃_k and the modified moments
    ∫_0^1 ln(u) P̃_k(u) du = −1 (k = 0), (−1)^{k+1} / (k(k+1)) (k ≥ 1).
    """
    u, lam = gauss_legendre_01(n)
    k = np.arange(n)
    mom = np.empty(n)
    mom[0] = -1.0
    mom[1:] = (-1.0) ** (k[1:] + 1) / (k[1:] * (k[1:] + 1.0))
    vander = np.polynomial.legendre.legvander(2.0 * u - 1.0, n - 1)  # P̃_k(u_i)
    m = lam * (vander @ ((2.0 * k + 1.0) * mom))
    return u, lam, m


def _gauss_order(ratio, s: int, scale: int) -> np.ndarray:
    """Gauss order for a kernel analytic up to ``ratio`` interval lengths beyond the interval.

    With r = 1 + ratio and ρ = r + √(r² − 1), choose q with ρ^{-(2q − s − 1)} ≲ 1e-16.
    """
    r = 1.0 + np.asarray(ratio, dtype=float)
    rho = r + np.sqrt(r * r - 1.0)
    q = np.ceil(0.5 * (_LOG_INV_TOL / np.log(rho) + s + 1.0)).astype(int)
    return scale * np.maximum(q, s + 1)


def _tensor_gauss(kernel, aI, hI, aJ, hJ, s: int, q: int) -> np.ndarray:
    """∬_{I×J} φ_a(x) φ_b(y) kernel(x, y) by tensor Gauss of order q, shape (P, s+1, s+1)."""
    tau, lam = gauss_legendre_01(q)
    phiw = local_shapes(s, tau) * lam[:, None]  # (q, s+1)
    out = np.empty((len(aI), s + 1, s + 1))
    step = max(1, _CHUNK // (q * q))
    for lo in range(0, len(aI), step):
        sl = slice(lo, lo + step)
        x = aI[sl, None] + hI[sl, None] * tau[None, :]
        y = aJ[sl, None] + hJ[sl, None] * tau[None, :]
        kmat = kernel(x[:, :, None], y[:, None, :])  # (p, q, q)
        out[sl] = (hI[sl] * hJ[sl])[:, None, None] * (phiw.T @ (kmat @ phiw))
    return out


def _log_term(aI, bI, aJ, bJ, term, s: int, n_log: int, n_x: int, q_piece: int) -> np.ndarray:
    """∬_{I×J} φ_a(x) φ_b(y) ln|σx x + σy y + c0| dx dy for each pair, shape (P, s+1, s+1).

    Exact (up to rounding) reduction to ∫ ln|z| W(z) dz, see the module docstring.
    """
    sx, sy, c0, _ = term
    kappa = -sx * sy  # y(x, z) = sy (z − c0) + κ x
    hI, hJ = bI - aI, bJ - aJ
    corners = np.stack([sx * aI + sy * aJ + c0, sx * aI + sy * bJ + c0,
                        sx * bI + sy * aJ + c0, sx * bI + sy * bJ + c0], axis=1)
    zero = np.clip(0.0, corners.min(axis=1), corners.max(axis=1))
    zs = np.sort(np.concatenate([corners, zero[:, None]], axis=1), axis=1)  # (P, 5)
    alpha, beta = zs[:, :-1], zs[:, 1:]  # 4 pieces, none straddles 0
    neg = beta <= 0.0
    A = np.where(neg, -beta, alpha)  # piece in |z|: [A, B], 0 <= A <= B
    B = np.where(neg, -alpha, beta)
    sgn = np.where(neg, -1.0, 1.0)

    # rule exact for polynomial × ln z on [0, L]: nodes L u, weights L (λ ln L + m)
    u, lam_u, m_u = _log_rule01(n_log)

    def rule0(L):
        pos = L > 0.0
        lnL = np.log(np.where(pos, L, 1.0))
        w = np.where(pos, L, 0.0)[..., None] * (lam_u * lnL[..., None] + m_u)
        return L[..., None] * u, w

    zb, wb = rule0(B)
    za, wa = rule0(A)
    # Gauss–Legendre on [A, B] when ln z is analytic there with A >= B − A (ρ >= 3 + √8)
    tau, lam = gauss_legendre_01(q_piece)
    zg = A[..., None] + (B - A)[..., None] * tau
    lng = np.log(np.where(zg > 0.0, zg, 1.0))
    wg = (B - A)[..., None] * lam * lng
    n_nodes = max(2 * n_log, q_piece)

    def pad(arr):
        return np.pad(arr, [(0, 0), (0, 0), (0, n_nodes - arr.shape[-1])])

    use_log = (A < B - A)[..., None]
    z = np.where(use_log, pad(np.concatenate([zb, za], axis=-1)), pad(zg))
    w = np.where(use_log, pad(np.concatenate([wb, -wa], axis=-1)), pad(wg))
    z = sgn[..., None] * z  # back to signed z, shape (P, 4, n_nodes)

    def x_bounds(zz):
        """Linear x-range {x : y(x, zz) ∈ J}, arrays broadcast to zz's shape."""
        c_, d_ = aJ.reshape((-1,) + (1,) * (zz.ndim - 1)), bJ.reshape((-1,) + (1,) * (zz.ndim - 1))
        v = sy * (zz - c0)
        return (c_ - v, d_ - v) if kappa > 0 else (v - d_, v - c_)

    # which bound is active on each piece: decided at the piece midpoint
    zmid = sgn * 0.5 * (A + B)
    lo_mid, hi_mid = x_bounds(zmid)
    keep_a = (aI[:, None] >= lo_mid)[..., None]
    keep_b = (bI[:, None] <= hi_mid)[..., None]
    lo, hi = x_bounds(z)
    L = np.where(keep_a, aI[:, None, None], lo)
    R = np.where(keep_b, bI[:, None, None], hi)

    tx, lx = gauss_legendre_01(n_x)
    xg = L[..., None] + (R - L)[..., None] * tx  # (P, 4, n_nodes, n_x)
    yg = sy * (z[..., None] - c0) + kappa * xg
    P = len(aI)
    px = local_shapes(s, ((xg - aI[:, None, None, None]) / hI[:, None, None, None]).ravel())
    qy = local_shapes(s, ((yg - aJ[:, None, None, None]) / hJ[:, None, None, None]).ravel())
    coef = (w * (R - L))[..., None] * lx  # (P, 4, n_nodes, n_x)
    px = px.reshape(P, -1, s + 1) * coef.reshape(P, -1, 1)
    qy = qy.reshape(P, -1, s + 1)
    return np.swapaxes(px, 1, 2) @ qy


def clear_partition_cache() -> None:
    """Forget the cached element integrals of every partition (:func:`_local_blocks`): a
    benchmark clears them before each timed call so that a repeat is not a cache lookup."""
    _local_blocks.cache_clear()


@lru_cache(maxsize=8)
def _local_blocks(xb_bytes: bytes, s: int, scale: int) -> np.ndarray:
    """Element integrals ∬_{I×J} φ_a(x) φ_b(y) k(x, y) dx dy (without the 1/π) of the local
    Lagrange basis of degree s, for every interval pair I <= J (``np.triu_indices`` order) of
    the partition given as float64 bytes; shape (P, s + 1, s + 1), read-only.

    They depend only on the partition and s, not on the space built on it: T3 and R5.2 (and
    the dual bases, through their local coefficients) share them, so do the three multiplier
    meshes of a matching pair. Cached, so each is integrated once per mesh pair.
    """
    xb = np.frombuffer(xb_bytes)
    n = len(xb) - 1

    # interval pairs i <= j (k is symmetric)
    iu, ju = np.triu_indices(n)
    aI, bI, aJ, bJ = xb[iu], xb[iu + 1], xb[ju], xb[ju + 1]
    hI, hJ = bI - aI, bJ - aJ
    hmax = np.maximum(hI, hJ)
    gap = np.maximum(aJ - bI, 0.0)
    delta = np.minimum.reduce([gap, aI + aJ, (1.0 - bI) + (1.0 - bJ), np.ones_like(gap)])
    far = delta >= hmax
    loc = np.empty((len(iu), s + 1, s + 1))

    # admissible pairs: full kernel, tensor Gauss grouped by order
    q_far = _gauss_order(np.where(far, delta / hmax, 1.0), s, scale)
    for q in np.unique(q_far[far]):
        sel = np.flatnonzero(far & (q_far == q))
        loc[sel] = _tensor_gauss(log_kernel, aI[sel], hI[sel], aJ[sel], hJ[sel], s, int(q))

    # near pairs: smooth remainder by Gauss + exact log terms
    near = np.flatnonzero(~far)
    if near.size:
        q_s = _gauss_order(1.0 / hmax[near], s, scale)
        for q in np.unique(q_s):
            sel = near[q_s == q]
            loc[sel] = _tensor_gauss(_smooth_remainder, aI[sel], hI[sel], aJ[sel], hJ[sel], s, int(q))
        n_log, n_x = scale * (2 * s + 2), scale * (s + 1)
        q_piece = int(_gauss_order(2.0, 2 * s + 1, scale))  # r = 1 + 2A/(B−A) >= 3
        step = max(1, _CHUNK // (4 * max(2 * n_log, q_piece) * n_x * (s + 1)))
        for lo in range(0, near.size, step):
            sel = near[lo:lo + step]
            for term in _LOG_TERMS:
                loc[sel] += term[3] * _log_term(aI[sel], bI[sel], aJ[sel], bJ[sel], term,
                                                s, n_log, n_x, q_piece)

    loc.flags.writeable = False
    return loc


def gram_h_logkernel(space: SegmentSpace, *, quad_scale: int = 1) -> np.ndarray:
    """Gram matrix of the H^{1/2}_00(Γ)-dual norm by the log-kernel double integral.

    G_ij = (1/π) ∬_{(0,1)²} φ_i(x) φ_j(y) k(x, y) dx dy with
    k(x, y) = ln|sin(π(x+y)/2) / sin(π(x−y)/2)|, the closed-form sum of the sine series
    Σ_n μ_n² / (nπ) of the norm of Bathe & Brezzi (2001), eq. (3.9) (see module
    docstring). No truncation; singular parts are integrated exactly, smooth parts by
    Gauss–Legendre with orders set for ≈ 1e-16 relative error.

    Parameters
    ----------
    space : SegmentSpace
        Multiplier space on a partition of Γ = (0, 1) (first breakpoint 0, last 1).
    quad_scale : int, optional
        Multiplies every quadrature order (for convergence checks); default 1.

    Returns
    -------
    ndarray, shape (dim, dim)
        Symmetric positive definite Gram matrix, μᵀ G μ = ‖μ‖²_M.

    Raises
    ------
    InputError
        If ``space`` is not a :class:`SegmentSpace`, its breakpoints do not span
        [0, 1], or ``quad_scale`` is not a positive integer.
    """
    if not isinstance(space, SegmentSpace):
        raise InputError("space", "a SegmentSpace", got=type(space).__name__)
    if isinstance(quad_scale, bool) or not isinstance(quad_scale, (int, np.integer)) or quad_scale < 1:
        raise InputError("quad_scale", "a positive integer", got=quad_scale)
    xb = np.asarray(space.breakpoints, dtype=float)
    if abs(xb[0]) > 1e-14 or abs(xb[-1] - 1.0) > 1e-14:
        raise InputError("breakpoints", "a partition of Γ = (0, 1) (first 0, last 1)",
                         got=(float(xb[0]), float(xb[-1])))
    xb = xb.copy()
    xb[0], xb[-1] = 0.0, 1.0
    n = len(xb) - 1
    iu, ju = np.triu_indices(n)
    loc = _local_blocks(xb.tobytes(), int(space.degree), int(quad_scale))

    if space.local_coefficients is not None:  # C_I loc C_Jᵀ for the space's own local basis
        loc = np.swapaxes(space.to_local_basis(np.swapaxes(space.to_local_basis(loc, iu), 1, 2), ju), 1, 2)

    # scatter: block (i, j) = loc, block (j, i) = locᵀ
    dofs = np.asarray(space.dofs)
    rows = dofs[iu][:, :, None]
    cols = dofs[ju][:, None, :]
    rows, cols = np.broadcast_arrays(rows, cols)
    vals = loc
    mirror = iu != ju
    rows_all = np.concatenate([rows.ravel(), np.swapaxes(cols[mirror], 1, 2).ravel()])
    cols_all = np.concatenate([cols.ravel(), np.swapaxes(rows[mirror], 1, 2).ravel()])
    vals_all = np.concatenate([vals.ravel(), np.swapaxes(vals[mirror], 1, 2).ravel()])
    ok = (rows_all >= 0) & (cols_all >= 0)
    dim = int(space.dim)
    g = np.bincount(rows_all[ok] * dim + cols_all[ok], weights=vals_all[ok],
                    minlength=dim * dim).reshape(dim, dim)
    return (0.5 / np.pi) * (g + g.T)
