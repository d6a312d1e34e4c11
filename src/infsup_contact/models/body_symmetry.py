"""The symmetries of a 3D body, found on its dofs and checked on its stiffness.

A map T of the body onto itself that maps its mesh onto itself, Γ onto Γ and the supports onto
the supports permutes its basis: φ_j ∘ T = φ_π(j) (NGSolve's hierarchical Q_k / P_k for k ≤ 2 and
the nodal HEX20 basis; a basis function whose sign T reverses makes π no permutation and the
body keeps the general route). π is found numerically from a signature of each dof that T maps
as it maps points: the centroid ∫ x φ_j / ∫ φ_j (NGSolve, four linear forms) or the node
(scikit-fem's ``doflocs``), with the invariants ∫ φ_j and K_jj (:func:`dof_signature`,
:func:`permutation`); a signature that matches no dof or two is no symmetry. π is then
**checked**: every dof's image is a free dof, Γ dofs go to Γ dofs, and P K Pᵀ = K entry by entry
to :data:`COMMUTE_RTOL` of max |K| (:func:`commutes`) — K is all the factorization sees, so S and
the solves follow from it.

Two uses (:func:`~.contract.factorized_side`, :func:`mirrored_side`):

* the square's reflections x → 1 − x, y → 1 − y (:func:`involutions`): the structured hexahedra
  (Q_k, HEX20) have both, and the body is factorized in four parity parts
  (:mod:`infsup_contact.la.body_parity`); where one involution alone maps the body (the Kuhn
  tetrahedra: the diagonal x ↔ y and its partner, whatever the mesh generator chose; tested) two
  parts; where none (perturbed meshes, the unstructured tetrahedra, a narrower body), the general
  route;
* the mirror of the pair, body 2 → body 1 (z → 2 − z, or the point reflection about the centre of Γ
  where the mirror reverses the tetrahedra's diagonals): on a matching pair side 2's K is side 1's
  permuted, checked entry by entry, and so are its Schur complement and solves (:func:`mirrored_side`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..discretization.gamma.symmetry import isotypic_bases
from ..la.reflection import symmetric_permutation
from ..la.threaded import concurrent_map, threads

ENABLED = True
"""Whether the sides use their symmetries (False: the general route everywhere; the tests'
reference route)."""
MATCH_TOL = 1e-8
"""Largest distance of a transformed signature from its match (coordinates of order 1, the
invariants scaled to max 1); the next nearest must be farther."""
COMMUTE_RTOL = 1e-10
"""Largest max |P K Pᵀ − K| / max |K| of a symmetry (assembly round-off is ~1e-15; a perturbed
mesh differs at O(1))."""


def _reflect(*axes, flip_z: bool = False):
    def transform(p):
        q = np.array(p, dtype=float)
        for a in axes:
            q[:, a] = 1.0 - q[:, a]
        if flip_z:
            q[:, 2] = 2.0 - q[:, 2]
        return q
    return transform


def _swap(anti: bool = False):
    def transform(p):
        q = np.array(p, dtype=float)
        q[:, 0], q[:, 1] = (1.0 - p[:, 1], 1.0 - p[:, 0]) if anti else (p[:, 1], p[:, 0])
        return q
    return transform


REFLECT_X, REFLECT_Y, POINT = _reflect(0), _reflect(1), _reflect(0, 1)
SWAP, ANTISWAP = _swap(), _swap(anti=True)
GROUPS = ((REFLECT_X, REFLECT_Y), (SWAP, ANTISWAP), (POINT,), (SWAP,), (ANTISWAP,), (REFLECT_X,), (REFLECT_Y,))
"""Commuting involutions of the square tried in turn: the first group that maps the body is used."""
MIRRORS = (_reflect(flip_z=True), _reflect(0, 1, flip_z=True))
"""Maps of body 2 onto body 1 fixing Γ = (0,1)² × {1} as a set: z → 2 − z, and the point reflection."""


def ngsolve_signature(fes) -> np.ndarray:
    """(ndof, 4): the centroid ∫ x φ_j / ∫ φ_j and ∫ φ_j of every dof of an NGSolve space, or
    None where some ∫ φ_j vanishes (no centroid)."""
    import ngsolve

    v = fes.TestFunction()
    cols = []
    for f in (ngsolve.CoefficientFunction(1.0), ngsolve.x, ngsolve.y, ngsolve.z):
        form = ngsolve.LinearForm(fes)
        form += f * v * ngsolve.dx
        form.Assemble()
        cols.append(form.vec.FV().NumPy().copy())
    mass = cols[0]
    if np.abs(mass).min() <= 1e-12 * np.abs(mass).max():
        return None
    return np.column_stack([c / mass for c in cols[1:]] + [mass])


def _keys(signature: np.ndarray, K) -> tuple:
    """(points (n, 3), invariants (n, m) scaled to max 1): the signature's coordinates and its
    other columns with K's diagonal."""
    inv = np.column_stack([signature[:, 3:], K.diagonal()])
    scale = np.abs(inv).max(axis=0)
    return signature[:, :3], inv / np.where(scale > 0, scale, 1.0)


def _reference_tree(ref_points, ref_inv) -> cKDTree:
    """The search tree of the reference keys (:func:`_match`; one body's, shared by its candidates)."""
    return cKDTree(np.column_stack([ref_points, ref_inv]), balanced_tree=False, compact_nodes=False)


def _match(ref_points, ref_inv, points, inv, tree: cKDTree | None = None) -> np.ndarray | None:
    """σ with (points, inv)[i] = (ref_points, ref_inv)[σ(i)] to :data:`MATCH_TOL` (the nearest
    reference), a bijection; else None. A wrong but close match cannot pass: the caller checks K.
    ``tree``: the reference's :func:`_reference_tree`, where the caller already has it."""
    if len(points) != len(ref_points) or len(points) < 2:
        return None
    tree = _reference_tree(ref_points, ref_inv) if tree is None else tree
    # the query split over the request's threads (scipy's own, without the GIL; each point's
    # nearest reference is the same however the points are shared out)
    dist, sigma = tree.query(np.column_stack([points, inv]), k=1, distance_upper_bound=MATCH_TOL,
                             workers=threads())
    if not np.all(np.isfinite(dist)):
        return None
    return sigma if np.unique(sigma).size == sigma.size else None


def _by_rows(*matrices) -> tuple:
    """The matrices as CSR for a row-by-row check: CSC ones (every one) as the CSR of their
    transposes, the same arrays without a conversion — what the checks read is the same for Kᵀ
    (its diagonal; P Kᵀ Pᵀ = (P K Pᵀ)ᵀ, so K_image = K[σ][:, σ] entry by entry iff the same holds
    for the transposes) — else converted to CSR."""
    if all(sp.issparse(M) and M.format == "csc" for M in matrices):
        return tuple(M.T for M in matrices)
    return tuple(sp.csr_matrix(M) for M in matrices)


BLOCK_ENTRIES = 2 ** 18
"""Stored entries of K per row block of :func:`commutes`: its temporaries (a few MB) are reused
from block to block, where whole-matrix ones (~30 bytes an entry, 0.5 GB at k = 2, N = 32) were
fresh memory each time (the pair's build spent about a third of its CPU time in the kernel)."""


def commutes(K, K_image, sigma: np.ndarray) -> bool:
    """Whether K_image = K[σ][:, σ] entry by entry to :data:`COMMUTE_RTOL` of max |K| (CSR, or two
    CSC matrices by their transposes, :func:`_by_rows`; row block by row block of K_image: K's rows
    σ gathered, their column indices mapped by σ⁻¹ and sorted, equal patterns compared value by
    value, other patterns, explicit zeros or no symmetry, as the difference of the two blocks; the
    first block that differs decides)."""
    K, K_image = _by_rows(K, K_image)
    n = sigma.size
    inverse = np.empty(n, dtype=K.indices.dtype)
    inverse[sigma] = np.arange(n, dtype=inverse.dtype)
    image = K_image if K_image.has_sorted_indices else K_image.sorted_indices()
    scale = np.abs(K.data).max() if K.nnz else 1.0
    step = max(1, int(BLOCK_ENTRIES * n // max(K.nnz, 1)))
    tolerance = COMMUTE_RTOL * scale
    for a in range(0, n, step):
        b = min(a + step, n)
        rows = K[sigma[a:b]]
        block = sp.csr_matrix((rows.data, inverse[rows.indices], rows.indptr), shape=(b - a, K.shape[1]))
        block.sort_indices()
        lo, hi = image.indptr[a], image.indptr[b]
        indptr = image.indptr[a:b + 1] - lo
        if np.array_equal(block.indptr, indptr) and np.array_equal(block.indices, image.indices[lo:hi]):
            diff = block.data - image.data[lo:hi]
        else:
            diff = (block - sp.csr_matrix((image.data[lo:hi], image.indices[lo:hi], indptr), shape=block.shape)).data
        if diff.size and not np.abs(diff).max() <= tolerance:  # a NaN is no match either
            return False  # the first block off K decides
    return True


def _gamma_closed(sigma: np.ndarray, n_gamma: int) -> bool:
    n = sigma.size
    return bool(np.all(sigma[n - n_gamma:] >= n - n_gamma))


def permutation(signature: np.ndarray, K, n_gamma: int, transform, keys: tuple | None = None) -> np.ndarray | None:
    """π of the free dofs (rows of ``signature`` and K, Γ the last ``n_gamma``) with
    φ_j ∘ T = φ_π(j), checked (module text), or None. ``keys``: the body's (points, invariants,
    search tree) where the caller tries several T (:func:`involutions`)."""
    points, inv, tree = keys if keys is not None else (*_keys(signature, K), None)
    pi = _match(points, inv, transform(points), inv, tree)
    if pi is None or np.any(pi[pi] != np.arange(pi.size)) or not _gamma_closed(pi, n_gamma):
        return None
    return pi if commutes(K, K, pi) else None


def involutions(signature, K, n_gamma: int) -> tuple | None:
    """The first group of :data:`GROUPS` whose every involution maps the body (checked, commuting),
    as permutations of the free dofs; None if none (or ``signature`` is None, or :data:`ENABLED` is off)."""
    if signature is None or not ENABLED or len(signature) < 2:  # nothing to split (N = 1: no free dof)
        return None
    K, = _by_rows(K)  # once for every candidate
    points, inv = _keys(signature, K)
    keys = (points, inv, _reference_tree(points, inv))  # the body's own, whatever T is tried
    found = {}
    for group in GROUPS:
        pis = []
        for T in group:
            if T not in found:
                found[T] = permutation(signature, K, n_gamma, T, keys)
            pis.append(found[T])
        if all(pi is not None for pi in pis) and all(np.array_equal(a[b], b[a]) for a in pis for b in pis):
            return tuple(pis)
    return None


def parity_bases(signature, K, n_gamma: int) -> tuple | None:
    """The isotypic bases (Q_0, ...) of the body's group (:func:`involutions`), or None."""
    pis = involutions(signature, K, n_gamma)
    return None if pis is None else isotypic_bases(pis)


def mirror_permutation(signature1, K1, signature2, K2, n_gamma: int) -> np.ndarray | None:
    """σ with K2 = K1[σ][:, σ] (body 2's free dof i is body 1's σ(i) under a map of
    :data:`MIRRORS`, Γ to Γ), checked entry by entry; None where no mirror maps the bodies."""
    if signature1 is None or signature2 is None or not ENABLED or K1.shape != K2.shape or K1.shape[0] < 2:
        return None
    K1, K2 = _by_rows(K1, K2)
    points1, inv1 = _keys(signature1, K1)
    points2, inv2 = _keys(signature2, K2)
    tree = _reference_tree(points1, inv1)  # body 1's, whichever mirror is tried
    for M in MIRRORS:
        sigma = _match(points1, inv1, M(points2), inv2, tree)
        if sigma is not None and _gamma_closed(sigma, n_gamma) and commutes(K1, K2, sigma):
            return sigma
    return None


class MirroredSolve:
    """b ↦ K2⁻¹ b = P K1⁻¹ Pᵀ b for K2 = K1[σ][:, σ] (P b = b[σ]), from body 1's solve."""

    def __init__(self, solve1, sigma: np.ndarray):
        self.solve1, self.sigma = solve1, sigma

    def __call__(self, b):
        b = np.asarray(b, dtype=float)
        w = np.empty_like(b)
        w[self.sigma] = b
        return self.solve1(w)[self.sigma]


SEARCH = object()
"""``sigma`` of :func:`mirrored_factors` not given: it looks for the mirror itself."""


def mirrored_factors(side1, signature2, K2, sigma=SEARCH) -> tuple | None:
    """(S2, solve2, X2 or None, X2's parity blocks or None) of body 2 from side 1's (its
    ``signature`` attribute, its stiffness, schur, solve, steklov, steklov_parts) through the
    checked mirror (:func:`mirror_permutation`; ``sigma``: its result for these bodies, where the
    caller looked already), else None. X2 = X1[τ][:, τ], so its blocks are side 1's with the rows of
    each P_c permuted (the X_c themselves shared)."""
    n_gamma = len(side1.trace.gamma_dofs)
    if sigma is SEARCH:
        sigma = mirror_permutation(getattr(side1, "signature", None), side1.stiffness, signature2, K2, n_gamma)
    if sigma is None:
        return None
    n = sigma.size
    tau = sigma[n - n_gamma:] - (n - n_gamma)
    # S2 and X2 side by side (np.take, GIL-free: the same copies)
    S, X = concurrent_map(lambda A: None if A is None else symmetric_permutation(A, tau), [side1.schur, side1.steklov])
    parts1 = getattr(side1, "steklov_parts", None)
    parts = None if parts1 is None else tuple((P[tau], Xc) for P, Xc in parts1)
    return S, MirroredSolve(side1.solve, sigma), X, parts
