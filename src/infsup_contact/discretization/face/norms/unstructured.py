"""Gram matrices of P_s spaces on general triangulations of Γ = (0, 1)².

L²(Γ): exact, the Duffy rule of :mod:`.face.partitions.quadrature` on the triangles of G_h (degree 2s).

M = H^{1/2}_00(Γ)': the double sine series of :mod:`.face.norms.tensor`,
‖μ‖²_M = Σ_{m,n≥1} μ_mn² / (π√(m² + n²)), μ_mn = 2 ∬ μ sin(mπx) sin(nπy), truncated to
m, n ≤ n_max and extrapolated in n_max (:func:`~.face.norms.tensor.extrapolated`, tail exponents of
:data:`~.face.norms.triangles.TAIL_EXPONENTS`). :mod:`.face.norms.triangles` factorises the
coefficients on axis-parallel triangles; a general triangle has no such factorisation, so the
coefficients come from the closed-form Fourier transform of a polynomial on a triangle:

* 2 ∬ φ sin(mπx) sin(nπy) = −Re[Φ(π(m, n)) − Φ(π(m, −n))] with Φ(k) = ∫_T φ e^{i k·x};
* on T = A + [B − A, C − A] T̂, Φ(k) = 2|T| e^{i k·A} F(φ̂)(κ), κ = (k·(B − A), k·(C − A)), and
  for the monomials ξ^a η^b of the reference triangle T̂ the divergence theorem with
  e^{iκ·ξ} = ∇·(−iκ e^{iκ·ξ}/|κ|²) gives (Gauss–Green)

      F_ab = −i/|κ|² [ Σ_edges (κ·ν_E) ∫_E ξ^a η^b e^{iκ·ξ} ds − a κ1 F_{a−1,b} − b κ2 F_{a,b−1} ],

  whose edge integrals are the moments ∫_0^1 t^j e^{iωt} dt
  (:func:`~.face.norms.triangles.moments`, the structured triangles' own: exact for every ω, a
  series for small |ω|);
* below |κ| = :data:`SMALL` the recursion would cancel, and the integrand is smooth: a Duffy
  rule of degree :data:`SMALL_DEGREE` (error ~ |κ|^{d+1}/(d+1)! ≪ ε) replaces it.

Cost O(nt · n_max² · s²) per partial sum, vectorised over triangles and blocks of m.
"""
from __future__ import annotations

from math import comb

import numpy as np

from ....errors import InputError
from .tensor import extrapolated
from ..partitions.quadrature import duffy_rule, triangles_rule
from .triangles import TAIL_EXPONENTS, moments, tail_key
from ..spaces.triangles import lagrange_barycentric
from ...segment.norms import N_MAX_CAP, gram_by_norm

SMALL = 2.0
"""|κ| below which F is integrated by a Duffy rule instead of the recursion."""
SMALL_DEGREE = 34
"""Degree of that rule: |κ|^35/35! < 1e-30 for |κ| < 2."""
_CHUNK = 8


def monomials(s: int) -> list:
    """Exponents (a, b) of the monomials ξ^a η^b, a + b ≤ s, by total degree."""
    return [(a, d - a) for d in range(s + 1) for a in range(d, -1, -1)]


def monomial_coefficients(s: int) -> np.ndarray:
    """C (n_mono, nloc): the Lagrange basis φ_l(ξ, η) (barycentric λ = (1 − ξ − η, ξ, η))
    = Σ_j C[j, l] ξ^{a_j} η^{b_j}, from the values on the P_s lattice (s = 0: the constant)."""
    from ..spaces.triangles import local_lattice

    al = local_lattice(s).astype(float) / max(s, 1)
    xi, eta = al[:, 1], al[:, 2]
    V = np.column_stack([xi ** a * eta ** b for a, b in monomials(s)])
    L = lagrange_barycentric(al, s)
    return np.linalg.solve(V, L)


def reference_transforms(k1: np.ndarray, k2: np.ndarray, s: int, e1=None, e2=None) -> np.ndarray:
    """F_ab(κ) = ∫_T̂ ξ^a η^b e^{i(κ1 ξ + κ2 η)}, shape (n_mono, *κ.shape), module docstring;
    ``e1``, ``e2``: e^{iκ1}, e^{iκ2} if already known."""
    k1, k2 = np.asarray(k1, float), np.asarray(k2, float)
    e1 = np.exp(1j * k1) if e1 is None else e1
    e2 = np.exp(1j * k2) if e2 is None else e2
    mono = monomials(s)
    kk = k1 ** 2 + k2 ** 2
    small = kk < SMALL ** 2
    scale = -1j / np.where(small, 1.0, kk)  # the recursion where |κ| ≥ SMALL
    M1, M2 = moments(k1, s, e1), moments(k2, s, e2)
    M12 = moments(k2 - k1, s, e2 * np.conj(e1))
    F = {}
    out = np.empty((len(mono),) + k1.shape, dtype=complex)
    for i, (a, b) in enumerate(mono):
        edges = (k1 + k2) * e1 * sum(comb(a, c) * (-1) ** c * M12[b + c] for c in range(a + 1))
        if b == 0:
            edges -= k2 * M1[a]
        if a == 0:
            edges -= k1 * M2[b]
        if a:
            edges -= a * k1 * F[(a - 1, b)]
        if b:
            edges -= b * k2 * F[(a, b - 1)]
        np.multiply(scale, edges, out=out[i])
        F[(a, b)] = out[i]
    if small.any():
        u, v, w = duffy_rule(SMALL_DEGREE)
        ph = np.exp(1j * (np.outer(k1[small], u) + np.outer(k2[small], v))) * w[None, :]
        out[:, small] = np.stack([ph @ (u ** a * v ** b) for a, b in mono])
    return out


def sine_coefficients(space, m: np.ndarray, n: np.ndarray) -> np.ndarray:
    """μ_mn = 2 ∬ φ sin(mπx) sin(nπy) of every basis function of a
    :class:`~.face.spaces.unstructured.MeshTriangleSpace`, for the frequencies ``m`` × ``n``:
    shape (dim, len(m), len(n)). The exponentials of κ are outer products of 1D ones."""
    m, n = np.asarray(m, float), np.asarray(n, float)
    c = space.breakpoints.corners  # (T, 3, 2)
    A, e1, e2 = c[:, 0], c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    jac = 2.0 * space.breakpoints.areas
    C = monomial_coefficients(space.s)  # (n_mono, nloc)

    def wave(v, sign):
        """(π(m v_x + sign n v_y) (T, m, n), its exponential) for vectors v (T, 2)."""
        px, py = np.pi * np.outer(v[:, 0], m), sign * np.pi * np.outer(v[:, 1], n)
        return px[:, :, None] + py[:, None, :], np.exp(1j * px)[:, :, None] * np.exp(1j * py)[:, None, :]

    nt, nloc = space.breakpoints.cells, space.n_local
    local = np.zeros((nloc, nt * len(m) * len(n)))
    for sign in (1.0, -1.0):
        (k1, x1), (k2, x2), (_, xa) = wave(e1, sign), wave(e2, sign), wave(A, sign)
        F = reference_transforms(k1, k2, space.s, x1, x2)  # (mono, T, m, n)
        F *= (jac[:, None, None] * xa)[None]
        local -= sign * (C.T @ F.real.reshape(len(C), -1))  # −Re[Φ(m, n) − Φ(m, −n)], per local function
    local = np.ascontiguousarray(local.reshape(nloc, nt, -1).transpose(1, 0, 2))  # (T, nloc, m n)
    if space.dual:
        local = np.matmul(space.local_matrices(), local)  # ψ = Â N
    flat = local.reshape(nt * nloc, -1)
    return np.asarray(space.scatter() @ flat).reshape(space.dim, len(m), len(n))


def _weighted(space, m: np.ndarray, n: np.ndarray) -> np.ndarray:
    """μ_mn / √(π √(m² + n²)), flattened to (dim, len(m) len(n)), in blocks of m."""
    out = []
    for start in range(0, len(m), _CHUNK):
        mm = m[start:start + _CHUNK]
        Cf = sine_coefficients(space, mm, n)
        Cf *= (1.0 / np.sqrt(np.pi * np.sqrt(mm[:, None] ** 2 + n[None, :] ** 2)))[None]
        out.append(Cf.reshape(space.dim, -1))
    return np.hstack(out)


def partial_gram(space, n_max: int, previous: tuple | None = None) -> np.ndarray:
    """S(n_max) = Σ_{m,n ≤ n_max} μ_mn μ_mnᵀ / (π√(m² + n²)); ``previous`` = (n, S(n)) with
    n ≤ n_max adds only the frequencies with max(m, n) > n (the coefficients do not depend on
    the truncation)."""
    n0, G = (0, np.zeros((space.dim, space.dim))) if previous is None else (previous[0], previous[1].copy())
    old = np.arange(1, n0 + 1, dtype=float)
    new = np.arange(n0 + 1, n_max + 1, dtype=float)
    full = np.arange(1, n_max + 1, dtype=float)
    for m, n in ((old, new), (new, full)):
        if len(m) and len(n):
            Cf = _weighted(space, m, n)
            G += Cf @ Cf.T
    return 0.5 * (G + G.T)


def gram_l2(space) -> np.ndarray:
    """Exact L²(Γ) Gram matrix of a :class:`~.face.spaces.unstructured.MeshTriangleSpace`."""
    u, v, _ = duffy_rule(2 * space.degree)  # triangles_rule's points: corner 0 + u e1 + v e2
    x, w = triangles_rule(space.triangles(), 2 * space.degree)
    tri = np.repeat(np.arange(space.breakpoints.cells), len(u))
    lam = np.tile(np.column_stack([1.0 - u - v, u, v]), (space.breakpoints.cells, 1))
    phi = space.evaluate_located(tri, lam)
    G = phi.T @ (w[:, None] * phi)
    return 0.5 * (G + G.T)


def gram_h(space, rtol: float = 1e-6, n_start: int | None = None, n_cap: int = N_MAX_CAP // 64,
           exponent: float | None = None) -> tuple[np.ndarray, dict]:
    """H^{1/2}_00(Γ)' Gram matrix, partial sums from n0 = max(16, 2 (s + 1) N) (N: nominal cells
    per direction of G_h), doubled and extrapolated as :func:`~.face.norms.triangles.gram_h_tri`."""
    if not rtol > 0:
        raise InputError("rtol", "a positive float", got=rtol)
    p = TAIL_EXPONENTS[tail_key(space)] if exponent is None else float(exponent)
    n0 = max(16, 2 * (space.degree + 1) * max(space.shape)) if n_start is None else int(n_start)
    if n0 < 1 or n_cap < 1:
        raise InputError("n_start/n_cap", "positive integers", got=(n_start, n_cap))
    last = {}

    def partial(k):  # the loop asks n0, 2 n0, 4 n0, ...: each sum extends the previous one
        prev = max((j for j in last if j <= k), default=None)
        S = partial_gram(space, k, None if prev is None else (prev, last[prev]))
        last.clear()
        last[k] = S
        return S

    return extrapolated(partial, p, n0, n_cap, rtol)


def gram(space, norm: str, **kwargs) -> tuple[np.ndarray, dict]:
    """Gram matrix for ``norm`` ∈ {"H", "L2"} (``kwargs`` to :func:`gram_h`)."""
    return gram_by_norm(norm, lambda: gram_l2(space), lambda **kw: gram_h(space, **kw), **kwargs)
