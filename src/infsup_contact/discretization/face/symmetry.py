"""Symmetries of Γ = (0, 1)² and the H Gram of a triangle space: the point reflection
below, and the transposition (x, y) → (y, x) of a square grid (:func:`transposition`, used by
:func:`~.face.norms.triangles.partial_gram`).

On a partition symmetric about the centre (xs and ys symmetric about 1/2: the uniform grids of
the 3D study), the reflection P(x, y) = (1 − x, 1 − y) maps the lower triangle of the cell (i, j)
onto the upper one of (n_x − 1 − i, n_y − 1 − j) (:mod:`.face.spaces.triangles`), and the basis
onto itself: φ_g ∘ P = φ_π(g) for a permutation π of the dofs, an involution
(:func:`reflection`, found and checked numerically, so a space it does not map, e.g. a graded
partition, falls back to the plain product). With sin(mπ(1 − x)) = −(−1)^m sin(mπx), the sine
coefficients μ_mn = 2 ∬ φ sin(mπx) sin(nπy) (:mod:`.face.norms.triangles`) satisfy

    μ_mn(φ_π(g)) = (−1)^{m+n} μ_mn(φ_g),

so in the orthonormal basis (e_g ± e_π(g))/√2 of the pairs g < π(g) (e_g for the fixed points
g = π(g)) the columns with m + n even have no antisymmetric part and those with m + n odd no
symmetric part: S = Σ w_mn μ_mn μ_mnᵀ is the sum of two Gram products of about half the rows
on half the columns each, a quarter of the flops of the plain product (:class:`ReflectedGram`).
Where the transposition maps the space onto itself too (every space of a uniform square grid),
the four components of both halve that again (:class:`KleinGram`).
"""
from __future__ import annotations

import numpy as np
from scipy import sparse

from ...errors import InputError
from ..gamma.symmetry import induced_permutation, reflect

#: Interior sample points of every triangle, barycentric (seeded): more than (s + 1)(s + 2)/2 for
#: s ≤ 2 in general position, so a function of P_s on a triangle is fixed by its values there.
_SAMPLES = np.random.default_rng(28).dirichlet(np.ones(3), size=9)


def _induced(space, transform) -> np.ndarray | None:
    """π with φ_g(T x) = φ_π(g)(x) for every dof g, T = ``transform`` (an involution of Γ mapping
    the triangles of G_h onto triangles of G_h), checked on :data:`_SAMPLES` of every triangle
    (:func:`~.gamma.symmetry.induced_permutation`); None if T does not map the space onto itself."""
    tri = space.triangles()  # (T, 3, 2)
    return induced_permutation(space, np.einsum("pk,tkd->tpd", _SAMPLES, tri).reshape(-1, 2), transform)


def reflection(space) -> np.ndarray | None:
    """π of the point reflection (x, y) → (1 − x, 1 − y) (:func:`_induced`), or None."""
    return _induced(space, reflect())


def transposition(space) -> np.ndarray | None:
    """σ of the transposition (x, y) → (y, x) (:func:`_induced`; xs = ys: the lower triangle of
    the cell (i, j) onto the upper one of (j, i)), or None: μ_mn(φ_σ(g)) = μ_nm(φ_g)."""
    return _induced(space, lambda x: x[:, ::-1])


class ReflectedGram:
    """Accumulates S = Σ C Cᵀ over blocks of weighted coefficient columns C (dim, rows m, n)
    through the symmetric and antisymmetric halves of the reflection π (module docstring)."""

    def __init__(self, pi: np.ndarray):
        g = np.arange(pi.size)
        self.rep, self.fixed = g[g < pi], g[g == pi]
        self.even_rows = np.concatenate([self.rep, self.fixed])
        self.dim, self.pi = pi.size, pi
        # the products of the rows C[g] themselves, symmetric (True) and antisymmetric halves; a
        # pair's coordinate is (C[g] ± C[π(g)])/√2 = √2 C[g] (:attr:`weights`, :meth:`gram` scales)
        self.G = {True: np.zeros((self.even_rows.size,) * 2), False: np.zeros((self.rep.size,) * 2)}
        self.weights = {True: np.concatenate([np.full(self.rep.size, np.sqrt(2.0)), np.ones(self.fixed.size)]),
                        False: np.full(self.rep.size, np.sqrt(2.0))}

    def add(self, C: np.ndarray, m: np.ndarray, n: np.ndarray) -> None:
        """Add the columns of the block C (len(even_rows), len(m), len(n)): the weighted
        coefficients of the dofs :attr:`even_rows` (the pairs' representatives g < π(g), then the
        fixed points; the others are ± these); ``m`` and ``n`` consecutive integers, so the
        columns of one parity of m + n are strided slices: rows m of one parity, every other n
        (one copy, no mask)."""
        if np.any(np.diff(m) != 1) or np.any(np.diff(n) != 1):
            raise InputError("m/n", "consecutive integers", got=(m, n))
        for pm in (0, 1):  # the rows m ≡ pm (mod 2)
            k0 = (pm - int(m[0])) % 2
            for rows, same in ((slice(None), True), (slice(0, self.rep.size), False)):
                j0 = ((pm if same else 1 - pm) - int(n[0])) % 2  # n ≡ m (m + n even) or not
                block = C[rows, k0::2, j0::2]
                if block.size:
                    self._accumulate(block, same)

    def _accumulate(self, block: np.ndarray, same: bool) -> None:
        """Add one strided block (rows, m of one parity, every other n) of columns to its half."""
        flat = block.reshape(block.shape[0], -1)  # a copy: the block is a strided view
        self.G[same] += flat @ flat.T

    def pair_bases(self) -> dict:
        """{True: Q_e, False: Q_o}: the orthonormal columns (e_g ± e_π(g))/√2 of the pairs (and
        e_g of the fixed points in Q_e), dim × coordinates, sparse."""
        r, p, f = self.rep, self.pi[self.rep], self.fixed
        h = np.full(r.size, 1.0 / np.sqrt(2.0))
        ke = r.size + f.size
        return {True: sparse.csr_matrix((np.concatenate([h, h, np.ones(f.size)]),
                                         (np.concatenate([r, p, f]),
                                          np.concatenate([np.arange(r.size)] * 2 + [np.arange(r.size, ke)]))),
                                        shape=(self.dim, ke)),
                False: sparse.csr_matrix((np.concatenate([h, -h]), (np.concatenate([r, p]), np.concatenate([np.arange(r.size)] * 2))),
                                         shape=(self.dim, r.size))}

    def gram(self) -> np.ndarray:
        """S in the dof basis: Q_e G_e Q_eᵀ + Q_o G_o Q_oᵀ (:meth:`pair_bases`), G_e and G_o
        scaled by the coordinates' :attr:`weights`."""
        Q = self.pair_bases()
        return _sandwich_sum(self.dim, ((Q[same], self.weights[same][:, None] * Gq * self.weights[same][None, :])
                             for same, Gq in self.G.items()))


def _sandwich_sum(dim: int, terms) -> np.ndarray:
    """Σ V G Vᵀ over ``terms`` (V sparse dim × k, G dense k × k), dense dim × dim."""
    out = np.zeros((dim, dim))
    for V, Gq in terms:
        if Gq.size:
            T = np.asarray(V @ Gq)  # (dim, k)
            out += np.asarray(V @ T.T).T
    return out


class KleinGram(ReflectedGram):
    """:class:`ReflectedGram` for a space that the transposition σ maps onto itself too: the
    sum S = H + P_σ H P_σᵀ of :func:`~.face.norms.triangles.partial_gram` (H its columns n ≥ m)
    in the four components of the group {1, π, σ, πσ} (π and σ commute).

    σ permutes the pairs {g, π(g)}, so in the coordinates of :class:`ReflectedGram` it acts as a
    permutation τ (the symmetric coordinates) or a signed one (the antisymmetric ones: −1 where
    σ(g) is not its pair's representative), an involution T. In the orthonormal bases U_± of its
    ±1 eigenspaces ((e_i ± s_i e_τ(i))/√2 of the pairs i < τ(i), e_i of the fixed points by their
    sign s_i), Tᵀ U_± = ±U_± gives U_±ᵀ (H + T H Tᵀ) U_± = 2 U_±ᵀ H U_± and
    U_+ᵀ (H + T H Tᵀ) U_− = 0: S is two Gram products of about a quarter of the rows per parity of
    m + n, half the flops of :class:`ReflectedGram`, and no σ sum afterwards (:meth:`gram` is S).
    The rows :attr:`even_rows` come ordered so that every row of U_±ᵀ C is the sum or the
    difference of two contiguous runs of C's rows (:meth:`_accumulate`: one pass from C's strided
    view, where :class:`ReflectedGram` copies it): the pairs' representatives [a with s = +1, a with
    s = −1, their images τ(a) in the same order, τ's fixed points with s = +1, then −1], then the
    reflection's fixed points [a, τ(a), τ's fixed points]."""

    def __init__(self, pi: np.ndarray, sigma: np.ndarray):
        g = np.arange(pi.size)
        if np.any(sigma[sigma] != g) or np.any(sigma[pi] != pi[sigma]):
            raise InputError("sigma", "an involution of the dofs commuting with the reflection π", got="another permutation")
        rep, fixed = g[g < pi], g[g == pi]
        image = np.minimum(sigma[rep], pi[sigma[rep]])          # τ on the pairs, by representative
        sign = np.where(sigma[rep] == image, 1.0, -1.0)          # of the antisymmetric coordinate
        a = [rep[(rep < image) & (sign == sg)] for sg in (1.0, -1.0)]
        tau = np.empty(pi.size, dtype=int)
        tau[rep] = image
        b = [tau[part] for part in a]
        own = [rep[(rep == image) & (sign == sg)] for sg in (1.0, -1.0)]
        fa, ff = fixed[fixed < sigma[fixed]], fixed[fixed == sigma[fixed]]
        super().__init__(pi)
        self.rep = np.concatenate([*a, *b, *own]).astype(int)
        self.fixed = np.concatenate([fa, sigma[fa], ff]).astype(int)
        self.even_rows = np.concatenate([self.rep, self.fixed])
        n_plus, n_minus, na = a[0].size, a[1].size, a[0].size + a[1].size
        r, nf = self.rep.size, fa.size
        run = lambda lo, k: slice(lo, lo + k)  # noqa: E731 - the runs of rows, by (start, length)
        A, B, A_plus, B_plus, A_minus, B_minus = (run(0, na), run(na, na), run(0, n_plus), run(na, n_plus),
                                                  run(n_plus, n_minus), run(na + n_plus, n_minus))
        F_a, F_b = run(r, nf), run(r + nf, nf)
        # per component (symmetric in π?, +1 eigenspace of σ?): its rows as (run a, run b or None, ±1)
        self.components = {
            (True, True): [(A, B, 1.0), (run(2 * na, r - 2 * na), None, 1.0), (F_a, F_b, 1.0), (run(r + 2 * nf, ff.size), None, 1.0)],
            (True, False): [(A, B, -1.0), (F_a, F_b, -1.0)],
            (False, True): [(A_plus, B_plus, 1.0), (A_minus, B_minus, -1.0), (run(2 * na, own[0].size), None, 1.0)],
            (False, False): [(A_plus, B_plus, -1.0), (A_minus, B_minus, 1.0), (run(2 * na + own[0].size, own[1].size), None, 1.0)]}
        self.G = {key: np.zeros((sum(p[0].stop - p[0].start for p in parts),) * 2) for key, parts in self.components.items()}

    def _accumulate(self, block: np.ndarray, same: bool) -> None:
        """Add one strided block of columns (:meth:`ReflectedGram.add`; its rows those of
        :attr:`even_rows`, or their first :attr:`rep`) to both σ components of its half: each row
        of U_±ᵀ C written once, from two runs of the view."""
        for plus in (True, False):
            G = self.G[(same, plus)]
            out, row = np.empty((G.shape[0],) + block.shape[1:]), 0
            for ra, rb, sg in self.components[(same, plus)]:
                target = out[row:row + ra.stop - ra.start]
                if rb is None:
                    np.copyto(target, block[ra])
                else:
                    (np.add if sg > 0 else np.subtract)(block[ra], block[rb], out=target)
                row += ra.stop - ra.start
            if row:
                flat = out.reshape(row, -1)
                G += flat @ flat.T

    def gram(self) -> np.ndarray:
        """S in the dof basis: Σ V (2 G) Vᵀ over the four components (2: S = H + P_σ H P_σᵀ),
        V = Q U D: the pairs' columns (:meth:`pair_bases`), the eigenspaces' (e_a ± e_b)/√2 with
        the 1/√2 :meth:`add` left out, and the coordinates' weights."""
        Q = self.pair_bases()
        return _sandwich_sum(self.dim, ((Q[same] @ self._basis(same, plus), 2.0 * Gq)
                                       for (same, plus), Gq in self.G.items()))

    def _basis(self, same: bool, plus: bool) -> sparse.csr_matrix:
        weight = self.weights[same]
        rows, cols, vals, col = [], [], [], 0
        for ra, rb, sg in self.components[(same, plus)]:
            ia = np.arange(ra.start, ra.stop)
            k = np.arange(col, col + ia.size)
            if rb is None:
                rows, cols, vals = rows + [ia], cols + [k], vals + [weight[ia]]
            else:
                ib = np.arange(rb.start, rb.stop)
                rows, cols, vals = rows + [ia, ib], cols + [k, k], vals + [weight[ia] / 2.0, sg * weight[ib] / 2.0]
            col += ia.size
        return sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                 shape=(weight.size, col))
