"""Gram matrices of a non-tensor face space (:class:`~.face.spaces.cellwise.CellwiseFaceSpace`) on Γ = (0, 1)².

The norms are those of :mod:`.face.norms.tensor`; only the basis is not a tensor product. Every basis
function μ_j is, on each rectangle of the space's ``pieces`` (a tensor partition), one
polynomial of degree ≤ s per variable, so it lies in the tensor space

    P = M^0_s(xs) ⊗ M^0_s(ys)        (discontinuous Q_s on the pieces, :func:`~.segment.multipliers.make_space`)

and μ_j = Σ_p R_jp P_p exactly. R is the L² projection onto P, computed with a Gauss rule
exact per piece (s + 1 points per direction for the degree-2s products): R = C G_P⁻¹,
C_jp = ∫ μ_j P_p, G_P = the exact L² Gram of P. A continuous basis (standard, transformed,
pwlin) lies in the continuous Q_s of the pieces, M^1_s ⊗ M^1_s, a quarter of the dimension at
s = 1 (4C pwlin on QUAD9 at N = 32: 4,225 instead of 16,384); there R_jp = μ_j(node p), the
Lagrange interpolant being exact on P. Then

* L²: G = ∫ μ μᵀ by the same rule (exact: the integrand has degree 2s per variable on a piece);
* H = H^{1/2}_00(Γ)': μ_mn = Σ_p R_jp P^x_{a,m} P^y_{b,n}, the sine moments of a piece monomial
  product being products of the closed 1D forms (:func:`~.segment.norms.sine_coefficients`), so the
  partial sums are S_μ(n) = R S_P(n) Rᵀ (:func:`~.face.norms.tensor.partial_gram` of P) and the series is
  extrapolated in n_max on S_μ itself (:func:`~.face.norms.tensor.extrapolated`), with the tail
  exponent of μ (4 for continuous bases vanishing on ∂Γ, else 2; :attr:`~.face.spaces.cellwise.CellwiseFaceSpace.smooth_tail`).

Spaces on the same G_h often share P (the standard, dual and transformed bases of one element
all live in discontinuous Q_s on the cells): inside :func:`shared_piece_sums` their Grams reuse
the partial sums S_P(n) computed for the first of them (the series of P does not depend on μ).

That μ ∈ P is checked (residual of the projection at points of a finer rule): a space whose
pieces are not axis-aligned rectangles (4C ``pwlin`` on QUAD8) is refused.
"""
from __future__ import annotations

import contextlib
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ....errors import InputError
from ....la.threaded import symmetric_part, symmetric_sandwich
from ...gamma.coupling import weighted_values
from ....la import face_parity
from . import parity_bases
from ...gamma.symmetry import axis_reflections, isotypic_bases
from .tensor import default_cap, extrapolated, partial_gram, partial_gram_blocks, start_level
from ..spaces.tensor import FaceSpace
from ...segment.multipliers import make_space
from ...segment.norms import gram_by_norm, gram_l2
from ....la.richardson import BlockOps
from ...gamma.quadrature import gauss_legendre

#: Largest |μ − R P| / max|μ| accepted at the check points (round-off of the projection).
PROJECTION_TOL = 1e-9

_shared: dict | None = None
"""The partial sums S_P(n) kept while a :func:`shared_piece_sums` block is open: those of one
piece space at a time ({"key": its partition and degree, "sums": {n: S_P(n)}}), else None."""


@contextlib.contextmanager
def shared_piece_sums():
    """Within the block, :func:`gram_h_cellwise` keeps the partial sums S_P(n) of the latest
    piece space P and reuses them for every space on the same P (the same numbers: S_P(n) does
    not depend on μ). Memory: the levels n0, 2 n0, ... of one P, (dim P)² doubles each, released
    when another P is asked for and when the outermost block ends."""
    global _shared
    outer = _shared
    _shared = {} if outer is None else outer
    try:
        yield
    finally:
        _shared = outer


def piece_partial_gram(P: FaceSpace, n: int, parities=None, direct: bool = False):
    """S_P(n) of :func:`~.face.norms.tensor.partial_gram` (with ``parities``: its four parity blocks,
    :func:`~.face.norms.tensor.partial_gram_blocks`), from the shared sums when a
    :func:`shared_piece_sums` block is open."""
    def compute():
        return partial_gram(P, n, direct=direct) if parities is None else partial_gram_blocks(P, n, parities)

    if _shared is None:
        return compute()
    key = (np.asarray(P.breakpoints.xs, float).tobytes(), np.asarray(P.breakpoints.ys, float).tobytes(),
           P.degree, P.dim, parities is None, direct)
    if _shared.get("key") != key:
        _shared.clear()
        _shared.update(key=key, sums={})
    sums = _shared["sums"]
    if n not in sums:
        sums[n] = compute()
    return sums[n]


def piece_rule(partition, points: int) -> tuple[np.ndarray, np.ndarray]:
    """Tensor Gauss–Legendre rule with ``points`` per direction on every rectangle of
    ``partition``: points (q, 2), weights (q,); exact per variable up to degree 2·points − 1."""
    t, w = gauss_legendre(points)

    def axis(g):
        g = np.asarray(g, dtype=float)
        a, b = g[:-1, None], g[1:, None]
        return (0.5 * (a + b) + 0.5 * (b - a) * t).ravel(), (0.5 * (b - a) * w).ravel()

    (x, wx), (y, wy) = axis(partition.xs), axis(partition.ys)
    X, Y = np.meshgrid(x, y, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel()]), np.outer(wx, wy).ravel()


def piece_space(space) -> FaceSpace:
    """P = M^r_s ⊗ M^r_s on the space's pieces, r = 1 for a continuous space, else 0
    (:class:`InputError` if it has none)."""
    pieces = space.pieces
    if pieces is None:
        raise InputError("space", "a face space that is polynomial on the rectangles of a tensor partition "
                         "(4C pwlin on QUAD8 has triangular pieces)", got=space.name)
    s, cont = space.piece_degree, bool(space.continuous)
    return FaceSpace(make_space(pieces.xs, s, cont, False), make_space(pieces.ys, s, cont, False), pieces)


def _at(space, x: np.ndarray) -> sp.csr_matrix:
    """The basis at ``x`` as CSR, from its nonzero pattern (:func:`~.gamma.coupling.weighted_values`)."""
    return weighted_values(space, x, np.ones(len(x)))


def block_inverse_mass(space) -> sp.csr_matrix:
    """G⁻¹ of the exact L² mass matrix G of a discontinuous 1D space, inverted interval block
    by interval block: no dof is shared by two intervals, so G is block diagonal (checked)."""
    G = gram_l2(space)
    d = space.dofs                                                    # (intervals, s + 1)
    blocks = G[d[:, :, None], d[:, None, :]]
    if np.any(d < 0) or np.count_nonzero(G) != np.count_nonzero(blocks):
        raise InputError("space", "a discontinuous 1D space with every shape live (block-diagonal mass)",
                         got=space)
    inv = np.linalg.inv(blocks)
    rows, cols = np.broadcast_to(d[:, :, None], inv.shape), np.broadcast_to(d[:, None, :], inv.shape)
    return sp.csr_matrix((inv.ravel(), (rows.ravel(), cols.ravel())), shape=G.shape)


def projection(space) -> tuple[sp.csr_matrix, FaceSpace]:
    """(R, P) with μ_j = Σ_p R_jp P_p (module docstring), the identity checked at other points.

    R is sparse (μ_j meets the pieces of its support only). On a continuous P it holds the
    nodal values; else it is formed piece by piece: C = ∫ μ Pᵀ from both spaces' nonzero
    patterns at the per-piece Gauss points, R = C G_P⁻¹ with G_P⁻¹ = G_x⁻¹ ⊗ G_y⁻¹, the 1D
    masses of P inverted block by block."""
    P = piece_space(space)
    s = space.piece_degree
    if P.sx.continuous:
        R = _at(space, P.nodes()).T.tocsr()
    else:
        x, w = piece_rule(P.breakpoints, s + 1)
        C = weighted_values(space, x, w).T @ _at(P, x)
        R = (C @ sp.kron(*(block_inverse_mass(f) for f in P.factors), format="csr")).tocsr()
    R.eliminate_zeros()
    xc, _ = piece_rule(P.breakpoints, s + 2)
    mu = _at(space, xc)
    err = abs(mu - _at(P, xc) @ R.T).max() / max(abs(mu).max(), 1e-300)
    if err > PROJECTION_TOL:
        raise InputError("space", f"a face space in Q_{s} on each piece (projection residual {err:.2e})",
                         got=space.name)
    return R, P


def gram_l2_cellwise(space) -> np.ndarray:
    """Exact L²(Γ) Gram ∫ μ_i μ_j by the per-piece Gauss rule of degree 2s per variable."""
    G = _l2_sparse(space).toarray()
    return 0.5 * (G + G.T)


def _l2_sparse(space) -> sp.csr_matrix:
    """The L² Gram of :func:`gram_l2_cellwise`, sparse and not yet symmetrised."""
    P = piece_space(space)
    x, w = piece_rule(P.breakpoints, space.piece_degree + 1)
    return (weighted_values(space, x, w).T @ _at(space, x)).tocsr()


class SparseParityGram(face_parity.ParityGram):
    """The L² Gram of a cellwise space in the parity blocks of the axis reflections
    (:func:`l2_parity`), Q_cᵀ G Q_c from the sparse G (local supports: about 25 nonzeros a row
    at s = 2), its dense matrix made on first read (bit for bit :func:`gram_l2_cellwise`), its
    diagonal the sparse G's (the same entries): inside
    :func:`~infsup_contact.la.face_parity.deferred_assembly` a β_h request never forms the dense
    G (708 MB at k = 2, N = 48) nor splits it again."""

    def __init__(self, bases, blocks, sparse):
        super().__init__(bases, blocks)
        self._sparse = sparse

    @cached_property
    def dense(self) -> np.ndarray:
        G = self._sparse.toarray()
        G = 0.5 * (G + G.T)
        G.setflags(write=False)
        return G

    def diagonal(self) -> np.ndarray:
        return self._sparse.diagonal()


def l2_parity(space):
    """The L² Gram of a cellwise space as a :class:`SparseParityGram` in the components of the
    axis reflections (the H Gram's bases, :func:`_parity_route`), or None: the basis not mapped
    onto itself, an empty component, or G not block diagonal in them (a cross block above
    :data:`~infsup_contact.la.face_parity.INTERTWINE_RTOL` of G, Frobenius)."""
    bases = _reflection_bases(space, piece_space(space))
    if bases is None:
        return None
    G = _l2_sparse(space)
    sym = (0.5 * (G + G.T)).tocsr()
    blocks = face_parity.intertwined(sym, bases, bases)
    if blocks is None:
        return None
    return SparseParityGram(bases, [symmetric_part(B.toarray()) for B in blocks], G)


def gram_h_cellwise(space, rtol: float = 1e-6, n_start: int | None = None, n_cap: int | None = None,
                    exponent: float | None = None, reference: bool = False) -> tuple[np.ndarray, dict]:
    """The H^{1/2}_00(Γ)' Gram matrix (module docstring); arguments as :func:`~.face.norms.tensor.gram_h_face`
    (n0 default max(16, 2 (s + 1) N), N the pieces per direction, raised for a long series as
    there, :func:`~.face.norms.tensor.start_level`). In the parity blocks where the space has
    them (:func:`_parity_route`, the blocks in ``info["parity"]``); ``reference``: the whole
    matrix by the direct sums, on the same levels."""
    if not rtol > 0:
        raise InputError("rtol", "a positive float", got=rtol)
    R, P = projection(space)
    p = (4.0 if space.smooth_tail else 2.0) if exponent is None else float(exponent)
    n_int = max(len(P.breakpoints.xs), len(P.breakpoints.ys)) - 1
    n0 = (start_level(max(16, 2 * (space.piece_degree + 1) * n_int), p, P.dim) if n_start is None
          else int(n_start))
    n_cap = default_cap(P.dim) if n_cap is None else n_cap

    blocked = None if reference else _parity_route(space, R, P)
    if blocked is not None:  # the four parity blocks of the axis reflections (:mod:`infsup_contact.la.face_parity`)
        parities, Rs, bases = blocked
        G, info = extrapolated(lambda n: face_parity.sandwiched(Rs, piece_partial_gram(P, n, parities)),
                               p, n0, n_cap, rtol, ops=BlockOps)
        G, parity = face_parity.gram_of(bases, G)  # G deferred in a β_h request
        return G, dict(info, parity=parity)

    def partial(n):  # S_P is exactly symmetric; the sandwich only to round-off
        return symmetric_part(symmetric_sandwich(R, piece_partial_gram(P, n, direct=reference)))

    return extrapolated(partial, p, n0, n_cap, rtol)


def _parity_route(space, R, P):
    """(P's 1D parities, [R̃_c], the multiplier basis's components Q_c) where both bases are
    symmetric under both axis reflections with R intertwining them, else None."""
    parities = parity_bases.tensor_parities(P)
    if parities is None:
        return None
    bases = _reflection_bases(space, P)
    if bases is None:
        return None
    Rs = face_parity.intertwined(R, bases, face_parity.tensor_bases(parities))
    return None if Rs is None else (parities, Rs, bases)


def _reflection_bases(space, P):
    """The multiplier basis's components Q_c under the two axis reflections (checked at P's
    Gauss points), or None: the basis not mapped onto itself, or an empty component."""
    pis = axis_reflections(space, piece_rule(P.breakpoints, space.piece_degree + 1)[0])
    if pis is None:
        return None
    bases = isotypic_bases(pis)
    return None if min(Q.shape[1] for Q in bases) < 1 else bases


def gram_cellwise(space, norm: str, **kwargs) -> tuple[np.ndarray, dict]:
    """Gram matrix for ``norm`` ∈ {"H", "L2"} of a non-tensor face space; the L² Gram inside
    :func:`~infsup_contact.la.face_parity.deferred_assembly` in its parity blocks where it has
    them (:func:`l2_parity`, also in ``info["parity"]``)."""
    parity = l2_parity(space) if norm == "L2" and face_parity.deferring() else None
    G, info = gram_by_norm(norm, lambda: gram_l2_cellwise(space) if parity is None else parity,
                           lambda **kw: gram_h_cellwise(space, **kw), **kwargs)
    return G, (info if parity is None else dict(info, parity=parity))
