"""Tests of the L² and M = H^{1/2}_00(Γ)' Gram matrices, checked against mathematics.

The reference values of ‖μ‖²_M = Σ μ_n²/(nπ) are computed independently of the module:
μ_n by dense composite Gauss quadrature of ``space.evaluate`` (or scipy's QAWO rule), the
tail n > n_ref from the leading asymptotic term of μ_n (jumps of μ, endpoint values
counted as jumps), whose remaining error is O(n_ref^{-3}).
"""
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import zeta

from infsup_contact.errors import InputError
from infsup_contact.discretization.segment.multipliers import make_space
from infsup_contact.discretization.spaces.registry import PAPER_CASES, SPACES, case_space
from infsup_contact.discretization.segment.norms import gram, gram_h, gram_l2, sine_coefficients
from infsup_contact.discretization.segment.interface import SEGMENT

UNIFORM7 = np.linspace(0.0, 1.0, 8)
NONUNIFORM5 = np.array([0.0, 0.07, 0.3, 0.35, 0.8, 1.0])


def _function(space, c):
    """μ = Σ c_j φ_j as a callable."""
    return lambda x: space.evaluate(np.atleast_1d(np.asarray(x, dtype=float))) @ c


def _composite_gauss(space, per_unit, q=20):
    """q-point Gauss on equal sub-intervals of every interval, ~per_unit of them per unit length."""
    t, w = np.polynomial.legendre.leggauss(q)
    t, w = 0.5 * (t + 1), 0.5 * w
    xs, ws = [], []
    for a, b in zip(space.breakpoints[:-1], space.breakpoints[1:]):
        edges = np.linspace(a, b, max(1, int(np.ceil((b - a) * per_unit))) + 1)
        width = np.diff(edges)
        xs.append((edges[:-1, None] + width[:, None] * t[None, :]).ravel())
        ws.append((width[:, None] * w[None, :]).ravel())
    return np.concatenate(xs), np.concatenate(ws)


def _reference_norm2(space, c, n_ref=2000, n_tail=1_000_000):
    """Σ_n μ_n²/(nπ) for μ = Σ c_j φ_j, independent of the module's sine coefficients."""
    # μ_n for n ≤ n_ref: sub-intervals of ≤ 1 wavelength (2/n_ref), 20 Gauss points each.
    x, w = _composite_gauss(space, per_unit=n_ref / 2)
    mu_w = (space.evaluate(x) @ c) * w
    head = 0.0
    for start in range(1, n_ref + 1, 250):
        n = np.arange(start, min(start + 250, n_ref + 1), dtype=float)
        mu_n = np.sqrt(2) * np.sin(np.pi * np.outer(n, x)) @ mu_w
        head += np.sum(mu_n**2 / (np.pi * n))
    # Tail: ∫ μ sin(ωx) = (1/ω) Σ_k J_k cos(ωx_k) + O(ω^{-2}), J_k the jump of μ at x_k
    # (μ(0+) at x = 0, −μ(1−) at x = 1). Summed explicitly to n_tail, then ~ n_tail^{-2}.
    xb = space.breakpoints
    eps = 1e-13
    right = _function(space, c)(np.minimum(xb + eps, 1.0))
    left = _function(space, c)(np.maximum(xb - eps, 0.0))
    jumps = right - left
    jumps[0], jumps[-1] = right[0], -left[-1]
    tail = 0.0
    for start in range(n_ref + 1, n_tail + 1, 200_000):
        m = np.arange(start, min(start + 200_000, n_tail + 1), dtype=float)
        lead = np.sqrt(2) * (np.cos(np.pi * np.outer(m, xb)) @ jumps) / (np.pi * m)
        tail += np.sum(lead**2 / (np.pi * m))
    tail += np.sum(np.abs(jumps)) ** 2 / (np.pi**3 * n_tail**2)   # bound on the rest
    return head + tail


# ------------------------------------------------------------------------------ L²
@pytest.mark.parametrize("continuous", [True, False])
@pytest.mark.parametrize("s", [2, 3])
def test_gram_l2_integrates_x_squared(s, continuous):
    space = make_space(NONUNIFORM5, s, continuous, False)
    c = space.nodes() ** 2                       # Lagrange interpolant of x², exact for s ≥ 2
    assert c @ gram_l2(space) @ c == pytest.approx(1 / 5, rel=1e-13)


def test_gram_l2_constant_p0():
    space = make_space(NONUNIFORM5, 0, False, False)
    c = np.ones(space.dim)
    assert c @ gram_l2(space) @ c == pytest.approx(1.0, rel=1e-14)


def test_gram_l2_matches_dense_quadrature():
    space = case_space("T3", 3, NONUNIFORM5, SEGMENT)
    x, w = _composite_gauss(space, per_unit=10)
    V = space.evaluate(x)
    np.testing.assert_allclose(gram_l2(space), (V * w[:, None]).T @ V, atol=1e-14)


# --------------------------------------------------------------- sine coefficients
def test_sine_coefficients_of_one():
    """μ ≡ 1: μ_n = 2√2/(nπ) for odd n, 0 for even n."""
    space = make_space(NONUNIFORM5, 0, False, False)
    n = np.arange(1, 3001)
    mu_n = np.ones(space.dim) @ sine_coefficients(space, n)
    exact = np.where(n % 2 == 1, 2 * np.sqrt(2) / (n * np.pi), 0.0)
    np.testing.assert_allclose(mu_n, exact, rtol=0, atol=1e-13)


@pytest.mark.parametrize("case,k", [("R5.2", 2), ("R5.4", 2), ("T3", 3)])
def test_sine_coefficients_match_qawo(case, k):
    """Per basis function and interval against scipy's QAWO (weight='sin') rule."""
    space = case_space(case, k, NONUNIFORM5, SEGMENT)
    n = np.array([1, 2, 5, 40, 333, 4001])
    phi = sine_coefficients(space, n)
    rng = np.random.default_rng(1)
    for j in rng.choice(space.dim, size=3, replace=False):
        e = np.zeros(space.dim)
        e[j] = 1.0
        f = _function(space, e)
        for col, nn in enumerate(n):
            ref = sum(quad(lambda x: f(x)[0], a, b, weight="sin", wvar=nn * np.pi)[0]
                      for a, b in zip(space.breakpoints[:-1], space.breakpoints[1:]))
            assert phi[j, col] == pytest.approx(np.sqrt(2) * ref, abs=1e-12)


@pytest.mark.parametrize("s", [0, 1, 2, 3])
def test_ibp_and_gauss_branches_agree_at_moderate_omega(s):
    # Ω = nπh ∈ [2, 8] on every interval: both formulas are accurate there.
    space = make_space(np.linspace(0.0, 1.0, 11), s, s > 0, False)
    h = 0.1
    n = np.arange(int(np.ceil(2 / (np.pi * h))), int(8 / (np.pi * h)) + 1)
    ibp = sine_coefficients(space, n, switch=0.0)
    gauss = sine_coefficients(space, n, switch=np.inf)
    np.testing.assert_allclose(ibp, gauss, rtol=0, atol=1e-13)


def test_gauss_branch_used_for_small_omega():
    """At tiny Ω integration by parts cancels; the default must match pure Gauss there."""
    space = make_space(np.linspace(0.0, 1.0, 201), 3, True, False)   # h = 0.005
    n = np.arange(1, 6)                                              # Ω ≤ 0.08
    np.testing.assert_allclose(sine_coefficients(space, n),
                               sine_coefficients(space, n, switch=np.inf), rtol=0, atol=1e-16)


# ---------------------------------------------------------------------------- M
def test_norm_of_constant_is_7zeta3_over_pi3():
    """‖1‖²_M = Σ_{n odd} 8/(nπ)³ = 7ζ(3)/π³."""
    space = make_space(NONUNIFORM5, 0, False, False)
    G, info = gram_h(space)
    c = np.ones(space.dim)
    assert c @ G @ c == pytest.approx(7 * zeta(3) / np.pi**3, rel=1e-6)
    assert not info["capped"]


@pytest.mark.parametrize("s,continuous,vanish", [
    (0, False, False),   # jumps
    (1, False, False),   # jumps, nonzero endpoint values
    (1, True, False),    # continuous, nonzero endpoint values
    (2, True, False),
    (2, True, True),     # continuous, vanishing at the ends: fast decay
])
@pytest.mark.parametrize("breakpoints", [UNIFORM7, NONUNIFORM5], ids=["uniform", "nonuniform"])
def test_gram_h_matches_independent_series(s, continuous, vanish, breakpoints):
    space = make_space(breakpoints, s, continuous, vanish)
    G, info = gram_h(space)
    rng = np.random.default_rng(12345)
    for _ in range(2):
        c = rng.standard_normal(space.dim)
        assert c @ G @ c == pytest.approx(_reference_norm2(space, c), rel=1e-5)


@pytest.mark.parametrize("case", list(PAPER_CASES))
@pytest.mark.parametrize("k", [1, 2, 3])
@pytest.mark.parametrize("breakpoints", [
    np.linspace(0, 1, 4), np.linspace(0, 1, 5), UNIFORM7,
    np.array([0.0, 0.1, 0.45, 1.0]), np.array([0.0, 0.02, 0.3, 0.31, 1.0]),
    np.array([0.0, 0.05, 0.1, 0.2, 0.4, 0.6, 0.95, 1.0]),
], ids=["N3", "N4", "N7", "N3-nonuni", "N4-nonuni", "N7-nonuni"])
def test_gram_matrices_symmetric_positive_definite(case, k, breakpoints):
    if k < SPACES[case].min_k:
        pytest.skip(f"{case} needs k >= {SPACES[case].min_k}")
    space = case_space(case, k, breakpoints, SEGMENT)
    for norm in ("H", "L2"):
        G, info = gram(space, norm)
        assert G.shape == (space.dim, space.dim)
        np.testing.assert_allclose(G, G.T, rtol=0, atol=1e-15 * np.abs(G).max())
        assert np.linalg.eigvalsh(G).min() > 0
        assert isinstance(info["n_max"], int) and isinstance(info["nmax_rel_error"], float)
    assert info == {"n_max": 0, "nmax_rel_error": 0.0}       # the L² call


@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8])
def test_truncation_reported_and_honest(rtol):
    space = make_space(NONUNIFORM5, 1, False, False)
    G, info = gram_h(space, rtol=rtol)
    assert not info["capped"]
    assert info["n_max"] >= info["n_start"] and info["nmax_rel_error"] <= rtol
    G_ref, _ = gram_h(space, rtol=1e-11)
    actual = np.linalg.norm(G - G_ref, 2) / np.linalg.norm(G_ref, 2)
    assert actual <= max(info["nmax_rel_error"], 1e-11)


def test_cap_is_reported_honestly():
    space = make_space(UNIFORM7, 1, False, False)
    G, info = gram_h(space, rtol=1e-10, n_cap=64)
    assert info["capped"] and info["n_max"] <= 64 and info["nmax_rel_error"] > 1e-10
    G_ref, _ = gram_h(space, rtol=1e-10)
    actual = np.linalg.norm(G - G_ref, 2) / np.linalg.norm(G_ref, 2)
    assert actual <= info["nmax_rel_error"]


def test_gram_dispatch_and_errors():
    space = case_space("T3", 2, UNIFORM7, SEGMENT)
    np.testing.assert_array_equal(gram(space, "L2")[0], gram_l2(space))
    np.testing.assert_array_equal(gram(space, "H", h_route="series")[0], gram_h(space)[0])
    # the two H routes are independent (log kernel vs truncated sine series) and agree
    G_log, info = gram(space, "H")
    assert info["n_max"] == 0
    np.testing.assert_allclose(G_log, gram_h(space, rtol=1e-9)[0], rtol=0, atol=1e-8 * np.abs(G_log).max())
    with pytest.raises(InputError) as err:
        gram(space, "H", h_route="fourier")
    assert err.value.key == "h_route"
    with pytest.raises(InputError) as err:
        gram(space, "H1")
    assert err.value.key == "norm" and err.value.got == "H1"
    with pytest.raises(InputError):
        gram_h(space, rtol=0.0)
    with pytest.raises(InputError):
        sine_coefficients(space, np.array([[1, 2]]))
