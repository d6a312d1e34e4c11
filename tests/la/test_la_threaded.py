"""The threaded products (la/threaded.py) are bit for bit the one-thread ones, at every thread count."""
import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.la import threaded


def _data(m, n, seed=0):
    rng = np.random.default_rng(seed)
    A = sp.random(m, n, density=min(1.0, 12 / n), format="csr", random_state=seed)
    X = rng.standard_normal((n, n))
    return A, X + X.T                                  # exactly symmetric


@pytest.mark.parametrize("n_threads", ["1", "2", "3"])
@pytest.mark.parametrize("shape", [(7, 5), (600, 700), (1100, 530)])
def test_sandwich_is_the_former_route_bit_for_bit(monkeypatch, n_threads, shape):
    monkeypatch.setenv("MKL_NUM_THREADS", n_threads)
    A, X = _data(*shape)
    former = np.asarray(A @ np.asarray(A @ X).T)
    assert np.array_equal(threaded.symmetric_sandwich(A, X), former)


@pytest.mark.parametrize("n_threads", ["1", "2"])
def test_sparse_times_dense_and_times_transpose(monkeypatch, n_threads):
    monkeypatch.setenv("MKL_NUM_THREADS", n_threads)
    A, X = _data(900, 400, seed=3)
    Y = np.random.default_rng(4).standard_normal((300, 400))
    assert np.array_equal(threaded.sparse_times_dense(A, X), A @ X)
    T = threaded.times_transpose(A, Y)
    assert T.flags.c_contiguous and T.shape == (300, 900)
    assert np.allclose(T, Y @ A.T.toarray(), rtol=0, atol=1e-12)


@pytest.mark.parametrize("n_threads", ["1", "2"])
@pytest.mark.parametrize("dx, dy", [(3, 4), (40, 30)])
def test_symmetric_pairs_reorders_and_symmetrises(monkeypatch, n_threads, dx, dy):
    monkeypatch.setenv("MKL_NUM_THREADS", n_threads)
    F = np.random.default_rng(5).standard_normal((dx * dx, dy * dy))
    G = F.reshape(dx, dx, dy, dy).transpose(0, 2, 1, 3).reshape(dx * dy, dx * dy)
    assert np.array_equal(threaded.symmetric_pairs(F, dx, dy), 0.5 * G + 0.5 * G.T)


def test_threads_follow_the_environment(monkeypatch):
    monkeypatch.delenv("MKL_NUM_THREADS", raising=False)
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")
    assert threaded.threads() == 2
    monkeypatch.setenv("MKL_NUM_THREADS", "junk")
    assert threaded.threads() == 1


@pytest.mark.parametrize("n_threads", ["1", "2"])
@pytest.mark.parametrize("m", [3, 700])
def test_symmetric_part(monkeypatch, n_threads, m):
    monkeypatch.setenv("MKL_NUM_THREADS", n_threads)
    A = np.random.default_rng(6).standard_normal((m, m))
    S = threaded.symmetric_part(A)
    assert np.array_equal(S, 0.5 * (A + A.T)) and np.array_equal(S, S.T)
    assert np.array_equal(threaded.symmetric_part(np.asfortranarray(A)), S)


def test_trailing_solve_refuses_c_order():
    from infsup_contact.la import mkl
    if not mkl.available():
        pytest.skip("MKL not loadable here")
    R = np.eye(4)
    with pytest.raises(ValueError, match="Fortran"):
        mkl.trailing_solve(np.ascontiguousarray(R) + np.tril(np.ones((4, 4)), -1), np.asfortranarray(R), 0, 2)


@pytest.mark.parametrize("n_threads", ["1", "2", "3"])
@pytest.mark.parametrize("m", [5, 900])
def test_elementwise_is_numpy_bit_for_bit(monkeypatch, n_threads, m):
    """The Richardson step a + (a − b)/7 and a difference, row blocks over the threads."""
    monkeypatch.setenv("MKL_NUM_THREADS", n_threads)
    rng = np.random.default_rng(7)
    a, b = rng.standard_normal((m, m)), rng.standard_normal((m, m))
    assert np.array_equal(threaded.elementwise(lambda x, y: x + (x - y) / 7.0, a, b), a + (a - b) / 7.0)
    assert np.array_equal(threaded.elementwise(np.subtract, a, np.asfortranarray(b)), a - b)


@pytest.mark.parametrize("n_threads", ["1", "2"])
def test_signed_gather_sum_is_the_sparse_sandwich_and_exactly_symmetric(monkeypatch, n_threads):
    """Σ_c Q_c D_c Q_cᵀ for bases with at most one nonzero per row, by gathers."""
    monkeypatch.setenv("MKL_NUM_THREADS", n_threads)
    rng = np.random.default_rng(8)
    m, sizes = 600, (250, 200, 150)
    owner = rng.permutation(np.repeat(np.arange(3), sizes))       # row i belongs to block owner[i]
    index, sign, blocks, ref = [], [], [], np.zeros((m, m))
    for c, mc in enumerate(sizes):
        rows = np.flatnonzero(owner == c)
        idx, w = np.zeros(m, dtype=np.intp), np.zeros(m)
        idx[rows], w[rows] = np.arange(mc), rng.choice([-1.0, 1.0], mc) * 0.5
        A = rng.standard_normal((mc, mc))
        D = A + A.T
        Q = sp.csr_matrix((w[rows], (rows, np.arange(mc))), shape=(m, mc))
        ref += (Q @ D @ Q.T)
        index.append(idx), sign.append(w), blocks.append(D)
    G = threaded.signed_gather_sum(blocks, index, sign)
    np.testing.assert_allclose(G, ref, atol=1e-14 * np.abs(ref).max())
    assert np.array_equal(G, G.T)
