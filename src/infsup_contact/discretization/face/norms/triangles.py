"""Gram matrices of the triangle multiplier spaces (:mod:`.face.spaces.triangles`) on Γ = (0, 1)².

L²(Γ): exact, by the collapsed (Duffy) Gauss rule of :mod:`.face.partitions.quadrature` on the triangles of
G_h, exact for the total degree 2s of a product of two P_s functions.

M = H^{1/2}_00(Γ)': the double sine series of :mod:`.face.norms.tensor`,
‖μ‖²_M = Σ_{m,n≥1} μ_mn² / (π√(m² + n²)), μ_mn = 2 ∬ μ sin(mπx) sin(nπy), truncated to
m, n ≤ n_max and extrapolated in n_max (:func:`~.face.norms.tensor.extrapolated`). The basis functions
are not tensor products, so their coefficients are computed triangle by triangle:

* on a triangle T with lower-left corner (x0, y0) and sides hx, hy, the addition formula
  sin(mπ(x0 + hx ξ)) = sin(mπx0) cos(mπhx ξ) + cos(mπx0) sin(mπhx ξ) (and in y) reduces the
  coefficients to four reference integrals R_ab[l, m, n] = hx hy ∫_T̂ φ_l f_a(mπhx ξ) g_b(nπhy η),
  computed once per triangle shape (a uniform grid has two);
* R_ab by the Duffy rule ξ = u, η = u t (lower triangle; η = u, ξ = u t for the upper one), in
  which the outer oscillation depends on u only, so the rule factorises into two matrix
  products; its Gauss order q grows with the largest phase π n_max (hx + hy) so that the
  integrals are exact up to round-off (Gauss–Legendre converges geometrically once
  q > e ω / 4 for a phase ω on [−1, 1]; :func:`coefficient_points`).

The tail exponent of the truncated square is measured (:func:`~.face.norms.tensor.tail_exponent`'s
ratio of increments, :func:`tail_exponent`), not assumed: it decides the Richardson step.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import sparse

from ....errors import InputError
from .tensor import extrapolated
from ..partitions.quadrature import triangles_rule
from ..symmetry import KleinGram, ReflectedGram, reflection, transposition
from ..spaces.triangles import lagrange_barycentric
from ...segment.norms import N_MAX_CAP, gram_by_norm
from ....la.richardson import _norm2

#: Values (float64) per working array of :func:`sine_coefficients_chunk` (2^23: 64 MB): its
#: output (dim × rows of m × n_max; :func:`chunk_rows`).
_BUDGET = 2 ** 23
#: Columns n per product W U in :func:`_coefficients`: a block of the stacked U (about 7,000 rows at
#: s = 2, N = 8, 64 columns: 3.5 MB) stays in the cache while the sparse product reads each of its
#: rows about eight times (once per cell of a row of cells). The whole U (57 MB at 1,024 columns)
#: did not: W U in blocks of 64 columns took 0.033 s against 0.19–0.24 s whole, the same bits
#: (each entry the same sum, in the same order); 32 and 128 columns were no faster.
_COLUMNS = 64
#: Tail exponents p (‖S(∞) − S(n)‖ ~ n^{−p}) measured by :func:`tail_exponent` on
#: N = 2, 4, s = 0..2, n = 32, 128 (tests/discretization/face/test_face_triangles.py); keys :func:`tail_key`.
TAIL_EXPONENTS = {(True, True): 4.0, (True, False): 2.0, (False, False): 2.0}


def gram_l2_tri(space) -> np.ndarray:
    """Exact L²(Γ) Gram matrix ∫ φ_i φ_j of a :class:`~.face.spaces.triangles.TriangleSpace`."""
    x, w = triangles_rule(space.triangles(), 2 * space.degree)
    phi = space.evaluate(x)
    G = phi.T @ (w[:, None] * phi)
    return 0.5 * (G + G.T)


def coefficient_points(n_max: int, h: float, s: int) -> int:
    """Gauss points of the outer Duffy variable for phases up to ω = π n_max h on [0, 1]
    (h = hx + hy): a degree ≳ ω/2 + 2 (ω/2)^{1/3} polynomial resolves e^{iωu} there."""
    w = 0.5 * np.pi * n_max * h
    return int(np.ceil(0.5 * w + 2.0 * w ** (1.0 / 3.0))) + s + 12


#: Below |ω| = 2 the moments use the Taylor series (the recursion divides by ω); 32 terms:
#: 2^32/32! < 1e-25.
_SERIES_BELOW, _SERIES_TERMS = 2.0, 32


def moments(omega: np.ndarray, jmax: int, e: np.ndarray | None = None) -> list:
    """[M_j(ω) = ∫_0^1 t^j e^{iωt} dt for j = 0..jmax], each complex of ω's shape: the
    recursion M_j = (e^{iω} − j M_{j−1})/(iω) for |ω| ≥ 2 (an error of M_{j−1} enters M_j times
    j/|ω|: at most jmax!/2^jmax in all, 1.5 for jmax = 4), the series Σ_k (iω)^k / (k! (j + k + 1))
    below. ``e``: e^{iω} where the caller has it already
    (:func:`~.face.norms.unstructured.reference_transforms` forms it from products of
    one-dimensional exponentials). The one route of these moments, for the structured and the
    general triangles; a list, not one stacked array (a fresh array of all jmax + 1 costs its
    page faults on every call)."""
    omega = np.asarray(omega, dtype=float)
    e = np.exp(1j * omega) if e is None else e
    small = np.abs(omega) < _SERIES_BELOW
    r = -1j / np.where(small, 1.0, omega)  # 1/(iω): a product per step, not a complex division
    out, prev = [], (e - 1.0) * r
    out.append(prev)
    for j in range(1, jmax + 1):
        prev = (e - j * prev) * r
        out.append(prev)
    if small.any():
        z = 1j * omega[small]
        term = np.ones_like(z)
        acc = np.zeros((jmax + 1, z.size), dtype=complex)
        for k in range(_SERIES_TERMS):
            acc += term[None, :] / (np.arange(jmax + 1)[:, None] + k + 1.0)
            term = term * z / (k + 1.0)
        for j in range(jmax + 1):
            out[j][small] = acc[j]
    return out


class _Shape:
    """The reference integrals R_ab of one triangle shape (lower or upper triangle of the
    rectangle [0, hx] × [0, hy]) for n = 1..n_max and any block of m (module docstring):
    ξ = u, η = u t (lower) or η = u, ξ = u t (upper); the inner t integral is exact
    (φ_l(u, u t) is a polynomial of degree ≤ s in t times e^{iωt}: :func:`moments`), the outer
    one a q-point Gauss rule in u, the variable that carries x (lower) or y (upper)."""

    def __init__(self, hx: float, hy: float, upper: bool, s: int, n: np.ndarray, q: int):
        from ...gamma.quadrature import gauss_legendre_01

        u, wu = gauss_legendre_01(q)
        tn = np.linspace(0.0, 1.0, s + 1) if s > 0 else np.zeros(1)
        U, T = np.meshgrid(u, tn, indexing="ij")
        xi, eta = (U * T, U) if upper else (U, U * T)
        lam = (np.stack([1.0 - eta, xi, eta - xi], -1) if upper
               else np.stack([1.0 - xi, xi - eta, eta], -1)).reshape(-1, 3)
        vals = lagrange_barycentric(lam, s).reshape(q, s + 1, -1)  # (q, t node, l)
        V = tn[:, None] ** np.arange(s + 1)[None, :]
        self.A = np.linalg.solve(V, vals.transpose(1, 0, 2).reshape(s + 1, -1)).reshape(s + 1, q, -1)  # (j, q, l)
        self.u, self.upper, self.s, self.hx, self.hy = u, upper, s, hx, hy
        w = wu * u * hx * hy
        if upper:  # outer y over all n: (n, q) matrices, fixed
            self.outer = {a: (f(np.outer(n * np.pi * hy, u)) * w[None, :]) for a, f in (("c", np.cos), ("s", np.sin))}
        else:  # inner y over all n: D_b (q, n, l), fixed
            self.inner = self._inner(n * np.pi * hy)
            self.w = w

    def _inner(self, freq: np.ndarray) -> dict:
        """{"c", "s"}: ∫_0^1 φ_l(u_q, ·) {cos, sin}(freq u_q t) dt, shape (q, len(freq), l)."""
        M = np.array(moments(self.u[:, None] * freq[None, :], self.s))  # (j, q, f)
        D = np.einsum("jqf,jql->qfl", M, self.A)
        return {"c": D.real, "s": D.imag}

    def integrals(self, m: np.ndarray, n_from: int = 1) -> dict:
        """{(x-function, y-function): R[l, m, n]} for the block ``m`` and n = n_from..n_max (the
        columns a block of the transposition's half asks: about half of them on average)."""
        out, cut = {}, slice(int(n_from) - 1, None)
        if self.upper:
            for bx, D in self._inner(m * np.pi * self.hx).items():  # (q, m, l)
                for ay, Cq in self.outer.items():
                    out[(bx, ay)] = np.tensordot(Cq[cut], D, axes=(1, 0)).transpose(2, 1, 0)
            return out
        for ax, f in (("c", np.cos), ("s", np.sin)):
            Cq = f(np.outer(m * np.pi * self.hx, self.u)) * self.w[None, :]  # (m, q)
            for by, D in self.inner.items():
                out[(ax, by)] = np.tensordot(Cq, D[:, cut], axes=(1, 0)).transpose(2, 0, 1)
        return out


def _width_groups(breaks: np.ndarray) -> list:
    """[(indices, width)]: the cells of a 1D partition grouped by their width rounded to 14
    decimals (the :class:`_Shape` key), in order of first appearance; width of the first cell."""
    h = np.diff(breaks)
    groups = {}
    for i, w in enumerate(h):
        groups.setdefault(round(w, 14), []).append(i)
    return [(np.array(v), h[v[0]]) for v in groups.values()]


def _scatter(space, glob: np.ndarray) -> tuple:
    """The incidence Z (dim × cells·nloc) as COO arrays (rows, columns, values): column
    cell·nloc + l holds the contribution of the raw local Lagrange function l of every triangle
    (rows of ``glob``, (cells, nloc) global dofs, −1: removed) to the global basis functions:
    1 at glob[cell, l] (standard bases), Â[l', l] at glob[cell, l'] for ψ = Â N (dual bases,
    :meth:`~.face.spaces.triangles.TriangleSpace._dual_matrix` per live pattern)."""
    cells, nloc = glob.shape
    if not space.dual:
        rows, cols, vals = glob.ravel(), np.arange(cells * nloc), np.ones(cells * nloc)
    else:
        masks = space.live_mask(glob)
        A = np.empty((cells, nloc, nloc))
        for p in np.unique(masks):
            A[masks == p] = space._dual_matrix(int(p))
        rows = np.broadcast_to(glob[:, :, None], A.shape).ravel()
        cols = np.broadcast_to((np.arange(cells)[:, None] * nloc + np.arange(nloc))[:, None, :], A.shape).ravel()
        vals = A.ravel()
    keep = rows >= 0
    return rows[keep], cols[keep], vals[keep]


def sine_coefficients_chunk(space, m: np.ndarray, n_max: int, q: int | None = None,
                            shapes: dict | None = None) -> np.ndarray:
    """μ_mn = 2 ∬ φ sin(mπx) sin(nπy) for every basis function, m in ``m``, n = 1..n_max:
    shape (dim, len(m), n_max). ``shapes`` caches the :class:`_Shape` s across blocks of m
    (same n_max and q); ``q`` overrides :func:`coefficient_points`. :func:`_coefficients` of
    every dof."""
    return _coefficients(space, m, n_max, q, shapes)


def _coefficients(space, m: np.ndarray, n_max: int, q: int | None = None, shapes: dict | None = None,
                  dofs_out: np.ndarray | None = None, n_from: int = 1) -> np.ndarray:
    """:func:`sine_coefficients_chunk` of the dofs ``dofs_out`` only (None: all), in that order,
    and of n = n_from..n_max only: shape (len(dofs_out), len(m), n_max − n_from + 1).

    Vectorised over the cells (module docstring): with tx_c[i, m] = sin(mπx_i),
    tx_s[i, m] = cos(mπx_i) (likewise ty_b[j, n] in y), the raw local function l of the triangle
    ``tri`` of cell (i, j) has the coefficients 2 Σ_a tx_a[i, m] U_a[j, l, m, n],
    U_a = Σ_b ty_b R_ab. The cells of one shape (hx, hy) are a sub-grid I × J of the tensor
    partition (its columns of width hx times its rows of height hy), so U is formed once per row
    j ∈ J, and the sum over the cells with the incidence Z (:func:`_scatter`, dual matrices
    included) is one sparse product W @ U for all m, shapes and triangles at once: row (g, m) of
    the output is Σ_{Z[g, (i, j, l)] ≠ 0} 2 Z[g, (i, j, l)] tx_a[i, m] · row (a, j, l, m) of the
    stacked U s, so no per-cell array of size cells × nloc × len(m) × n_max is formed. U and W U
    are made by blocks of :data:`_COLUMNS` columns n, each block read from the cache; R only for
    the n asked (``n_from``). Cost: the output (dim · len(m) · n_max values) written once,
    2 nnz(Z) n_max len(m) flops."""
    n = np.arange(1, n_max + 1, dtype=float)
    m = np.asarray(m, dtype=float)
    xs, ys = np.asarray(space.breakpoints.xs, float), np.asarray(space.breakpoints.ys, float)
    rows_m = len(m)
    # sin(mπ(x0 + X)) = sin(mπx0) cos(mπX) + cos(mπx0) sin(mπX), likewise in y
    tx = np.stack([np.sin(np.outer(xs[:-1], m * np.pi)), np.cos(np.outer(xs[:-1], m * np.pi))])  # (a, i, m)
    ty = {"c": np.sin(np.outer(ys[:-1], n * np.pi)), "s": np.cos(np.outer(ys[:-1], n * np.pi))}
    cut = slice(int(n_from) - 1, None)  # the n asked (the shapes keep every n: one cache per n_max)
    ty = {b: t[:, cut] for b, t in ty.items()}
    n_cols = n_max - int(n_from) + 1
    dofs, nloc = space._dofs, space.n_local
    shapes = {} if shapes is None else shapes
    mm = np.arange(rows_m)
    position = np.arange(space.dim)  # output row of each dof, −1: not asked
    if dofs_out is not None:
        position = np.full(space.dim, -1)
        position[dofs_out] = np.arange(len(dofs_out))
    n_out = space.dim if dofs_out is None else len(dofs_out)
    rows, cols, vals, stack = [], [], [], []  # stack: (first row of U / rows_m, J, R) per shape's triangle
    offset = 0  # first row of the current U in the stack, in units of rows_m
    for I, hx in _width_groups(xs):
        for J, hy in _width_groups(ys):
            cells = dofs[np.ix_(I, J)]  # (|I|, |J|, 2, nloc)
            width = len(J) * nloc
            for tri, upper in enumerate((False, True)):
                key = (round(hx, 14), round(hy, 14), upper)
                if key not in shapes:
                    qq = coefficient_points(max(n_max, int(m.max())), hx + hy, space.s) if q is None else q
                    shapes[key] = _Shape(hx, hy, upper, space.s, n, qq)
                stack.append((offset, J, shapes[key].integrals(m, n_from)))
                g, col, z = _scatter(space, cells[:, :, tri].reshape(-1, nloc))
                g = position[g]
                g, col, z = g[g >= 0], col[g >= 0], z[g >= 0]
                i, jl = np.divmod(col, width)  # cell row in I, (j, l) within it
                v = 2.0 * z[None, :, None] * tx[:, I[i], :]  # (a, nnz, m)
                rows.append(np.broadcast_to(g[None, :, None] * rows_m + mm, v.shape).ravel())
                cols.append(((offset + np.arange(2)[:, None, None] * width + jl[None, :, None]) * rows_m + mm).ravel())
                vals.append(v.ravel())
                offset += 2 * width
    W = sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n_out * rows_m, offset * rows_m))
    out = np.empty((n_out * rows_m, n_cols))
    for start in range(0, n_cols, _COLUMNS):  # the stacked U and W U by blocks of columns n (module text)
        cut = slice(start, min(start + _COLUMNS, n_cols))
        U = np.empty((offset * rows_m, cut.stop - start))
        for first, J, R in stack:
            for a in range(2):  # U_a = ty_c R_ac + ty_s R_as, bit for bit the one expression
                block = U[(first + a * len(J) * nloc) * rows_m:(first + (a + 1) * len(J) * nloc) * rows_m]
                block = block.reshape(len(J), nloc, rows_m, -1)
                np.multiply(ty["c"][J][:, None, None, cut], R[("cs"[a], "c")][None, :, :, cut], out=block)
                block += ty["s"][J][:, None, None, cut] * R[("cs"[a], "s")][None, :, :, cut]
        out[:, cut] = W @ U
    return out.reshape(n_out, rows_m, n_cols)


def chunk_rows(space, n_max: int) -> int:
    """Rows m per :func:`sine_coefficients_chunk` call: its output dim · rows · n_max within
    :data:`_BUDGET` values (the stacked U is made by blocks of :data:`_COLUMNS` columns)."""
    return int(min(n_max, max(1, _BUDGET // (space.dim * n_max))))


@lru_cache(maxsize=8)
def _symmetries(space) -> tuple:
    """(:func:`~.face.symmetry.reflection`, :func:`~.face.symmetry.transposition`)
    of a space, once (the Richardson loop asks several partial sums of the same space)."""
    return reflection(space), transposition(space)


def partial_gram(space, n_max: int, n_min: int = 0) -> np.ndarray:
    """S(n_max) = Σ_{m,n ≤ n_max} μ_mn μ_mnᵀ / (π√(m² + n²)), in row blocks of m
    (:func:`chunk_rows`), using the symmetries of Γ that map the space onto itself
    (:mod:`.face.symmetry`): the transposition σ (μ_nm = μ_mn ∘ σ) sums n ≥ m only,
    H = Σ_{n>m} + ½ Σ_{n=m}, S = H + H[σ, σ] (half the coefficients and half the product); the
    point reflection sums H through its symmetric and antisymmetric halves (coefficients of about
    half the dofs, a quarter of the product's flops), and with σ as well in the four components
    of both (:class:`~.face.symmetry.KleinGram`: half that again; S itself, no σ sum after). ``n_min`` > 0: only the terms with
    max(m, n) > n_min, S(n_max) − S(n_min) (what the Richardson loop adds from one truncation to
    the next, :func:`incremental_partial_gram`)."""
    n = np.arange(1, n_max + 1, dtype=float)
    pi, sigma = _symmetries(space)
    halves = None if pi is None else (ReflectedGram(pi) if sigma is None else KleinGram(pi, sigma))
    G = np.zeros((space.dim, space.dim))
    shapes = {}
    rows = chunk_rows(space, n_max)
    n_min = int(min(max(n_min, 0), n_max))
    starts = [(s, min(s + rows, n_min)) for s in range(0, n_min, rows)] + \
             [(s, min(s + rows, n_max)) for s in range(n_min, n_max, rows)]
    for start, stop in starts:
        m = n[start:stop]
        if stop <= n_min:  # rows inside the old square: only its new columns n > n_min (all above m)
            n_from = n_min + 1
        else:
            n_from = 1 if sigma is None else int(m[0])
        nn = n[n_from - 1:]
        C = _coefficients(space, m, n_max, shapes=shapes, dofs_out=None if halves is None else halves.even_rows,
                          n_from=n_from)
        w = 1.0 / np.sqrt(np.pi * np.sqrt(m[:, None] ** 2 + nn[None, :] ** 2))
        if sigma is not None:  # H: n > m, half of n = m, none of the few n < m of the block
            w *= np.sqrt(np.select([nn[None, :] > m[:, None], nn[None, :] == m[:, None]], [1.0, 0.5], 0.0))
        C *= w[None]
        if halves is not None:
            halves.add(C, m, nn)
            continue
        C = C.reshape(C.shape[0], -1)
        G += C @ C.T
    if halves is not None:
        G = halves.gram()
    if sigma is not None and not isinstance(halves, KleinGram):
        G = G + G[np.ix_(sigma, sigma)]
    return 0.5 * (G + G.T)


def tail_exponent(space, n_max: int) -> float:
    """Measured p of ‖S(∞) − S(n)‖ ~ C n^{−p}: log2 ‖S(2n) − S(n)‖ / ‖S(4n) − S(2n)‖."""
    s1, s2, s4 = (partial_gram(space, k) for k in (n_max, 2 * n_max, 4 * n_max))
    return float(np.log2(_norm2(s2 - s1) / _norm2(s4 - s2)))


def tail_key(space) -> tuple:
    """(continuous, vanish) of the functions themselves: a dual basis is discontinuous."""
    return (space.continuous and not space.dual, space.vanish and not space.dual)


def incremental_partial_gram(space):
    """``partial(n)`` = :func:`partial_gram` (space, n) for increasing n, each from the last one plus
    the terms it lacks (the Richardson loop asks n0, 2 n0, 4 n0, ...: a quarter of each sum is
    the previous one); a smaller or repeated n is summed afresh."""
    last = {}

    def partial(n_max: int) -> np.ndarray:
        prev = last.get("n")
        if prev is None or prev >= n_max:
            S = partial_gram(space, n_max)
        else:
            S = last["S"] + partial_gram(space, n_max, n_min=prev)
        last.update(n=n_max, S=S)
        return S
    return partial


def gram_h_tri(space, rtol: float = 1e-6, n_start: int | None = None, n_cap: int = N_MAX_CAP // 64,
               exponent: float | None = None) -> tuple[np.ndarray, dict]:
    """Gram matrix of the H^{1/2}_00(Γ)' norm of a triangle space (module docstring), partial
    sums from n0 = max(16, 2 (s + 1) N) (N: the larger number of cells per direction), doubled
    and extrapolated with the exponent of :data:`TAIL_EXPONENTS` until ``rtol`` or ``n_cap``."""
    if not rtol > 0:
        raise InputError("rtol", "a positive float", got=rtol)
    p = TAIL_EXPONENTS[tail_key(space)] if exponent is None else float(exponent)
    n0 = max(16, 2 * (space.degree + 1) * max(space.shape)) if n_start is None else int(n_start)
    if n0 < 1 or n_cap < 1:
        raise InputError("n_start/n_cap", "positive integers", got=(n_start, n_cap))
    return extrapolated(incremental_partial_gram(space), p, n0, n_cap, rtol)


def gram(space, norm: str, **kwargs) -> tuple[np.ndarray, dict]:
    """Gram matrix of a triangle space for ``norm`` ∈ {"H", "L2"} (``kwargs`` to :func:`gram_h_tri`)."""
    return gram_by_norm(norm, lambda: gram_l2_tri(space), lambda **kw: gram_h_tri(space, **kw), **kwargs)
