"""The large route's pencils split by the point reflection of the face (issue 28, large N).

On a face mesh pair symmetric about the centre of Γ = (0, 1)² (the structured hexahedra, any
N1, N2), the point reflection R(x, y) = (1 − x, 1 − y) maps the multiplier basis onto itself,
μ_j ∘ R = μ_π(j) with π an involution (:func:`reflection_split`, found and checked on Gauss
points of G_h, :func:`~infsup_contact.discretization.basis_symmetry.induced_permutation`), and the interface operator S = Σ_i B_i X_i B_iᵀ and every Gram matrix G commute
with the permutation: P S Pᵀ = S, P G Pᵀ = G. In the orthonormal basis Q = [Q_e, Q_o] of the
even and odd functions ((e_j ± e_π(j))/√2 for the pairs j < π(j), e_j for the fixed points in
Q_e) both are block diagonal, so the pencil S x = λ G x is two pencils of about half the size,

    spec(S, G) = spec(Q_eᵀ S Q_e, Q_eᵀ G Q_e) ∪ spec(Q_oᵀ S Q_o, Q_oᵀ G Q_o),

and the kernel of Bᵀ (invariant: B_i commute with the reflections of the traces) splits into its
even and odd parts. Each half costs an eighth of the Cholesky factorizations, triangular solves
and products of :func:`~.bottom.bottom_pencil` (m³/3 each), and half of each Lanczos product.
The kernel decision itself runs on the even and odd columns of the scaled coupling W
(:func:`split_bottom_kernel`), with the unsplit η and a certificate per half.

The computed S and G are invariant only to round-off (the sides' sparse factorizations order
their dofs differently): the split is taken only where the dropped block Q_oᵀ M Q_e is at most
:data:`INVARIANCE_RTOL` of M (Frobenius) for S and every G (:meth:`ReflectionSplit.blocks`), and
dropping it then moves each eigenvalue by at most its norm (Weyl), at the pencil's own
round-off level. A face that is
not symmetric (perturbed meshes, the tetrahedra's 3D Kuhn cubes, whose diagonals R reverses)
keeps the unsplit route.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..discretization.basis_symmetry import induced_permutation
from ..la.threaded import sparse_times_dense, symmetric_part, times_transpose
from . import bottom
from .kernel import BLOCK_EXTRA, KernelDecision, certified_bottom, certify_floor, decide, error_level

INVARIANCE_RTOL = 1e-11
"""Largest ‖Q_oᵀ M Q_e‖_F / ‖M‖_F (the block the split drops) for which S and G count as
reflection invariant."""
SPLIT_GAP = 1e-6
"""A kernel vector's even (or odd) part must have norm > 1 − SPLIT_GAP or < SPLIT_GAP (the
cosines of the principal angles between the kernel and the even functions): else no split."""


@dataclass(frozen=True)
class ReflectionSplit:
    """The even/odd coordinates of an involution π of the multiplier basis."""

    pi: np.ndarray

    @cached_property
    def rep(self) -> np.ndarray:
        g = np.arange(self.pi.size)
        return g[g < self.pi]

    @cached_property
    def fixed(self) -> np.ndarray:
        g = np.arange(self.pi.size)
        return g[g == self.pi]

    @property
    def sizes(self) -> tuple[int, int]:
        return self.rep.size + self.fixed.size, self.rep.size

    @cached_property
    def bases(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """(Q_e, Q_o), sparse with orthonormal columns."""
        r, p, f, m = self.rep, self.pi[self.rep], self.fixed, self.pi.size
        h, k, ke = np.full(self.rep.size, np.sqrt(0.5)), np.arange(self.rep.size), self.sizes[0]
        Qe = sp.csr_matrix((np.concatenate([h, h, np.ones(f.size)]),
                            (np.concatenate([r, p, f]), np.concatenate([k, k, r.size + np.arange(f.size)]))), shape=(m, ke))
        Qo = sp.csr_matrix((np.concatenate([h, -h]), (np.concatenate([r, p]), np.concatenate([k, k]))),
                           shape=(m, self.rep.size))
        return Qe, Qo

    def blocks(self, M: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """(Q_eᵀ M Q_e, Q_oᵀ M Q_o, ‖Q_oᵀ M Q_e‖_F / ‖M‖_F) of a symmetric M, the diagonal blocks
        symmetrised; the last is its distance from reflection invariance (0 for P M Pᵀ = M).

        Row combinations Q_σᵀ M (sparse × dense: whole rows, threaded), then (Q_σᵀ M) Q_τ by
        :func:`~infsup_contact.la.threaded.times_transpose` (small transposed blocks): fancy
        column gathers M[:, j] of a C-ordered 4,225² matrix took 0.12 s each."""
        QeT, QoT = (Q.T.tocsr() for Q in self.bases)
        M = np.ascontiguousarray(M, dtype=float)
        Te, To = sparse_times_dense(QeT, M), sparse_times_dense(QoT, M)
        Me, Mo = times_transpose(QeT, Te), times_transpose(QoT, To)
        off = times_transpose(QeT, To) if To.shape[0] else np.zeros(0)
        scale = float(np.linalg.norm(M))
        distance = float(np.linalg.norm(off)) / scale if scale > 0 else 0.0
        return symmetric_part(Me), symmetric_part(Mo), distance

    def even_odd(self, Z: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """Bases of the even and odd parts of span Z in the coordinates of Q_e and Q_o, or None
        when span Z is not the sum of its parts (a cosine not within :data:`SPLIT_GAP` of 0 or 1)."""
        V = sla.qr(Z, mode="economic")[0]
        r, p, h = self.rep, self.pi[self.rep], np.sqrt(0.5)
        parts = [np.vstack([(V[r] + V[p]) * h, V[self.fixed]]), (V[r] - V[p]) * h]
        out = []
        for P in parts:
            if P.shape[0] == 0:
                out.append(np.zeros((0, 0)))
                continue
            U, s, _ = sla.svd(P, full_matrices=False)
            if np.any((s > SPLIT_GAP) & (s < 1.0 - SPLIT_GAP)):
                return None
            out.append(U[:, s >= 1.0 - SPLIT_GAP])
        if out[0].shape[1] + out[1].shape[1] != Z.shape[1]:
            return None
        return out[0], out[1]


def reflection_split(space, points: np.ndarray) -> ReflectionSplit | None:
    """The split of ``space`` by the point reflection (x, y) → (1 − x, 1 − y), checked at
    ``points`` (e.g. the Gauss points of G_h), or None where it does not map the basis onto itself."""
    pi = induced_permutation(space, np.asarray(points, float), lambda x: 1.0 - x)
    return None if pi is None else ReflectionSplit(pi)


def split_of(space, gamma, g_h, k: int) -> ReflectionSplit | None:
    """The point reflection's split of ``space`` (:func:`reflection_split`, checked at
    the Gauss points of G_h), or None (no such symmetry, or a Γ without a quadrature)."""
    quadrature = getattr(gamma, "quadrature", None)
    if quadrature is None:
        return None
    split = reflection_split(space, quadrature(g_h, 2 * k)[0])
    return split if split is not None and min(split.sizes) >= 1 else None


def usable(split: ReflectionSplit | None, grams: dict, kernel: KernelDecision):
    """(split, kernel parts, {norm: halves of G}) where every Gram matrix is invariant under
    ``split`` and the kernel splits, else (None, None, None). Each interface operator S is checked where it
    is split (:func:`split_pencils`; :func:`~.infsup.split_spectra` solves it unsplit where it is not)."""
    if split is None:
        return None, None, None
    halves = {}
    for norm, (G, _) in grams.items():
        *halves[norm], distance = split.blocks(G)
        if distance > INVARIANCE_RTOL:
            return None, None, None
    parts = split.even_odd(kernel.vectors) if kernel.dim else None
    if kernel.dim and parts is None:
        return None, None, None
    return split, parts, halves


def split_pencils(split: ReflectionSplit, S: np.ndarray, factors: dict, kernel_parts, n_values: int) -> dict | None:
    """{norm: (values above the kernel, λ_max)} of S x = λ G x from the two halves, or None where
    S is not reflection invariant to :data:`INVARIANCE_RTOL` (the caller solves it unsplit).

    ``factors``: {norm: (L_e, L_o)} the Cholesky factors of the halves of G; ``kernel_parts``:
    (Z_e, Z_o) from :meth:`ReflectionSplit.even_odd` (None: no kernel deflated; a half whose S
    is definite then shares its factor between the norms, as :func:`~.infsup.bottom_spectra`)."""
    *halves, distance = split.blocks(S)
    if distance > INVARIANCE_RTOL:
        return None
    parts = [None if kernel_parts is None or not Z.shape[1] else Z for Z in (kernel_parts or (None, None))]
    shared = [bottom.definite_factor(h) if Z is None and h.shape[0] >= 3 else None for h, Z in zip(halves, parts)]
    out = {}
    for norm, Ls in factors.items():
        values, top = [], 0.0
        for b, (Sb, Lb) in enumerate(zip(halves, Ls)):
            Zb = parts[b]
            free = Sb.shape[0] - (0 if Zb is None else Zb.shape[1])
            if free < 1:
                continue
            if free == 1 or Sb.shape[0] < 3:  # too small for Lanczos: the dense pencil
                ev = sla.eigh(Sb, Lb @ Lb.T, eigvals_only=True)
                values.append(ev[(0 if Zb is None else Zb.shape[1]):])
                top = max(top, float(ev[-1]))
                continue
            res = bottom.bottom_pencil(Sb, Lb, n_values, Zb, s_factor=shared[b])
            values.append(res.values)
            top = max(top, res.lam_max)
        out[norm] = (np.sort(np.concatenate(values))[:max(n_values, 1)], top)
    return out


def split_bottom_kernel(W, split: ReflectionSplit, proven: int = 0, entry_error: float = 0.0) -> KernelDecision | None:
    """:func:`~.kernel.bottom_kernel` of W (trace dofs × multipliers, sparse) on the even and
    odd columns W Q_e, W Q_o, or None where the split does not hold.

    With the traces' reflections W is equivariant, so WᵀW is block diagonal in Q = [Q_e, Q_o]
    and its eigenvalues are those of the blocks; the off-diagonal block C = Q_eᵀ WᵀW Q_o of the
    computed W is round-off, and moves each eigenvalue by at most ‖C‖₂ <= ‖C‖_F (Weyl). Each
    block goes through the same steps as the unsplit route (block inverse iteration, counted
    values ‖W v‖ of orthonormal v, hence upper bounds of singular values of W; the Cholesky
    certificate at τ_b = σ_{d_b+1}²/2 per block: the block-diagonal WᵀW has at most d = d_e + d_o
    eigenvalues below min τ_b, so the computed one at most d below min τ_b − ‖C‖_F >= min τ_b / 2),
    with the unsplit η = max(rows, m) ε σ_max + 2 ‖δW‖_F. None (the caller takes the unsplit
    route) wherever a step would fall back, or ‖C‖_F > τ_b / 2."""
    W = sp.csr_matrix(W)
    rows, m = W.shape
    proven = int(max(proven, m - rows, 0))
    Qe, Qo = split.bases
    blocks = [sp.csr_matrix(W @ Q) for Q in (Qe, Qo)]
    grams = [sp.csr_matrix(B.T @ B) for B in blocks]
    cross = float(sp.linalg.norm(blocks[0].T @ blocks[1]))
    smaxes = [bottom.largest_singular(B, g) if B.shape[1] else 0.0 for B, g in zip(blocks, grams)]
    smax = max(smaxes)
    tol = error_level(rows, m, smax, entry_error)
    floor = max(certify_floor(rows, m, smax), 2.0 * cross)  # the whole W's certificate at τ − ‖C‖
    counted, vectors, above = [], [], np.inf
    for B, g, s_b, Q in zip(blocks, grams, smaxes, (Qe, Qo)):
        mb = B.shape[1]
        if mb < 2:
            return None
        hint = int(np.ceil(proven * mb / m))  # a block size only: each half holds about its share
        res = certified_bottom(B, g, min(hint + BLOCK_EXTRA, mb - 1), tol, s_b, floor)
        if res is None:
            return None
        counted.append(res.values[:res.count])
        vectors.append(np.asarray(Q @ res.vectors[:, :res.count]))
        above = min(above, float(res.above))
    d = sum(len(c) for c in counted)
    if d < proven:
        return None
    s = np.concatenate([np.sort(np.concatenate(counted)), [above, smax]])
    return decide(s, proven, tol, d, smax, np.hstack(vectors))
