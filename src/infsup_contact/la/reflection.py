"""The large route's pencils split by the reflections of the face (large N).

On a face mesh pair symmetric about the centre of Γ = (0, 1)² (the structured hexahedra, any
N1, N2), the point reflection R(x, y) = (1 − x, 1 − y) maps the multiplier basis onto itself,
μ_j ∘ R = μ_π(j) with π an involution (:func:`~infsup_contact.solvers.symmetry.reflection_split`, found and checked on Gauss
points of G_h, :func:`~infsup_contact.discretization.gamma.symmetry.induced_permutation`), and
the interface operator S = Σ_i B_i X_i B_iᵀ and every Gram matrix G commute with the
permutation: P S Pᵀ = S, P G Pᵀ = G. In the orthonormal basis Q = [Q_e, Q_o] of the even and
odd functions ((e_j ± e_π(j))/√2 for the pairs j < π(j), e_j for the fixed points in Q_e)
both are block diagonal, so the pencil S x = λ G x is two pencils of about half the size,

    spec(S, G) = spec(Q_eᵀ S Q_e, Q_eᵀ G Q_e) ∪ spec(Q_oᵀ S Q_o, Q_oᵀ G Q_o),

and the kernel of Bᵀ (invariant: B_i commute with the reflections of the traces) splits into its
even and odd parts. Where the axis reflections x → 1 − x and y → 1 − y map the basis too (the
hexahedra's tensor faces; not the Kuhn triangles, whose diagonals they reverse), the two
commuting involutions give four components (:class:`ReflectionSplit`, the characters of
Z2 × Z2), each a pencil of about a quarter of the size. A component of order m/c costs
(1/c)³ of the Cholesky factorizations, triangular solves and products of
:func:`~.bottom.bottom_pencil` (m³/3 each), and (1/c)² of each Lanczos product. The kernel
decision itself runs on the components' columns of the scaled coupling W
(:func:`~infsup_contact.solvers.symmetry.split_bottom_kernel`), with the unsplit η and a certificate per component.

The computed S and G are invariant only to round-off (the sides' sparse factorizations order
their dofs differently): the split is taken only where the dropped blocks Q_aᵀ M Q_b are at most
:data:`INVARIANCE_RTOL` of M (Frobenius) for S and every G (:meth:`ReflectionSplit.blocks`), and
dropping them then moves each eigenvalue by at most their norm (Weyl), at the pencil's own
round-off level. A face that is not symmetric (perturbed meshes, the tetrahedra's 3D Kuhn
cubes, whose diagonals R reverses) keeps the unsplit route.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .threaded import concurrent_map, sparse_times_dense, symmetric_part, times_transpose
from . import bottom
from .parity_sandwich import INVARIANCE_RTOL, ParityOperator

SPLIT_GAP = 1e-6
"""A kernel vector's part in a component must have norm > 1 − SPLIT_GAP or < SPLIT_GAP (the
cosines of the principal angles between the kernel and the component): else no split."""


@dataclass(frozen=True)
class ReflectionSplit:
    """The isotypic coordinates of commuting involutions π_1, ..., π_g of the multiplier basis.

    They generate a group of 2^g permutations P_b (b a bit mask), whose characters
    χ_c(b) = (−1)^{popcount(b & c)} label 2^g components. Component c has the orthonormal basis
    Q_c of the orbit sums Σ_b χ_c(b) e_{P_b(j)} / √|orbit| over the orbits whose stabilizer χ_c
    leaves fixed (the others sum to 0); a matrix commuting with every P_b is block diagonal in
    Q = [Q_0, ..., Q_{2^g − 1}]. For g = 1 these are Q_e = (e_j + e_π(j))/√2 with the fixed
    points e_j, and Q_o = (e_j − e_π(j))/√2 (the point reflection's even and odd functions)."""

    pis: tuple
    bases: tuple = field(compare=False)
    """(Q_0, ..., Q_{2^g − 1}), sparse with orthonormal columns
    (:func:`~infsup_contact.discretization.gamma.symmetry.isotypic_bases` of ``pis``)."""

    @property
    def sizes(self) -> tuple:
        return tuple(Q.shape[1] for Q in self.bases)

    def blocks(self, M: np.ndarray) -> tuple:
        """(Q_0ᵀ M Q_0, ..., Q_lastᵀ M Q_last, distance) of a symmetric M, the diagonal blocks
        symmetrised; ``distance`` = (Σ_{a<b} ‖Q_aᵀ M Q_b‖_F²)^{1/2} / ‖M‖_F (the blocks the split
        drops; 0 for M commuting with every P_b).

        Row combinations Q_aᵀ M (sparse × dense: whole rows, threaded), then (Q_aᵀ M) Q_b by
        :func:`~infsup_contact.la.threaded.times_transpose` (small transposed blocks): fancy
        column gathers M[:, j] of a C-ordered 4,225² matrix were a strided pass each. An operator
        already kept in these components (:class:`~.parity_sandwich.ParityOperator`) gives its
        blocks and its bound on what they drop."""
        if isinstance(M, ParityOperator):
            if tuple(Q.shape for Q in M.bases) != tuple(Q.shape for Q in self.bases):
                raise ValueError("a ParityOperator of another split")
            return (*M.blocks, M.distance)
        QT = [Q.T.tocsr() for Q in self.bases]
        M = np.ascontiguousarray(M, dtype=float)
        T = [sparse_times_dense(Q, M) for Q in QT]
        diag = [symmetric_part(times_transpose(Q, t)) for Q, t in zip(QT, T)]
        off = sum(float(np.linalg.norm(times_transpose(QT[a], T[b]))) ** 2
                  for b in range(len(QT)) for a in range(b) if T[a].shape[0] and T[b].shape[0])
        scale = float(np.linalg.norm(M))
        return (*diag, float(np.sqrt(off)) / scale if scale > 0 else 0.0)

    def components(self, Z: np.ndarray) -> tuple | None:
        """Bases of the components of span Z in the coordinates of each Q_c, or None when span Z
        is not the sum of its components (a cosine not within :data:`SPLIT_GAP` of 0 or 1)."""
        V = sla.qr(Z, mode="economic")[0]
        out = []
        for Q in self.bases:
            if Q.shape[1] == 0:
                out.append(np.zeros((0, 0)))
                continue
            U, s, _ = sla.svd(np.asarray(Q.T @ V), full_matrices=False)
            if np.any((s > SPLIT_GAP) & (s < 1.0 - SPLIT_GAP)):
                return None
            out.append(U[:, s >= 1.0 - SPLIT_GAP])
        if sum(P.shape[1] for P in out) != Z.shape[1]:
            return None
        return tuple(out)


def usable(split: ReflectionSplit | None, grams: dict, kernel):
    """(split, kernel parts, {norm: blocks of G}) where every Gram matrix is invariant under
    ``split`` and the kernel splits (``kernel`` None: no kernel to deflate, parts None), else (None, None, None). Each interface operator S is checked where it
    is split (:func:`split_pencils`; :func:`~infsup_contact.solvers.spectra.split_spectra` solves it unsplit where it is not).
    A Gram summed in the same components (``info["parity"]``, :class:`~.face_parity.ParityGram`)
    gives its blocks as summed (exactly block diagonal: no distance to check); else G is split."""
    if split is None:
        return None, None, None
    halves = {}
    for norm, (G, info) in grams.items():
        summed = info.get("parity") if isinstance(info, dict) else None
        halves[norm] = summed.in_bases(split.bases) if summed is not None else None
        if halves[norm] is None:
            *halves[norm], distance = split.blocks(G)
            if distance > INVARIANCE_RTOL:
                return None, None, None
    parts = split.components(kernel.vectors) if kernel is not None and kernel.dim else None
    if kernel is not None and kernel.dim and parts is None:
        return None, None, None
    return split, parts, halves


def split_pencils(split: ReflectionSplit, S: np.ndarray, factors: dict, kernel_parts, n_values: int) -> dict | None:
    """{norm: (values above the kernel, λ_max)} of S x = λ G x from the components' pencils, or
    None where S is not reflection invariant to :data:`INVARIANCE_RTOL` (the caller solves it unsplit).

    ``factors``: {norm: (L_0, L_1, ...)} the Cholesky factors of the blocks of G; ``kernel_parts``:
    (Z_0, Z_1, ...) from :meth:`ReflectionSplit.components` (None: no kernel deflated; a block whose
    S is definite then shares its factor between the norms, as :func:`~infsup_contact.solvers.spectra.bottom_spectra`)."""
    *halves, distance = split.blocks(S)
    if distance > INVARIANCE_RTOL:
        return None
    parts = [None if kernel_parts is None or not Z.shape[1] else Z for Z in (kernel_parts or [None] * len(halves))]
    shared = concurrent_map(lambda hZ: bottom.definite_factor(hZ[0]) if hZ[1] is None and hZ[0].shape[0] >= 3 else None,
                            list(zip(halves, parts)))  # side by side: LAPACK potrf, one BLAS thread each

    def solve(task):  # one block's pencil of one norm: (values above its kernel, its λ_max), or None
        norm, b = task
        Sb, Lb, Zb = halves[b], factors[norm][b], parts[b]
        free = Sb.shape[0] - (0 if Zb is None else Zb.shape[1])
        if free < 1:
            return None
        if free == 1 or Sb.shape[0] < 3:  # too small for Lanczos: the dense pencil
            ev = sla.eigh(Sb, Lb @ Lb.T, eigvals_only=True)
            return ev[(0 if Zb is None else Zb.shape[1]):], float(ev[-1])
        res = bottom.bottom_pencil(Sb, Lb, n_values, Zb, s_factor=shared[b])
        return res.values, res.lam_max

    # every (norm, block) side by side: the Lanczos products (symv, OpenBLAS's one thread) and the
    # factorizations, one BLAS thread each (each pencil the same operations: the same bits)
    tasks = [(norm, b) for norm, Ls in factors.items() for b in range(min(len(halves), len(Ls)))]
    solved = dict(zip(tasks, concurrent_map(solve, tasks)))
    out = {}
    for norm in factors:
        done = [r for (n, _), r in solved.items() if n == norm and r is not None]
        values = np.sort(np.concatenate([v for v, _ in done]))
        out[norm] = (values[:max(n_values, 1)], max([0.0] + [t for _, t in done]))
    return out


def symmetric_permutation(A: np.ndarray, p: np.ndarray) -> np.ndarray:
    """A[p][:, p] of a dense square A (bit for bit ``A[np.ix_(p, p)]``: the same entries copied),
    row by row with ``np.take``: at order 9,409 (Γ of k = 2, N = 48) 0.26 s against 1.5 s for
    the fancy index, whose gather walks A with stride 9,409 (the mirrored body's Schur
    complement and Steklov matrix, :func:`~infsup_contact.models.body_symmetry.mirrored_factors`)."""
    A = np.asarray(A)
    p = np.asarray(p, dtype=np.intp)
    if len(p) == len(A) and np.array_equal(p, np.arange(len(p))):  # the identity: the entries as they are
        return A.copy()
    out = np.empty((len(p), len(p)), dtype=A.dtype)
    for i, row in enumerate(p):
        np.take(A[row], p, out=out[i])
    return out
