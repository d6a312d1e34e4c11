"""Tests of the truncation-free log-kernel Gram matrix of the H^{1/2}_00(Γ)-dual norm.

All references come from mathematics: the exact value for μ ≡ 1 and an independent
brute-force sine series ‖μ‖²_M = Σ μ_n²/(nπ) computed here.
"""
import numpy as np
import pytest
from scipy.special import zeta

from infsup_contact.errors import InputError
from infsup_contact.discretization.segment.logkernel import gram_h_logkernel, log_kernel
from infsup_contact.discretization.segment.multipliers import local_shapes, make_space
from infsup_contact.discretization.spaces.registry import PAPER_CASES, SPACES, case_space
from infsup_contact.discretization.segment.interface import SEGMENT

NONUNIFORM = np.array([0.0, 0.07, 0.21, 0.5, 0.56, 0.83, 1.0])
GRADED = np.array([0.0, 1e-3, 1e-2, 0.1, 0.3, 1.0])


# ---------------------------------------------------------------- independent reference
def _sine_coefficients(space, n_max):
    """B[n−1, i] = √2 ∫_Γ φ_i(x) sin(nπx) dx for n = 1..n_max.

    Per interval [a, a + h] with ω = nπh: 80-point Gauss–Legendre when ω ≤ 40 (the
    integrand is then resolved to machine precision), otherwise the exact integration
    by parts ∫_0^1 P(t) sin(ωt + φ) dt = Σ_k (−1)^k [P^(k)(t) sin(ωt + φ − (k+1)π/2)/ω^(k+1)]_0^1
    (no cancellation for large ω).
    """
    s = space.degree
    nodes = np.array([0.5]) if s == 0 else np.linspace(0.0, 1.0, s + 1)
    n = np.arange(1, n_max + 1, dtype=float)
    tg, wg = np.polynomial.legendre.leggauss(80)
    tg, wg = 0.5 * (tg + 1.0), 0.5 * wg
    shapes_g = local_shapes(s, tg)
    out = np.zeros((n_max, space.dim))
    for e in range(space.n_intervals):
        a, b = space.breakpoints[e], space.breakpoints[e + 1]
        h = b - a
        om, ph = n * np.pi * h, n * np.pi * a
        low = om <= 40.0
        for loc in range(s + 1):
            g = space.dofs[e, loc]
            if g < 0:
                continue
            others = np.delete(nodes, loc)
            poly = np.polynomial.Polynomial.fromroots(others) if s else np.polynomial.Polynomial([1.0])
            poly = poly / poly(nodes[loc])
            val = np.zeros(n_max)
            for k in range(s + 1):
                pk = poly.deriv(k)
                for t, sign in ((1.0, 1.0), (0.0, -1.0)):
                    val += sign * (-1) ** k * pk(t) * np.sin(om * t + ph - (k + 1) * np.pi / 2) / om ** (k + 1)
            val[low] = np.sin(np.outer(n[low], np.pi * (a + h * tg))) @ (wg * shapes_g[:, loc])
            out[:, g] += np.sqrt(2.0) * h * val
    return out


def _series_norm2(space, coeffs, n_max=20000):
    """Σ_n μ_n²/(nπ) up to n_max and n_max/2, Richardson-extrapolated (tail ~ n^-2)."""
    mu_n = _sine_coefficients(space, n_max) @ coeffs
    terms = mu_n ** 2 / (np.pi * np.arange(1, n_max + 1))
    s_half, s_full = terms[: n_max // 2].sum(), terms.sum()
    return (4.0 * s_full - s_half) / 3.0


def test_reference_sine_coefficients_against_plain_gauss():
    """The test's own sine coefficients agree with brute-force composite Gauss."""
    space = make_space(NONUNIFORM, 2, False, False)
    n_max = 300
    ref = _sine_coefficients(space, n_max)
    tg, wg = np.polynomial.legendre.leggauss(40)
    xs, ws = [], []  # composite Gauss, panels inside each interval (jumps at breakpoints)
    for a, b in zip(space.breakpoints[:-1], space.breakpoints[1:]):
        m = max(4, int(np.ceil(60 * (b - a))))
        edges = np.linspace(a, b, m + 1)
        xs.append((0.5 * (edges[1:] + edges[:-1])[:, None] + 0.5 * np.diff(edges)[:, None] * tg).ravel())
        ws.append((0.5 * np.diff(edges)[:, None] * wg).ravel())
    x, w = np.concatenate(xs), np.concatenate(ws)
    phi = space.evaluate(x)
    direct = np.sqrt(2.0) * np.sin(np.pi * np.outer(np.arange(1, n_max + 1), x)) @ (w[:, None] * phi)
    assert np.abs(direct - ref).max() < 1e-13


# ---------------------------------------------------------------- exact constant
@pytest.mark.parametrize("breakpoints", [np.linspace(0, 1, 4), NONUNIFORM, GRADED])
@pytest.mark.parametrize("degree, continuous", [(0, False), (1, False), (2, True), (3, True)])
def test_constant_function_exact(breakpoints, degree, continuous):
    """μ ≡ 1: ‖1‖²_M = Σ_{n odd} 8/(n³π³) = 7ζ(3)/π³ (Lagrange shapes sum to 1)."""
    space = make_space(breakpoints, degree, continuous, False)
    g = gram_h_logkernel(space)
    one = np.ones(space.dim)
    exact = 7.0 * zeta(3) / np.pi ** 3
    assert abs(one @ g @ one / exact - 1.0) < 1e-10


# ---------------------------------------------------------------- sine-series reference
SERIES_SPACES = {
    "P0 disc uniform": lambda: make_space(np.linspace(0, 1, 5), 0, False, False),
    "P0 disc nonuniform": lambda: make_space(NONUNIFORM, 0, False, False),
    "P1 disc nonuniform": lambda: make_space(NONUNIFORM, 1, False, False),
    "P2 disc graded": lambda: make_space(GRADED, 2, False, False),
    "P1 cont (R5.2 k=1)": lambda: case_space("R5.2", 1, NONUNIFORM, SEGMENT),
    "P2 cont (R5.2 k=2)": lambda: case_space("R5.2", 2, np.linspace(0, 1, 4), SEGMENT),
    "T3 k=1 nonuniform": lambda: case_space("T3", 1, NONUNIFORM, SEGMENT),
    "T3 k=2 nonuniform": lambda: case_space("T3", 2, NONUNIFORM, SEGMENT),
    "T3 k=3 uniform": lambda: case_space("T3", 3, np.linspace(0, 1, 4), SEGMENT),
    "P3 disc one interval": lambda: make_space([0.0, 1.0], 3, False, False),
}


@pytest.mark.parametrize("name", list(SERIES_SPACES))
def test_agrees_with_sine_series(name):
    """μᵀGμ equals the brute-force Σ μ_n²/(nπ) for random (seeded) μ, to 1e-9 relative."""
    space = SERIES_SPACES[name]()
    g = gram_h_logkernel(space)
    rng = np.random.default_rng(20010167)
    for _ in range(3):
        mu = rng.standard_normal(space.dim)
        ref = _series_norm2(space, mu)
        assert abs(mu @ g @ mu - ref) <= 1e-9 * ref


# ---------------------------------------------------------------- structure
CASE_GRID = [(c, k, n) for c in PAPER_CASES for k in (1, 2, 3) for n in (3, 4, 7) if k >= SPACES[c].min_k]


@pytest.mark.parametrize("case, k, n", CASE_GRID)
def test_symmetric_positive_definite(case, k, n):
    rng = np.random.default_rng(n)
    for bp in (np.linspace(0, 1, n + 1), np.r_[0.0, np.sort(rng.uniform(0.05, 0.95, n - 1)), 1.0]):
        space = case_space(case, k, bp, SEGMENT)
        g = gram_h_logkernel(space)
        assert g.shape == (space.dim, space.dim)
        assert np.array_equal(g, g.T)
        np.linalg.cholesky(g)  # raises unless positive definite
        assert np.linalg.eigvalsh(g).min() > 0.0


@pytest.mark.parametrize("space", [
    make_space(np.linspace(0, 1, 8), 0, False, False),
    make_space(NONUNIFORM, 1, False, False),
    make_space(GRADED, 3, False, False),
    case_space("T3", 2, np.linspace(0, 1, 33), SEGMENT),
    make_space(np.r_[0.0, np.sort(np.random.default_rng(1).random(40)), 1.0], 2, True, False),
], ids=["P0x7", "P1 nonuniform", "P3 graded", "T3 k=2 N=32", "P2 cont random N=41"])
def test_quadrature_converged(space):
    """Doubling every quadrature order changes G by < 1e-11 relative."""
    g1 = gram_h_logkernel(space)
    g2 = gram_h_logkernel(space, quad_scale=2)
    assert np.abs(g2 - g1).max() < 1e-11 * np.abs(g1).max()


def test_mesh_refinement_invariance():
    """Embedding: a space on a refined partition contains the coarse one; norms agree."""
    coarse = make_space(NONUNIFORM, 2, True, False)
    fine_bp = np.sort(np.r_[NONUNIFORM, 0.5 * (NONUNIFORM[1:] + NONUNIFORM[:-1])])
    fine = make_space(fine_bp, 2, True, False)
    mu = np.random.default_rng(5).standard_normal(coarse.dim)
    mu_fine = coarse.evaluate(fine.nodes()) @ mu  # exact interpolation of a coarse P2 function
    v_c = mu @ gram_h_logkernel(coarse) @ mu
    v_f = mu_fine @ gram_h_logkernel(fine) @ mu_fine
    assert abs(v_c - v_f) < 1e-12 * v_c


def test_kernel_symmetry_and_sign():
    rng = np.random.default_rng(0)
    x, y = rng.random(200), rng.random(200)
    k = log_kernel(x, y)
    assert np.allclose(k, log_kernel(y, x), rtol=1e-14, atol=0)
    assert np.all(k > 0)
    assert np.allclose(k, log_kernel(1 - x, 1 - y), rtol=1e-12, atol=1e-14)


def test_empty_space():
    # the Gram matrix of an empty space is empty; the registry refuses to build one for a case
    assert gram_h_logkernel(make_space([0.0, 1.0], 1, True, True)).shape == (0, 0)
    with pytest.raises(InputError, match="T3"):
        case_space("T3", 1, [0.0, 1.0], SEGMENT)


@pytest.mark.parametrize("kwargs", [{"quad_scale": 0}, {"quad_scale": 1.5}, {"quad_scale": True}])
def test_bad_quad_scale(kwargs):
    with pytest.raises(InputError):
        gram_h_logkernel(make_space([0.0, 1.0], 1, False, False), **kwargs)


def test_bad_inputs():
    with pytest.raises(InputError):
        gram_h_logkernel("not a space")
    with pytest.raises(InputError):
        gram_h_logkernel(make_space([0.0, 0.5, 2.0], 1, True, False))


def test_subspace_gram_is_a_submatrix():
    """T3 = R5.2 without its two end functions: its Gram matrix is R5.2's with those rows and
    columns struck out (the element integrals are shared between the two, so this also checks
    that one space's integrals are not handed to the other wrongly)."""
    bp = np.r_[0.0, np.sort(np.random.default_rng(3).uniform(0.02, 0.98, 9)), 1.0]
    for k in (1, 2, 3):
        full, inner = case_space("R5.2", k, bp, SEGMENT), case_space("T3", k, bp, SEGMENT)
        g_full, g_inner = gram_h_logkernel(full), gram_h_logkernel(inner)
        x_full, x_inner = full.nodes(), inner.nodes()
        keep = [int(np.argmin(np.abs(x_full - x))) for x in x_inner]
        assert np.allclose(g_full[np.ix_(keep, keep)], g_inner, rtol=0, atol=1e-15 * np.abs(g_full).max())


def test_gram_depends_on_the_partition():
    """Two partitions asked for in turn get their own matrices (no stale reuse)."""
    a, b = np.linspace(0, 1, 6), np.linspace(0, 1, 6) ** 1.5
    ga1 = gram_h_logkernel(make_space(a, 1, True, True))
    gb = gram_h_logkernel(make_space(b, 1, True, True))
    ga2 = gram_h_logkernel(make_space(a, 1, True, True))
    assert np.array_equal(ga1, ga2) and not np.allclose(ga1, gb)
