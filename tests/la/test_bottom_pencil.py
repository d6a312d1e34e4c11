"""The large route's pencils (la/bottom.bottom_pencil, spectra.bottom_spectra, spectra.betas_v1_zero):
the blocked shift-invert operator against the plain one, the pencil against the dense eigh(S, G),
the factor shared between norms against unshared pencils, and β(v1 = 0) between the routes."""
import numpy as np
import pytest
import scipy.linalg as sla
from scipy.linalg import blas

from infsup_contact.la import mkl
from infsup_contact.la import bottom
from infsup_contact.solvers import spectra
from infsup_contact.solvers.kernel import coupling_kernel


def _spd(m, seed, cond=1e3):
    rng = np.random.default_rng(seed)
    Q = np.linalg.qr(rng.standard_normal((m, m)))[0]
    return Q @ np.diag(np.geomspace(1.0, cond, m)) @ Q.T


def _pencil(m, d, seed):
    """S = V diag(0 (d times), 0.1 … 10) Vᵀ, V orthogonal: an exact kernel of dimension d (its
    basis Z) and a conditioning above it at which eigh itself is accurate to ~1e-13; G SPD."""
    rng = np.random.default_rng(seed)
    V = np.linalg.qr(rng.standard_normal((m, m)))[0]
    S = V[:, d:] @ np.diag(np.geomspace(0.1, 10.0, m - d)) @ V[:, d:].T
    return (S + S.T) / 2, _spd(m, seed + 1, cond=10.0), V[:, :d]


@pytest.mark.parametrize("route", ["mkl", "scipy"])
@pytest.mark.parametrize("m,block", [(1, 512), (7, 3), (90, 16), (90, 512), (131, 32)])
def test_blocked_inverse_form_equals_the_plain_one(m, block, route, monkeypatch):
    """Kᵀ K by the column-blocked solve and lauum = dsyrk of the full solve R⁻¹ L, to round-off;
    blocks that do not divide m included; both routes (MKL in place on sub-blocks, scipy on copies)."""
    if route == "mkl" and not mkl.available():
        pytest.skip("MKL not loadable here")
    monkeypatch.setattr(mkl, "available", lambda: route == "mkl")
    monkeypatch.setattr(bottom, "SOLVE_BLOCK", block)
    monkeypatch.setattr(bottom, "SOLVE_BLOCK_MKL", block)
    R = np.tril(sla.cholesky(_spd(m, m), lower=True))
    L = np.tril(sla.cholesky(_spd(m, m + 1), lower=True))
    K = sla.solve_triangular(R, L, lower=True)
    assert np.array_equal(np.triu(K, 1), np.zeros((m, m)))  # lower triangular: what the blocks use
    plain = np.tril(blas.dsyrk(1.0, K, trans=1, lower=1))
    blocked = bottom.inverse_standard_form(R, L)
    assert blocked.flags.f_contiguous
    np.testing.assert_allclose(np.tril(blocked), plain, rtol=0, atol=1e-13 * np.abs(plain).max())
    # and the matrix it stands for: Lᵀ (R Rᵀ)⁻¹ L
    direct = L.T @ np.linalg.solve(R @ R.T, L)
    np.testing.assert_allclose(np.tril(blocked), np.tril(direct), rtol=0, atol=1e-10 * np.abs(direct).max())


@pytest.mark.parametrize("d", [0, 3, 25])
def test_pencil_equals_dense_eigh(d, monkeypatch):
    """The values above the kernel are those of scipy.linalg.eigh(S, G) to 1e-10 relative,
    λ_max to LAM_MAX_RTOL (the blocks small enough that there are several)."""
    monkeypatch.setattr(bottom, "SOLVE_BLOCK", 64)
    S, G, Z = _pencil(250, d, seed=10 + d)
    ev = sla.eigh(S, G, eigvals_only=True)
    res = bottom.bottom_pencil(S, sla.cholesky(G, lower=True), 4, Z if d else None)
    np.testing.assert_allclose(res.values, ev[d:d + 4], rtol=1e-10)
    assert abs(res.lam_max - ev[-1]) <= bottom.LAM_MAX_RTOL * ev[-1]


def test_shared_factor_changes_no_bit():
    """Two Gram matrices, no kernel: bottom_spectra (one Cholesky factor of S for both norms)
    gives bit for bit the spectra of the unshared calls, and those equal the dense route."""
    S, _, _ = _pencil(200, 0, seed=4)
    factors = {"A": spectra.gram_factor(_spd(200, 5, 10.0)), "B": spectra.gram_factor(_spd(200, 6, 100.0))}
    shared = spectra.bottom_spectra(S, factors)
    for norm, L in factors.items():
        alone = spectra.bottom_spectrum(S, L)
        assert (shared[norm].beta, shared[norm].gap) == (alone.beta, alone.gap)
        assert np.array_equal(shared[norm].bottom, alone.bottom)
        dense = spectra.spectrum(S, factor=L)
        assert shared[norm].beta == pytest.approx(dense.beta, rel=1e-10)


def test_singular_s_without_kernel_falls_back_to_the_floor():
    """S singular and no kernel passed (β with v1 = 0 of a space whose B_2ᵀ alone has a kernel):
    potrf refuses S, the floored factorization answers λ ≈ 0, reported as β = 0 like a
    round-off eigenvalue."""
    S, G, _ = _pencil(200, 4, seed=7)
    assert bottom.definite_factor(S) is None
    assert bottom.definite_factor(G) is not None
    L = spectra.gram_factor(G)
    it = spectra.bottom_spectrum(S, L)
    dense = spectra.spectrum(S, factor=L)
    assert it.beta == 0.0
    assert dense.beta <= np.sqrt(200 * np.finfo(float).eps * sla.eigh(S, G, eigvals_only=True)[-1])
    assert (spectra.bottom_spectra(S, {"H": L})["H"].beta, it.beta) == (0.0, 0.0)


def _terms_and_factors(m, d, seed):
    """Interface terms S1, S2 sharing a kernel of dimension d (B_1ᵀ and B_2ᵀ vanish on it)."""
    rng = np.random.default_rng(seed)
    Z = np.linalg.qr(rng.standard_normal((m, d)))[0] if d else np.zeros((m, 0))
    P = np.eye(m) - Z @ Z.T
    terms = []
    for i in range(2):
        C = rng.standard_normal((m + 5, m)) @ P
        terms.append(C.T @ C)
    return terms, {"H": spectra.gram_factor(_spd(m, seed + 1, 10.0)), "L2": spectra.gram_factor(_spd(m, seed + 2))}, Z


@pytest.mark.parametrize("d", [0, 6])
def test_beta_v1_zero_between_routes(d, monkeypatch):
    """Without a kernel both routes solve the pencil of S2 (1e-10); with one the large route
    reports 0 without solving (bottom_spectra is not called), and the dense route's value is
    round-off: below sqrt(m ε λ_max)."""
    terms, factors, Z = _terms_and_factors(160, d, seed=20 + d)
    W = np.vstack([terms[0] + terms[1], np.zeros((3, 160))])
    kernel = coupling_kernel(W, proven=d)
    assert kernel.dim == d
    dense = spectra.betas_v1_zero(terms, factors, kernel, iterative=False)
    assert dense == {n: spectra.spectrum(terms[1], factor=L).beta for n, L in factors.items()}  # as before
    if d:
        monkeypatch.setattr(spectra, "bottom_spectra", lambda *a, **k: pytest.fail("computed"))
    large = spectra.betas_v1_zero(terms, factors, kernel, iterative=True)
    for norm, L in factors.items():
        if d:
            top = sla.eigh(terms[1], L @ L.T, eigvals_only=True)[-1]
            assert large[norm] == 0.0 <= dense[norm] <= np.sqrt(160 * np.finfo(float).eps * top)
        else:
            assert large[norm] == pytest.approx(dense[norm], rel=1e-10)


@pytest.mark.parametrize("order", ["C", "F"])
def test_standard_form_and_lam_max(order):
    """x ↦ L⁻¹ S L⁻ᵀ x with S in either memory order (symv on its lower triangle) equals the dense
    product; λ_max within LAM_MAX_RTOL of eigh's (6 Lanczos vectors, ARPACK's own test)."""
    S, G, _ = _pencil(150, 0, seed=30)
    S = np.array(S, order=order)
    L = np.tril(sla.cholesky(G, lower=True))
    x = np.random.default_rng(1).standard_normal(150)
    dense = np.linalg.solve(L, S @ np.linalg.solve(L.T, x))
    np.testing.assert_allclose(bottom._standard_form(S, L).matvec(x), dense, rtol=0, atol=1e-12 * np.abs(dense).max())
    top = sla.eigh(S, G, eigvals_only=True)[-1]
    assert abs(bottom.lam_max(S, L) - top) <= bottom.LAM_MAX_RTOL * top
