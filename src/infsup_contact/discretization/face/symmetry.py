"""Symmetries of Γ = (0, 1)² and the H Gram of a triangle space (issue 28): the point reflection
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
        ke, ko = self.even_rows.size, self.rep.size
        self.Ge, self.Go = np.zeros((ke, ke)), np.zeros((ko, ko))
        # Ge, Go hold the products of the rows C[g] themselves; a pair's coordinate is
        # (C[g] ± C[π(g)])/√2 = √2 C[g] (:meth:`gram` scales)
        self.w_even = np.concatenate([np.full(self.rep.size, np.sqrt(2.0)), np.ones(self.fixed.size)])

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
            for G, rows, same in ((self.Ge, slice(None), True), (self.Go, slice(0, self.rep.size), False)):
                j0 = ((pm if same else 1 - pm) - int(n[0])) % 2  # n ≡ m (m + n even) or not
                block = C[rows, k0::2, j0::2]
                if block.size:
                    block = block.reshape(block.shape[0], -1)
                    G += block @ block.T

    def gram(self) -> np.ndarray:
        """S in the dof basis: Q_e G_e Q_eᵀ + Q_o G_o Q_oᵀ, Q_e / Q_o the orthonormal columns
        (e_g ± e_π(g))/√2 of the pairs (and e_g of the fixed points in Q_e)."""
        r, p, f = self.rep, self.pi[self.rep], self.fixed
        h = np.full(r.size, 1.0 / np.sqrt(2.0))
        ke = r.size + f.size
        Qe = sparse.csr_matrix((np.concatenate([h, h, np.ones(f.size)]),
                                (np.concatenate([r, p, f]), np.concatenate([np.arange(r.size)] * 2 + [np.arange(r.size, ke)]))),
                               shape=(self.dim, ke))
        Qo = sparse.csr_matrix((np.concatenate([h, -h]), (np.concatenate([r, p]), np.concatenate([np.arange(r.size)] * 2))),
                               shape=(self.dim, r.size))
        G = np.zeros((self.dim, self.dim))
        Ge = self.w_even[:, None] * self.Ge * self.w_even[None, :]
        for Q, Gq in ((Qe, Ge), (Qo, 2.0 * self.Go)):
            if Gq.size:
                T = np.asarray(Q @ Gq)  # (dim, k)
                G += np.asarray(Q @ T.T).T
        return G
