"""scipy's LAPACK called through ctypes (la/openblas.py: potrf, lauum, geqrf, orgqr, gesdd) gives what
scipy.linalg's wrappers give, bit for bit (the same routine of the same library, the same
workspace), in C or Fortran order, overwritten in place or not; the calls release the GIL, so
two threads give each their own result unchanged."""
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.linalg import lapack

from infsup_contact.la import openblas


def _spd(n, seed=0):
    A = np.random.default_rng(seed).standard_normal((n, n))
    return A @ A.T + n * np.eye(n)


def test_the_routines_are_found_in_scipys_openblas():
    assert openblas._agrees()
    names = ("dpotrf", "dpotrs", "dlauum", "dgeqrf", "dorgqr", "dgesdd", "dsymv", "dtrsv", "dtrtrs")
    assert all(openblas._lapack(name) is not None for name in names)


@pytest.mark.parametrize("n", [1, 7, 130, 600])
@pytest.mark.parametrize("order", ["C", "F"])
def test_potrf_cholesky_and_lauum_are_scipys_bit_for_bit(n, order):
    S = np.array(_spd(n, n), order=order)
    for clean in (True, False):
        L, info = openblas.potrf(S, clean=clean)
        L0, info0 = lapack.dpotrf(S, lower=1, clean=int(clean))
        assert info == info0 == 0 and np.array_equal(L, L0) and L.flags.f_contiguous
    assert np.array_equal(openblas.cholesky_lower(S), sla.cholesky(S, lower=True, check_finite=False))
    K = np.tril(np.random.default_rng(n).standard_normal((n, n)))
    C, info = openblas.lauum(np.array(K, order=order))
    assert info == 0 and np.array_equal(C, lapack.dlauum(K, lower=1)[0])
    F = np.asfortranarray(S.copy())
    L, _ = openblas.potrf(F, overwrite=True)
    assert L is F and np.array_equal(L, lapack.dpotrf(S, lower=1, clean=1)[0])  # in place, as overwrite_a
    assert np.array_equal(S, _spd(n, n))  # the input untouched without overwrite


def test_a_matrix_that_is_not_positive_definite_is_reported_as_scipy_does():
    S = _spd(50)
    S[10, 10] = -1.0
    assert openblas.potrf(S)[1] == lapack.dpotrf(S, lower=1, clean=1)[1] == 11
    with pytest.raises(np.linalg.LinAlgError):
        openblas.cholesky_lower(S)


@pytest.mark.parametrize("shape", [(40, 40), (300, 120), (700, 200), (90, 150), (1, 1), (5, 0)])
@pytest.mark.parametrize("order", ["C", "F"])
def test_gesdd_and_the_qr_r_are_scipys_bit_for_bit(shape, order):
    W = np.array(np.random.default_rng(sum(shape)).standard_normal(shape), order=order)
    s, vt = openblas.gesdd(W, compute_uv=True)
    _, s0, vt0 = sla.svd(W, full_matrices=False, check_finite=False)
    assert np.array_equal(s, s0) and np.array_equal(vt, vt0)
    s, none = openblas.gesdd(W, compute_uv=False)
    assert none is None and np.array_equal(s, sla.svdvals(W, check_finite=True))
    if shape[0] >= shape[1]:
        R0 = np.triu(sla.qr(W, mode="r", check_finite=True)[0][:shape[1]])
        assert np.array_equal(openblas.qr_r(W), R0)
        F = np.asfortranarray(W.copy())
        assert np.array_equal(openblas.qr_r(F, overwrite=True), R0)


@pytest.mark.parametrize("shape", [(40, 40), (300, 120), (700, 200), (90, 150), (1, 1), (5, 0), (2000, 40)])
@pytest.mark.parametrize("order", ["C", "F"])
def test_the_full_gesdd_and_the_orthonormal_qr_factor_are_scipys_bit_for_bit(shape, order):
    W = np.array(np.random.default_rng(3 * sum(shape)).standard_normal(shape), order=order)
    s, vt = openblas.gesdd(W, compute_uv=True, full=True)
    _, s0, vt0 = sla.svd(W, check_finite=False)  # full_matrices: Vᵀ square
    assert vt.shape == vt0.shape == (shape[1], shape[1])
    assert np.array_equal(s, s0) and np.array_equal(vt, vt0)
    Q0 = sla.qr(W, mode="economic")[0]
    Q = openblas.qr_q(W)
    assert Q.shape == Q0.shape and np.array_equal(Q, Q0)
    assert np.array_equal(W, np.random.default_rng(3 * sum(shape)).standard_normal(shape))  # W untouched
    if shape[0] >= shape[1] > 0:
        assert np.allclose(Q.T @ Q, np.eye(shape[1]), atol=1e-13)
        F = np.asfortranarray(W.copy())
        assert np.array_equal(openblas.qr_q(F, overwrite=True), Q0)


def test_a_non_finite_matrix_is_refused_by_the_qr_as_by_scipys():
    W = np.ones((6, 3))
    W[2, 1] = np.nan
    for qr in (openblas.qr_q, openblas.qr_r, lambda A: sla.qr(A, mode="economic")):
        with pytest.raises(ValueError):
            qr(W)


def test_two_threads_give_each_call_its_own_result():
    mats = [_spd(400, seed) for seed in range(4)]
    alone = [openblas.gesdd(M, compute_uv=True) for M in mats] + [openblas.potrf(M)[0] for M in mats]
    with ThreadPoolExecutor(2) as pool:
        both = list(pool.map(lambda M: openblas.gesdd(M, compute_uv=True), mats))
        both += list(pool.map(lambda M: openblas.potrf(M)[0], mats))
    for a, b in zip(alone, both):
        a, b = (a, b) if isinstance(a, np.ndarray) else (np.concatenate([a[0], a[1].ravel()]),
                                                          np.concatenate([b[0], b[1].ravel()]))
        assert np.array_equal(a, b)


@pytest.mark.parametrize("n", [1, 9, 250])
@pytest.mark.parametrize("order", ["C", "F"])
def test_the_lanczos_steps_level_2_calls_are_scipys_bit_for_bit(n, order):
    from scipy.linalg import blas

    rng = np.random.default_rng(n)
    S = np.array(_spd(n, n), order=order)
    L = np.array(np.linalg.cholesky(S), order=order)
    x = rng.standard_normal(n)
    X = rng.standard_normal((n, 3))
    for lower in (True, False):
        A = L if lower else np.array(L.T, order=order)
        assert np.array_equal(openblas.symv(S, x, lower), blas.dsymv(1.0, S, x, lower=int(lower)))
        for trans in (0, 1):
            assert np.array_equal(openblas.trsv(A, x, lower, trans), blas.dtrsv(A, x, lower=int(lower), trans=trans))
            for b in (x, X):
                want = sla.solve_triangular(A, b, lower=lower, trans=trans, check_finite=False)
                got = openblas.solve_triangular(A, b, lower, trans)
                assert got.shape == want.shape and np.array_equal(got, want)
    assert np.array_equal(x, np.random.default_rng(n).standard_normal(n))  # the inputs untouched
    A = np.array(L, order=order)
    A[n // 2, n // 2] = 0.0
    with pytest.raises(np.linalg.LinAlgError):
        sla.solve_triangular(A, x, lower=True, check_finite=False)
    with pytest.raises(np.linalg.LinAlgError):
        openblas.solve_triangular(A, x, True)


@pytest.mark.parametrize("n", [1, 60, 300])
def test_cho_factor_and_cho_solve_are_scipys_bit_for_bit(n):
    S = _spd(n, 2 * n)
    c0, _ = sla.cho_factor(S.copy(), lower=True, check_finite=False)
    c = openblas.cholesky_lower(S.copy(), clean=False)
    assert np.array_equal(c, c0)
    rng = np.random.default_rng(n)
    for b in (rng.standard_normal(n), rng.standard_normal((n, 4)), np.asfortranarray(rng.standard_normal((n, 2)))):
        want = sla.cho_solve((c0, True), b, check_finite=False)
        got = openblas.potrs(c, b)
        assert got.shape == want.shape and np.array_equal(got, want)


def test_without_scipys_openblas_the_calls_are_scipy_linalgs(monkeypatch):
    """Where the routines are not found (another scipy build) every call falls back to
    scipy.linalg's own, with the same results."""
    monkeypatch.setattr(openblas, "_lapack", lambda name: None)
    S, W = _spd(30), np.random.default_rng(3).standard_normal((50, 20))
    assert np.array_equal(openblas.potrf(S)[0], lapack.dpotrf(S, lower=1, clean=1)[0])
    assert np.array_equal(openblas.gesdd(W, True)[1], sla.svd(W, full_matrices=False)[2])
    assert np.array_equal(openblas.qr_r(W), np.triu(sla.qr(W, mode="r")[0][:20]))
    assert np.array_equal(openblas.potrs(openblas.cholesky_lower(S, clean=False), W[:30]),
                          sla.cho_solve(sla.cho_factor(S, lower=True), W[:30]))
