"""Γ's reflections for the engine: the split of a multiplier space and the kernel on its components.

The linear algebra of a reflection-invariant pencil (its isotypic blocks, the components'
pencils) is :mod:`infsup_contact.la.reflection`; here the split is found on a space's basis
(:func:`reflection_split`, checked at Gauss points of G_h with
:func:`~infsup_contact.discretization.gamma.symmetry.induced_permutation`) and the kernel of Bᵀ
is decided on the split's components (:func:`split_bottom_kernel`, the certificates of
:mod:`.kernel`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..discretization.gamma.symmetry import axis_reflections, induced_permutation, isotypic_bases, reflect
from ..la import bottom, openblas
from ..la.parity_sandwich import strongest_components
from ..la.reflection import ReflectionSplit
from ..la.threaded import concurrent_map
from .kernel import BLOCK_EXTRA, KernelDecision, certified_bottom, certify_floor, decide, error_level, right_singular


def reflection_split(space, points: np.ndarray) -> ReflectionSplit | None:
    """The split of ``space`` by the reflections of Γ that map its basis onto itself, checked
    at ``points`` (e.g. the Gauss points of G_h; (n,) on the segment, (n, 2) on the face), or None.

    On the face the reflections x → 1 − x and y → 1 − y together (four components: a tensor
    mesh pair symmetric in each direction, the structured hexahedra) where both map the basis,
    else the point reflection (x, y) → (1 − x, 1 − y) alone (two: e.g. the Kuhn triangles,
    whose diagonals the axis reflections reverse); on the segment x → 1 − x."""
    x = np.asarray(points, float)
    pis = axis_reflections(space, x) if x.ndim == 2 and x.shape[1] == 2 else None
    if pis is None:
        pi = induced_permutation(space, x, reflect())
        pis = None if pi is None else (pi,)
    return None if pis is None else ReflectionSplit(pis, isotypic_bases(pis))


def split_of(space, gamma, g_h, k: int, face_only: bool = False) -> ReflectionSplit | None:
    """The reflections' split of ``space`` (:func:`reflection_split`, checked at the Gauss
    points of G_h), or None (no such symmetry, a Γ without a quadrature, or an empty component).
    ``face_only``: None on a one-dimensional Γ too (the dense route splits the face's pencils
    only: the segment's are small, and its rows keep their digits)."""
    quadrature = getattr(gamma, "quadrature", None)
    if quadrature is None:
        return None
    points = quadrature(g_h, 2 * k)[0]
    if face_only and not (np.ndim(points) == 2 and np.shape(points)[1] == 2):
        return None
    split = reflection_split(space, points)
    return split if split is not None and min(split.sizes) >= 1 else None


def split_bottom_kernel(W, split: ReflectionSplit, proven: int = 0, entry_error: float = 0.0) -> KernelDecision | None:
    """:func:`~.kernel.bottom_kernel` of W (trace dofs × multipliers, sparse) on the columns
    W Q_c of each component, or None where the split does not hold.

    With the traces' reflections W is equivariant, so WᵀW is block diagonal in Q = [Q_0, Q_1, ...]
    and its eigenvalues are those of the blocks; the off-diagonal part O of the computed WᵀW
    in Q is round-off, and moves each eigenvalue by at most ‖O‖₂ (Weyl; <= ‖C‖_F for the one
    block C of two components, <= ‖O‖_F beyond). Each block goes through the same steps as the
    unsplit route (block inverse iteration, counted values ‖W v‖ of orthonormal v, hence upper
    bounds of singular values of W; the Cholesky certificate at τ_b = σ_{d_b+1}²/2 per block:
    the block-diagonal WᵀW has at most d = Σ d_b eigenvalues below min τ_b, so the computed
    one at most d below min τ_b − ‖O‖₂ >= min τ_b / 2), with the unsplit
    η = max(rows, m) ε σ_max + 2 ‖δW‖_F. None (the caller takes the unsplit route) wherever a
    step would fall back, or the bound on ‖O‖₂ > τ_b / 2."""
    W = sp.csr_matrix(W)
    rows, m = W.shape
    proven = int(max(proven, m - rows, 0))
    bases = split.bases

    def prepared(Q):  # a component's W Q_c, its Gram and σ_max (sparse products and Lanczos)
        B = sp.csr_matrix(W @ Q)
        g = sp.csr_matrix(B.T @ B)
        return B, g, (bottom.largest_singular(B, g) if B.shape[1] else 0.0)

    # the components side by side, then their cross products (GIL-free: the same bits)
    blocks, grams, smaxes = map(list, zip(*concurrent_map(prepared, bases)))
    pairs = [(a, b) for b in range(len(blocks)) for a in range(b)]
    off = concurrent_map(lambda ab: float(sp.linalg.norm(blocks[ab[0]].T @ blocks[ab[1]])), pairs)
    # ‖O‖₂ of the off-diagonal part O of WᵀW in Q: ‖C‖₂ <= ‖C‖_F for two blocks, ‖O‖_F beyond
    cross = off[0] if len(off) == 1 else float(np.sqrt(2.0 * np.sum(np.square(off))))
    smax = max(smaxes)
    tol = error_level(rows, m, smax, entry_error)
    floor = max(certify_floor(rows, m, smax), 2.0 * cross)  # the whole W's certificate at τ − ‖O‖
    if min(B.shape[1] for B in blocks) < 2:
        return None

    def certified(b):
        mb = blocks[b].shape[1]
        hint = int(np.ceil(proven * mb / m))  # a block size only: each half holds about its share
        return certified_bottom(blocks[b], grams[b], min(hint + BLOCK_EXTRA, mb - 1), tol, smaxes[b], floor)

    # the blocks side by side (LAPACK by la/openblas.py and sparse products: GIL-free, one BLAS thread each; each
    # block's steps are the same operations whatever runs beside them, so the same bits)
    results = concurrent_map(certified, range(len(blocks)))
    if any(res is None for res in results):
        return None
    counted, vectors, above = [], [], np.inf
    for res, Q in zip(results, bases):
        counted.append(res.values[:res.count])
        vectors.append(np.asarray(Q @ res.vectors[:, :res.count]))
        above = min(above, float(res.above))
    d = sum(len(c) for c in counted)
    if d < proven:
        return None
    s = np.concatenate([np.sort(np.concatenate(counted)), [above, smax]])
    return decide(s, proven, tol, d, smax, np.hstack(vectors))


def _cross_norm(blocks) -> float:
    """‖O‖_F of :func:`split_dense_kernel`: O's blocks (W Q_a)ᵀ (W Q_b), a < b, each counted twice,
    from the sparse W Q_c (a coupling touches only the trace dofs under its multiplier's support:
    the dense products cost 6 rows (m/4)² flops, as much as the blocks' SVDs at R5.4, k = 2,
    N = 24). O is itself round-off, bounded against σ_{d+1}²: another order of its sums does not matter."""
    off2 = sum(sp.linalg.norm((blocks[a].T @ blocks[b]).tocsr()) ** 2
               for b in range(len(blocks)) for a in range(b) if blocks[a].shape[1] and blocks[b].shape[1])
    return float(np.sqrt(2.0 * off2))


def split_dense_kernel(W: np.ndarray, split: ReflectionSplit, proven: int = 0,
                       entry_error: float = 0.0, vectors: bool = False, row_bases=None) -> KernelDecision | None:
    """:func:`~.kernel.coupling_kernel` of W (trace dofs × multipliers, dense or sparse) from the singular
    values of its components' columns W Q_c (about (1/c)² of the whole SVD's flops), or None (the
    caller's dense SVD decides).

    With the traces' reflections W is equivariant, so in Q = [Q_0, Q_1, ...] the computed WᵀW
    is D + O, D = diag((W Q_c)ᵀ (W Q_c)) and O the round-off across components (‖O‖₂ <= ‖O‖_F,
    computed). The blocks' count d is taken only where it is provably W's count (η the unsplit
    :func:`~.kernel.error_level` of σ_max, the same from either):

    * at least d values <= η: the counted right vectors v_j of the blocks, x_j = Q_c v_j, are
      orthonormal with ‖W x_j‖ = σ_j, so by Cauchy interlacing W has d singular values <= ‖W X‖₂
      <= ‖W X‖_F = (Σ_j σ_j²)^{1/2}; required <= η (the cross terms cancel nothing here: the
      bound holds whatever O is);
    * at most d: Weyl on D + O, σ_{d+1}(W)² >= σ'_{d+1}² − ‖O‖₂; required > η².

    And only where d is exactly the proven count: the margin is then log10(σ_{d+1}/η), a value
    above round-off, which the blocks give to its relative ‖O‖/σ_{d+1}²; where modes beyond the
    proof would be counted the margin rests on a round-off singular value, and the whole SVD
    reports it as before (None). ``vectors``: also the kernel's basis, the blocks' right singular
    vectors below η mapped by Q_c (orthonormal: the Q_c are).

    ``row_bases``: the trace dofs' components (R_0, ...: orthonormal, complete; the bodies'
    parity parts on Γ, :func:`row_components`), which the equivariant W Q_c keeps to one of them
    but round-off: each block is then R_{σ(c)}ᵀ W Q_c (about 1/2^g of the rows, as many fewer QR
    flops), and the rows dropped, O_c, enter the first bound (‖W X‖_F² <= Σ_j σ_j² + Σ_c ‖O_c‖_F²,
    computed) — not the second: (W Q_c)ᵀ (W Q_c) = A_cᵀ A_c + O_cᵀ O_c ⪰ A_cᵀ A_c, so the kept
    rows' σ_{d+1} is a lower bound of the whole block's."""
    W = sp.csr_matrix(W, dtype=float)
    rows, m = W.shape
    proven = int(max(proven, m - rows, 0))
    if rows == 0 or m == 0:
        return None
    sparse = [(W @ Q).tocsc() for Q in split.bases]  # the products of W's nonzeros, in W's order
    cross = _cross_norm(sparse)
    sparse, dropped_rows = row_components(sparse, row_bases)
    blocks = [B.toarray(order="F") for B in sparse]  # Fortran-ordered: their QR in place
    del sparse  # not needed past the cross term: freed before the SVDs
    live = [(B, Q) for B, Q in zip(blocks, split.bases) if B.shape[1]]
    # the blocks' SVDs side by side (LAPACK by la/openblas.py, GIL-free, one BLAS thread each: the same bits)
    if vectors:  # each block's SVD with its right vectors, ascending (structural zeros first)
        svds = concurrent_map(lambda BQ: right_singular(BQ[0], overwrite=True), live)
        per_block = [np.concatenate([np.zeros(B.shape[1] - len(sb)), np.sort(sb)]) for (B, _), (sb, _) in zip(live, svds)]
        s = per_block
    else:
        s = concurrent_map(lambda BQ: openblas.gesdd(np.asarray_chkfinite(BQ[0]), False)[0], live)  # as coupling_kernel
    s = np.sort(np.concatenate([np.zeros(m - sum(len(v) for v in s))] + s))
    s_max = float(s[-1])
    tol = error_level(rows, m, s_max, entry_error)
    numerical = int(np.sum(s <= tol))
    if numerical != proven:
        return None
    below = float(np.sqrt(np.sum(s[:numerical] ** 2) + dropped_rows)) <= tol
    above = s[numerical] ** 2 - cross > tol ** 2 if numerical < m else True
    if not (below and above):
        return None
    if not vectors:
        return decide(s, proven, tol, numerical, s_max)
    basis = []
    for (B, Q), (sb, vt), asc in zip(live, svds, per_block):
        d_b = int(np.sum(asc <= tol))
        if d_b:
            basis.append(np.asarray(Q @ vt[::-1][:d_b].T))  # rows of vt descending: the smallest last
    return decide(s, proven, tol, numerical, s_max, np.hstack(basis) if basis else np.zeros((m, 0)))


def row_components(blocks, row_bases) -> tuple:
    """([R_{σ(c)}ᵀ B_c, ...], Σ_c Σ_{d ≠ σ(c)} ‖R_dᵀ B_c‖_F²) for the column blocks B_c = W Q_c and
    the row components ``row_bases`` (σ(c) the component holding most of B_c: a bijection between
    the non-empty blocks, else the blocks unchanged, 0.0); ``row_bases`` None: the same."""
    if row_bases is None:
        return blocks, 0.0
    RT = [sp.csr_matrix(R.T) for R in row_bases]
    parts = [[(Rt @ B).tocsc() for Rt in RT] if B.shape[1] else [] for B in blocks]
    energy = [[sp.linalg.norm(T) ** 2 if T.nnz else 0.0 for T in row] for row in parts]
    sigma = strongest_components(energy)
    if sigma is None:
        return blocks, 0.0
    kept = [row[s] if s is not None else B for row, s, B in zip(parts, sigma, blocks)]  # B: empty or zero
    # the rest summed as such, not as a difference: no cancellation
    dropped = float(sum(v for row, s in zip(energy, sigma) for d, v in enumerate(row) if d != s))
    total = float(sum(map(sum, energy)))
    if dropped > ROWS_SPLIT_RTOL * total:  # the rows do not split (another group: the tetrahedra's)
        return blocks, 0.0
    return kept, dropped


ROWS_SPLIT_RTOL = 1e-20
"""Largest share of ‖W Q_c‖_F² outside the kept row components for which :func:`row_components`
reduces the rows (round-off is about ε² ≈ 5e-32 of it; a body group that is not the face's leaves
a share of order one)."""

