"""Gram matrices of a non-tensor face space (:class:`~.face_cells.CellwiseFaceSpace`) on Γ = (0, 1)².

The norms are those of :mod:`.face_norms`; only the basis is not a tensor product. Every basis
function μ_j is, on each rectangle of the space's ``pieces`` (a tensor partition), one
polynomial of degree ≤ s per variable, so it lies in the tensor space

    P = M^0_s(xs) ⊗ M^0_s(ys)        (discontinuous Q_s on the pieces, :func:`~.multipliers.make_space`)

and μ_j = Σ_p R_jp P_p exactly. R is the L² projection onto P, computed with a Gauss rule
exact per piece (s + 1 points per direction for the degree-2s products): R = C G_P⁻¹,
C_jp = ∫ μ_j P_p, G_P = the exact L² Gram of P. Then

* L²: G = ∫ μ μᵀ by the same rule (exact: the integrand has degree 2s per variable on a piece);
* H = H^{1/2}_00(Γ)': μ_mn = Σ_p R_jp P^x_{a,m} P^y_{b,n}, the sine moments of a piece monomial
  product being products of the closed 1D forms (:func:`~.norms.sine_coefficients`), so the
  partial sums are S_μ(n) = R S_P(n) Rᵀ (:func:`~.face_norms.partial_gram` of P) and the series is
  extrapolated in n_max on S_μ itself (:func:`~.face_norms.extrapolated`), with the tail
  exponent of μ (4 for continuous bases vanishing on ∂Γ, else 2; :attr:`~.face_cells.CellwiseFaceSpace.smooth_tail`).

That μ ∈ P is checked (residual of the projection at points of a finer rule): a space whose
pieces are not axis-aligned rectangles (4C ``pwlin`` on QUAD8) is refused.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from .face_norms import extrapolated, gram_l2_face, partial_gram
from .face_spaces import FaceSpace
from .multipliers import make_space
from .norms import N_MAX_CAP, gram_by_norm
from .quadrature import gauss_legendre

#: Largest |μ − R P| / max|μ| accepted at the check points (round-off of the projection).
PROJECTION_TOL = 1e-9


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
    """P = M^0_s ⊗ M^0_s on the space's pieces (:class:`InputError` if it has none)."""
    pieces = getattr(space, "pieces", None)
    if pieces is None:
        raise InputError("space", "a face space that is polynomial on the rectangles of a tensor partition "
                         "(4C pwlin on QUAD8 has triangular pieces)", got=getattr(space, "element", space))
    s = space.piece_degree
    return FaceSpace(make_space(pieces.xs, s, False, False), make_space(pieces.ys, s, False, False), pieces)


def projection(space) -> tuple[np.ndarray, FaceSpace]:
    """(R, P) with μ_j = Σ_p R_jp P_p (module docstring), the identity checked at other points."""
    P = piece_space(space)
    s = space.piece_degree
    x, w = piece_rule(P.breakpoints, s + 1)
    C = (space.evaluate(x) * w[:, None]).T @ P.evaluate(x)
    R = np.linalg.solve(gram_l2_face(P), C.T).T
    xc, _ = piece_rule(P.breakpoints, s + 2)
    mu = space.evaluate(xc)
    err = np.max(np.abs(mu - P.evaluate(xc) @ R.T)) / max(np.max(np.abs(mu)), 1e-300)
    if err > PROJECTION_TOL:
        raise InputError("space", f"a face space in Q_{s} on each piece (projection residual {err:.2e})",
                         got=getattr(space, "element", space))
    return R, P


def gram_l2_cellwise(space) -> np.ndarray:
    """Exact L²(Γ) Gram ∫ μ_i μ_j by the per-piece Gauss rule of degree 2s per variable."""
    P = piece_space(space)
    x, w = piece_rule(P.breakpoints, space.piece_degree + 1)
    E = space.evaluate(x)
    G = (E * w[:, None]).T @ E
    return 0.5 * (G + G.T)


def gram_h_cellwise(space, rtol: float = 1e-6, n_start: int | None = None, n_cap: int = N_MAX_CAP // 8,
                    exponent: float | None = None) -> tuple[np.ndarray, dict]:
    """The H^{1/2}_00(Γ)' Gram matrix (module docstring); arguments as :func:`~.face_norms.gram_h_face`
    (n0 default max(16, 2 (s + 1) N), N the pieces per direction)."""
    if not rtol > 0:
        raise InputError("rtol", "a positive float", got=rtol)
    R, P = projection(space)
    p = (4.0 if space.smooth_tail else 2.0) if exponent is None else float(exponent)
    n_int = max(len(P.breakpoints.xs), len(P.breakpoints.ys)) - 1
    n0 = max(16, 2 * (space.piece_degree + 1) * n_int) if n_start is None else int(n_start)

    def partial(n):
        S = R @ partial_gram(P, n) @ R.T
        return 0.5 * (S + S.T)

    return extrapolated(partial, p, n0, n_cap, rtol)


def gram_cellwise(space, norm: str, **kwargs) -> tuple[np.ndarray, dict]:
    """Gram matrix for ``norm`` ∈ {"H", "L2"} of a non-tensor face space."""
    return gram_by_norm(norm, lambda: gram_l2_cellwise(space), lambda **kw: gram_h_cellwise(space, **kw), **kwargs)
