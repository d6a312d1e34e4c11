"""Gram matrices of a face multiplier space M^x ⊗ M^y (:mod:`.face.spaces.tensor`) on Γ = (0, 1)².

L²(Γ): the norm is separable, so G = G_x ⊗ G_y with the exact 1D mass matrices
(:func:`~.segment.norms.gram_l2`).

M = H^{1/2}_00(Γ)': the spectral realisation of the 1D module (:mod:`.segment.norms`) on the square.
The Dirichlet Laplacian of (0, 1)² has the L²-orthonormal eigenfunctions 2 sin(mπx) sin(nπy)
with eigenvalues π²(m² + n²); H^{1/2}_00 is the interpolation space halfway between L² and
H¹_0, whose norm weights a coefficient by π√(m² + n²), and its dual

    ‖μ‖²_M = Σ_{m,n≥1} μ_mn² / (π √(m² + n²)),     μ_mn = 2 ∬ μ sin(mπx) sin(nπy).

For a tensor basis function μ^x_a(x) μ^y_b(y) the coefficient factorizes, μ_mn = μ^x_{a,m} μ^y_{b,n},
with the 1D sine coefficients of :func:`~.segment.norms.sine_coefficients` (closed form per interval).
The series is truncated to m, n ≤ n_max and extrapolated in n_max (Richardson): the tail of the
square m, n ≤ n_max behaves like C n_max^{−p}, p = 2 when a basis function has a jump or
a nonzero value on ∂Γ (1D coefficients ~ 1/m), p = 4 for continuous spaces vanishing on ∂Γ
(coefficients ~ 1/m²) — the exponents :func:`tail_exponent` measures (T3: 4, R5.2: 2).
"""
from __future__ import annotations

from functools import cached_property

import numpy as np

from ....errors import InputError
from ....la.threaded import symmetric_pairs
from ....la import face_parity
from . import parity_bases
from ....la.exponential_sum import inverse_sqrt
from ...segment.norms import N_MAX_CAP, gram_by_norm, gram_l2, sine_coefficients
from ....la.richardson import BlockOps, _norm2, extrapolate

#: Rows of the weight matrix W[m, n] = 1/(π√(m² + n²)) handled at once (memory ~ chunk · n_max).
_CHUNK = 512
LONG_SERIES_MIN_DIM = 1500
"""dim above which the series' levels are those of a long series (:func:`start_level`,
:func:`default_cap`): chosen when the exponential sum (:mod:`infsup_contact.la.exponential_sum`)
was the route above this size only, where a level costs about the same at every n; kept so that
every space keeps its Richardson levels, hence its n_max and its stated error, now that the
exponential sum is the route at every size (:func:`partial_gram`)."""
EXP_SUM_START = 4
"""Factor of the first level on the exponential-sum route for a slow tail (:func:`start_level`):
there a level costs about the same at every n (its product has dim² · r terms, n-independent),
and the p = 2 spaces stopped at n_max ≥ 16 n0 at N = 32, k = 2 but R5.2 (8 n0: one level more
there); the levels n0 and 2 n0 were cost without a use."""
TAYLOR_BELOW = 1.0
"""Exponential terms with a_j x_max ≤ this are taken as one Taylor block (:func:`_separable_sum`)."""
TAYLOR_DEGREE = 17
"""Degree per variable of that block: remainder ≤ e^τ τ^{p+1}/(p + 1)! = 4e-16 relative at τ = 1
in each of the two factors e^{−b t}, e^{−b u}."""
EXP_SUM_RTOL = 1e-13
"""Relative accuracy of the exponential sum's weights: every eigenvalue of a pencil with the Gram
moves by at most this factor (Loewner order), far below the series' own ``rtol``."""


def gram_l2_face(space) -> np.ndarray:
    """Exact L²(Γ) Gram matrix G_x ⊗ G_y of a tensor space (index a·dim M^y + b)."""
    sx, sy = space.factors
    return np.kron(gram_l2(sx), gram_l2(sy))


def partial_gram(space, n_max: int, aspect: float = 1.0, direct: bool = False) -> np.ndarray:
    """S(n_max) = Σ_{m,n ≤ n_max} c_mn c_mnᵀ / (π√(m² + n²)), c_mn = c^x_m ⊗ c^y_n.

    ``aspect`` = a ≠ 1: the space lives on the rectangle (0, a) × (0, 1), given by its pull-back
    μ̃(s, y) = μ(a s, y) on the unit square. The Dirichlet Laplacian of the rectangle has the
    L²-orthonormal eigenfunctions (2/√a) sin(mπx/a) sin(nπy), eigenvalues π²((m/a)² + n²), and
    the coefficient of μ is √a μ̃_mn, so the weight is a / (π√((m/a)² + n²)).

    With A[(a, a'), m] = c^x_{a,m} c^x_{a',m} and B[(b, b'), n] = c^y_{b,n} c^y_{b',n},
    S[(a, b), (a', b')] = (A W Bᵀ)[(a, a'), (b, b')]. The route of every size: W as an exponential
    sum (:func:`_separable_sum`, n_max · r (dim M^x² + dim M^y²) + r (dim M)² operations, r ≈ 90
    columns after the Taylor block), within a relative :data:`EXP_SUM_RTOL` of the direct sum in
    the Loewner order. ``direct``: the reference route, W formed in row blocks and summed
    (n_max² · (dim M^y)² + n_max · (dim M^x dim M^y)² operations; the route below dim 1,500
    before, kept for the tests that compare the two)."""
    sx, sy = space.factors
    n = np.arange(1, n_max + 1, dtype=float)
    cx, cy = sine_coefficients(sx, n), sine_coefficients(sy, n)
    dx, dy = cx.shape[0], cy.shape[0]
    A = (cx[:, None, :] * cx[None, :, :]).reshape(dx * dx, n_max)
    B = (cy[:, None, :] * cy[None, :, :]).reshape(dy * dy, n_max)
    if not direct:
        flat = _separable_sum(A, B, n, n, aspect)
    else:
        flat = np.zeros((dx * dx, dy * dy))
        n2 = n ** 2
        for start in range(0, n_max, _CHUNK):
            W = _weights(n[start:start + _CHUNK], n2, aspect)
            flat += A[:, start:start + _CHUNK] @ (W @ B.T)
    return symmetric_pairs(flat, dx, dy)


def _weights(m: np.ndarray, n2: np.ndarray, aspect: float) -> np.ndarray:
    """W[m, n] = a / (π√((m/a)² + n²)) for the rows ``m`` (``n2`` = n²), evaluated in place: the
    operations of the formula in its order (the same values, bit for bit), without its three
    temporaries of W's size — at the slow tails' n_max (thousands) forming W is most of a level."""
    W = np.add.outer((m / aspect) ** 2, n2)
    np.sqrt(W, out=W)
    np.multiply(np.pi, W, out=W)
    return np.divide(aspect, W, out=W)


def _separable_sum(A: np.ndarray, B: np.ndarray, m: np.ndarray, n: np.ndarray, aspect: float) -> np.ndarray:
    """A W Bᵀ for W[m, n] = a / (π√((m/a)² + n²)) (A's columns at the indices ``m``, B's at ``n``),
    W as the exponential sum of :class:`SeparableWeights` on the range of (m/a)² + n²:
    (A E_x) D (B E_y)ᵀ, never forming W (B E_y is A E_x itself when the two directions are the
    same: one product of dim² · n_max · r fewer)."""
    x_lo, x_hi = (m[0] / aspect) ** 2 + n[0] ** 2, (m[-1] / aspect) ** 2 + n[-1] ** 2
    weights = SeparableWeights(x_lo, x_hi, aspect)
    left = weights.columns(A, (m / aspect) ** 2)
    same = aspect == 1.0 and np.array_equal(m, n) and (B is A or np.array_equal(A, B))
    right = left if same else weights.columns(B, n ** 2)
    return weights.scaled(left) @ right.T


class SeparableWeights:
    """W[m, n] = a / (π√(x)), x = (m/a)² + n² in [x_lo, x_hi] (either order), written as
    Σ_j w_j e^{−a_j (m/a)²} e^{−a_j n²} (:func:`~infsup_contact.la.exponential_sum.inverse_sqrt`,
    relative accuracy :data:`EXP_SUM_RTOL`): W = E_x D E_yᵀ, so M_x W M_yᵀ =
    :meth:`scaled` (:meth:`columns` (M_x)) · :meth:`columns` (M_y)ᵀ. One instance serves every
    product whose x lies in its range (the four parity blocks of a level,
    :func:`~infsup_contact.la.face_parity.parity_blocks`: each direction's columns once).

    Most terms have a_j x_max ≤ :data:`TAYLOR_BELOW`: there e^{−b_j (t + u)}, b_j = a_j x_max,
    t = (m/a)²/x_max, u = n²/x_max ∈ [0, 1], is its double Taylor polynomial of degree
    :data:`TAYLOR_DEGREE` per variable to round-off, so those terms together are T_x C T_yᵀ with
    T[m, q] = t_m^q and one (p + 1)² matrix C = Σ_j w_j v_j v_jᵀ, v_j[q] = (−b_j)^q / q!: about
    200 of the ~270 columns become 18."""

    def __init__(self, x_lo: float, x_hi: float, aspect: float = 1.0):
        self.x_max = max(x_lo, x_hi)
        expo = inverse_sqrt(min(x_lo, x_hi), self.x_max, EXP_SUM_RTOL)
        weights = aspect * expo.weights / np.pi
        taylor = expo.rates * self.x_max <= TAYLOR_BELOW
        self.q = np.arange(TAYLOR_DEGREE + 1)
        v = (-(expo.rates[taylor] * self.x_max)[:, None]) ** self.q / np.cumprod(np.maximum(self.q, 1))
        self.C = (v * weights[taylor, None]).T @ v
        self.rates, self.weights = expo.rates[~taylor], weights[~taylor]

    def columns(self, M: np.ndarray, squares: np.ndarray) -> np.ndarray:
        """[M e^{−a_j x}, M T] for one direction (x = ``squares``, M's columns at them)."""
        return np.hstack([M @ np.exp(-np.multiply.outer(squares, self.rates)),
                          M @ (squares / self.x_max)[:, None] ** self.q])

    def scaled(self, left: np.ndarray) -> np.ndarray:
        """:meth:`columns` times the weights: [L_e diag(w_j), L_T C]."""
        k = len(self.rates)
        return np.hstack([left[:, :k] * self.weights, left[:, k:] @ self.C])


def default_cap(dim: int) -> int:
    """Largest n_max of a face series summed in ``dim`` dimensions: :data:`~.segment.norms.N_MAX_CAP` on the
    long series (above :data:`LONG_SERIES_MIN_DIM`), where a level costs about the same at
    every n (at k = 2, N = 32, R5.2, DUAL-ALL and TDUAL-Q9 stopped at the former cap 8,192 with a
    stated error of 1.5e-5 to 3.2e-5; one level more, 12,288, states 6e-8 to 9e-8); an eighth of
    it on the direct sums, whose levels cost n_max²."""
    return N_MAX_CAP if dim > LONG_SERIES_MIN_DIM else N_MAX_CAP // 8


def start_level(n0: int, p: float, dim: int) -> int:
    """The first n of the Richardson levels: n0, or :data:`EXP_SUM_START` n0 for a slow tail
    (p = 2) on the exponential-sum route (``dim`` = the dimension :func:`partial_gram` sums in,
    above :data:`LONG_SERIES_MIN_DIM`). The result is that of the levels from n0 whenever those
    would have stopped at n_max ≥ 16 · EXP_SUM_START · n0 (the two-stage extrapolation, its
    step and the step's look-ahead use the last five levels only)."""
    return EXP_SUM_START * n0 if p <= 2.0 and dim > LONG_SERIES_MIN_DIM else n0


def smooth_tail(space) -> bool:
    """Whether every basis function is continuous and vanishes on ∂Γ (tail exponent 4, else 2)."""
    return space.smooth_tail


def tail_exponent(space, n_max: int) -> float:
    """Measured p of the tail ‖S(∞) − S(n)‖ ~ C n^{−p}: log2 of the ratio of successive
    increments ‖S(2n) − S(n)‖ / ‖S(4n) − S(2n)‖ (spectral norms)."""
    s1, s2, s4 = (partial_gram(space, n) for n in (n_max, 2 * n_max, 4 * n_max))
    return float(np.log2(_norm2(s2 - s1) / _norm2(s4 - s2)))


def gram_h_face(space, rtol: float = 1e-6, n_start: int | None = None, n_cap: int | None = None,
                exponent: float | None = None, aspect: float = 1.0, reference: bool = False) -> tuple[np.ndarray, dict]:
    """Gram matrix of the M = H^{1/2}_00(Γ)' norm on the square (module docstring).

    Partial sums S(n) at n = n0, 2n0, 4n0, ... are extrapolated,
    R(n) = S(2n) + (S(2n) − S(n)) / (2^p − 1) and once more for n^{−(p+1)}, until the stated
    error is ≤ rtol: the last step in R's own metric with a one-level look-ahead, a bound on the
    relative change of every eigenvalue of a pencil with the Gram (:func:`~.richardson.extrapolate`).
    Each S(n) is the exponential-sum product (:func:`partial_gram`), in the four parity blocks of
    the axis reflections where both factors are symmetric (:func:`partial_gram_blocks`; the
    blocks go on in ``info["parity"]``, :class:`~infsup_contact.la.face_parity.ParityGram`).

    Parameters
    ----------
    space : FaceSpace
    rtol : float
        Target of the stated relative truncation error (in the Gram's metric).
    n_start : int, optional
        n0; default max(16, 2 (s + 1) N) with N the larger number of intervals per direction,
        times :data:`EXP_SUM_START` for a slow tail on the exponential-sum route (:func:`start_level`).
    n_cap : int, optional
        Largest n_max (``info["capped"]`` when the estimate is still above rtol there); default
        :func:`default_cap`.
    exponent : float, optional
        Tail exponent p; default 4 for continuous spaces vanishing on ∂Γ, else 2 (:func:`smooth_tail`).
    aspect : float
        Width a of the rectangle (0, a) × (0, 1) the pulled-back ``space`` stands for
        (:func:`partial_gram`); 1 for the square.
    reference : bool
        The reference route: the whole matrix by the direct sums (``partial_gram(direct=True)``),
        on the same levels (the tests compare the two).

    Returns
    -------
    G : ndarray (dim, dim)
    info : dict
        ``n_max``, ``nmax_rel_error``, ``capped``, ``n_start``, ``tail_exponent``; ``parity`` (the
        blocks) where they were summed in blocks.
    """
    if not rtol > 0:
        raise InputError("rtol", "a positive float", got=rtol)
    p = (4.0 if smooth_tail(space) else 2.0) if exponent is None else float(exponent)
    n_int = max(f.n_intervals for f in space.factors)
    n0 = (start_level(max(16, 2 * (space.degree + 1) * n_int), p, space.dim) if n_start is None
          else int(n_start))
    if not aspect > 0:
        raise InputError("aspect", "a positive float", got=aspect)
    n_cap = default_cap(space.dim) if n_cap is None else n_cap
    parities = parity_bases.tensor_parities(space) if aspect == 1.0 and not reference else None
    if parities is None:
        return extrapolated(lambda n: partial_gram(space, n, aspect, direct=reference), p, n0, n_cap, rtol)
    blocks, info = extrapolated(lambda n: partial_gram_blocks(space, n, parities), p, n0, n_cap, rtol,
                                ops=BlockOps)
    G, parity = face_parity.gram_of(face_parity.tensor_bases(parities), blocks)  # G deferred in a β_h request
    return G, dict(info, parity=parity)


def partial_gram_blocks(space, n_max: int, parities) -> list:
    """:func:`partial_gram` (exponential-sum route) in the four parity blocks of the axis
    reflections (:func:`.parity_bases.partial_gram_blocks`)."""
    return parity_bases.partial_gram_blocks(space, n_max, parities, SeparableWeights)


def extrapolated(partial, p: float, n0: int, n_cap: int, rtol: float, ops=None) -> tuple[np.ndarray, dict]:
    """The segment's Richardson loop (:func:`~.richardson.extrapolate`) on a face series, the tail
    exponent p recorded in ``info`` (also the route of the non-tensor and triangle spaces,
    :mod:`.face.norms.cellwise`, :mod:`.face.norms.triangles`; ``ops``: that of parity blocks)."""
    G, info = extrapolate(partial, p, n0, n_cap, rtol, ops)
    return G, dict(info, tail_exponent=p)


def gram(space, norm: str, **kwargs) -> tuple[np.ndarray, dict]:
    """Gram matrix of a tensor face space (its ``factors``) for ``norm`` ∈ {"H", "L2"} (``kwargs``
    go to :func:`gram_h_face`); spaces without factors: :mod:`.face.norms.cellwise`. The L² Gram
    of a space with both factors symmetric carries its parity blocks too (:func:`l2_parity`)."""
    parity = l2_parity(space) if norm == "L2" else None
    deferred = parity is not None and face_parity.deferring()  # a β_h request: G_x ⊗ G_y where read
    G, info = gram_by_norm(norm, lambda: KronParityGram(space, parity) if deferred else gram_l2_face(space),
                           lambda **kw: gram_h_face(space, **kw), **kwargs)
    return G, (info if parity is None else dict(info, parity=G if deferred else parity))


class KronParityGram(face_parity.ParityGram):
    """The L² Gram G_x ⊗ G_y of a tensor space in its parity blocks (:func:`l2_parity`), its dense
    matrix the Kronecker product made on first read (bit for bit :func:`gram_l2_face`), its
    diagonal that of the factors (each entry the same one product): inside
    :func:`~infsup_contact.la.face_parity.deferred_assembly` the kernel decision's scaling reads
    the diagonal only, the pencils the blocks (a β_h request at k = 2, N = 48 never forms the
    708 MB of each space's G)."""

    def __init__(self, space, parity):
        super().__init__(parity.bases, parity.blocks)
        self._factors = tuple(gram_l2(f) for f in space.factors)

    @cached_property
    def dense(self) -> np.ndarray:
        G = np.kron(*self._factors)
        G.setflags(write=False)
        return G

    def diagonal(self) -> np.ndarray:
        return np.kron(*(np.diag(g) for g in self._factors))


def l2_parity(space):
    """The L² Gram G_x ⊗ G_y in the four parity blocks of the axis reflections,
    (Q^x_pᵀ G_x Q^x_p) ⊗ (Q^y_qᵀ G_y Q^y_q) (a :class:`~infsup_contact.la.face_parity.ParityGram`,
    for the pencils' split without splitting G), or None (a factor not symmetric)."""
    parities = parity_bases.tensor_parities(space)
    if parities is None:
        return None
    gx, gy = (gram_l2(f) for f in space.factors)
    blocks = [np.kron(np.asarray(parities[0][c & 1].T @ gx @ parities[0][c & 1]),
                      np.asarray(parities[1][c >> 1].T @ gy @ parities[1][c >> 1])) for c in range(4)]
    return face_parity.ParityGram(face_parity.tensor_bases(parities), [0.5 * (B + B.T) for B in blocks])
