"""Multiplier spaces on the face (tensor products of the registry's 1D spaces) and their Gram
matrices: L² against quadrature of the basis, the H^{-1/2}_00 series against its bound and
itself as n_max grows, and the measured tail exponents of its Richardson extrapolation."""
import numpy as np
import pytest

from infsup_contact.discretization.face.norms import tensor as face_norms
from infsup_contact.la.richardson import relative_step
from infsup_contact.discretization.spaces.registry import case_space, space_spec
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition

CASES = [("T3", 1), ("T3", 2), ("R5.2", 1), ("R5.2", 2), ("T4", 2), ("R5.4", 1), ("R5.4", 2), ("T5", 2),
         ("DUAL", 2), ("DUAL-ALL", 1)]
P = TensorPartition(np.array([0.0, 0.3, 0.55, 1.0]), np.array([0.0, 0.25, 0.5, 0.75, 1.0]))


@pytest.mark.parametrize("case,k", CASES)
def test_face_space_is_the_tensor_product_of_the_1d_space(case, k):
    space = case_space(case, k, P, SQUARE)
    sx, sy = space.factors
    spec = space_spec(case)
    assert sx.dim == spec.build(k, P.xs).dim and sy.dim == spec.build(k, P.ys).dim
    assert space.dim == sx.dim * sy.dim and space.breakpoints is P and space.degree == spec.degree(k)
    x = np.random.default_rng(0).uniform(size=(50, 2))
    ex, ey = sx.evaluate(x[:, 0]), sy.evaluate(x[:, 1])
    np.testing.assert_allclose(space.evaluate(x), np.einsum("na,nb->nab", ex, ey).reshape(50, -1), rtol=0,
                               atol=1e-15)


@pytest.mark.parametrize("case,k", CASES)
def test_l2_gram_is_the_integral_of_the_basis_products(case, k):
    space = case_space(case, k, P, SQUARE)
    G, info = SQUARE.gram(space, "L2")
    x, w = SQUARE.quadrature(P, 2 * space.degree)
    phi = space.evaluate(x)
    np.testing.assert_allclose(G, (phi * w[:, None]).T @ phi, rtol=0, atol=1e-14)
    assert info == {"n_max": 0, "nmax_rel_error": 0.0}


@pytest.mark.parametrize("case,k", CASES)
def test_h_gram_is_spd_below_the_l2_bound_and_converged(case, k):
    """‖μ‖²_M = Σ μ_mn²/(π√(m²+n²)) ≤ Σ μ_mn²/(π√2) = ‖μ‖²_L²/(π√2), since m, n ≥ 1."""
    space = case_space(case, k, P, SQUARE)
    G, info = SQUARE.gram(space, "H")
    L2 = SQUARE.gram(space, "L2")[0]
    np.testing.assert_allclose(G, G.T, rtol=0, atol=1e-15 * np.abs(G).max())
    assert np.linalg.eigvalsh(G).min() > 0
    assert np.linalg.eigvalsh(L2 / (np.pi * np.sqrt(2)) - G).min() > -1e-6 * np.abs(G).max()
    assert info["nmax_rel_error"] <= 1e-6 and not info["capped"]
    tight, info2 = face_norms.gram_h_face(space, rtol=1e-8, n_cap=2 ** 15)
    assert info2["n_max"] >= info["n_max"] and info2["nmax_rel_error"] <= 1e-8 and not info2["capped"]
    # the stated error bounds the real one in the Gram's own metric (−ε G ≤ G − G* ≤ ε G), the
    # one that bounds every eigenvalue of a pencil with G, not only against ‖G‖₂
    assert relative_step(G - tight, tight) <= info["nmax_rel_error"] + info2["nmax_rel_error"]


@pytest.mark.parametrize("case,k,smooth", [("T3", 2, True), ("T3", 1, True), ("R5.2", 2, False),
                                           ("R5.4", 1, False), ("T5", 2, False)])
def test_measured_tail_exponent_is_the_one_used(case, k, smooth):
    """Coefficients ~ 1/m² (continuous, zero on ∂Γ) give a tail ~ n^{-4}, ~ 1/m (jumps or
    boundary values) ~ n^{-2}: the exponent the extrapolation uses, measured."""
    space = case_space(case, k, P, SQUARE)
    assert face_norms.smooth_tail(space) is smooth
    used = face_norms.gram_h_face(space)[1]["tail_exponent"]
    assert face_norms.tail_exponent(space, 256) == pytest.approx(used, abs=0.05)


@pytest.mark.parametrize("case,k", [("T3", 2), ("R5.4", 1), ("T5", 2)])
def test_partial_sum_is_the_double_sine_series_of_the_basis(case, k):
    """S(n) against μ_mn = 2 ∬ μ sin(mπx) sin(nπy) by a 2D Gauss rule (exact up to round-off for
    these low modes), summed directly: checks the Kronecker indexing of the fast contraction."""
    space = case_space(case, k, P, SQUARE)
    n_max = 12
    x, w = SQUARE.quadrature(SQUARE.common_refinement(P, TensorPartition(*[np.linspace(0, 1, 9)] * 2)), 30)
    phi = space.evaluate(x) * w[:, None]
    m = np.arange(1, n_max + 1)
    sx, sy = np.sin(np.pi * np.outer(x[:, 0], m)), np.sin(np.pi * np.outer(x[:, 1], m))
    G = np.zeros((space.dim, space.dim))
    for a in range(n_max):
        for b in range(n_max):
            mu = 2 * phi.T @ (sx[:, a] * sy[:, b])
            G += np.outer(mu, mu) / (np.pi * np.hypot(a + 1, b + 1))
    np.testing.assert_allclose(face_norms.partial_gram(space, n_max), G, rtol=0, atol=1e-10 * np.abs(G).max())


def test_norm2_above_the_short_krylov_gate_agrees_with_lapack():
    """The spectral norm of the Richardson loop above NORM2_SHORT_KRYLOV_MIN (Lanczos with 10
    vectors) equals the largest |eigenvalue| from LAPACK to the 1e-8 asked, for a Gram-like
    matrix (dominant top) and for an indefinite difference of two."""
    from infsup_contact.la import richardson
    n = richardson.NORM2_SHORT_KRYLOV_MIN + 100
    rng = np.random.default_rng(3)
    X = rng.standard_normal((n, n)) / n
    for A in (X @ X.T + np.diag(np.linspace(0, 1, n)), (X + X.T) - np.diag(np.linspace(-2, 1, n))):
        exact = np.max(np.abs(np.linalg.eigvalsh(A)))
        assert abs(richardson._norm2(A) / exact - 1) < 1e-8


@pytest.mark.parametrize("aspect", [1.0, 0.37, 0.05])
def test_in_place_weights_are_the_formula_bit_for_bit(aspect):
    """W[m, n] = a / (π√((m/a)² + n²)) formed in place equals the formula evaluated plainly."""
    from infsup_contact.discretization.face.norms.tensor import _weights

    n = np.arange(1, 1201, dtype=float)
    m = n[512:1024]
    plain = aspect / (np.pi * np.sqrt((m[:, None] / aspect) ** 2 + n[None, :] ** 2))
    assert np.array_equal(_weights(m, n ** 2, aspect), plain)
