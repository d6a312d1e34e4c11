"""The contact QP from (A, B, F) only: Γ read off B, blocks of A, both factorization routes."""
import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.contact.kkt import solve_kkt_sparse
from infsup_contact.contact.contact import linear_saddle_solve
from infsup_contact.errors import InputError
from infsup_contact.la.schur import gamma_factorization
from infsup_contact.contact.reduced_qp import solve_reduced_qp, touched_columns

from test_pdas import assert_qp_kkt, lap2d, random_problem, thin_obstacle

TOL = 1e-10


def two_membranes(n, seed=0):
    """Two independent 5-point Laplacians coupled by gap rows on one grid row each, the
    discrete analogue of the model problem: A block diagonal, B = [−E1, E2]."""
    rng = np.random.default_rng(seed)
    A = sp.block_diag([lap2d(n), 2.0 * lap2d(n)], format="csc")
    row1 = (n - 1) * n + np.arange(n)          # top row of membrane 1
    row2 = n * n + np.arange(n)                # bottom row of membrane 2
    B = sp.csr_matrix((np.r_[-np.ones(n), np.ones(n)],
                       (np.r_[np.arange(n), np.arange(n)], np.r_[row1, row2])), shape=(n, 2 * n * n))
    column = np.tile(np.arange(n), n)
    up = np.where(column < n // 2, 1.0, -1.0)      # membrane 1 pushed up on its left half only
    F = np.r_[up, np.full(n * n, -0.5)] / n ** 2 + 0.05 * rng.standard_normal(2 * n * n) / n ** 2
    return A, B, F


def test_touched_columns_ignore_explicit_zeros():
    B = sp.csr_matrix(np.array([[0.0, 1.0, 0.0, 2.0], [0.0, 0.0, 0.0, -1.0]]))
    B.data[0] = 0.0                             # an explicitly stored zero
    assert touched_columns(B).tolist() == [3]


@pytest.mark.parametrize("route", ["auto", "solves", "nested"])
@pytest.mark.parametrize("seed", range(3))
def test_random_constraints_match_the_sparse_kkt_route(route, seed):
    A, B, F = random_problem(seed)
    sol = solve_reduced_qp(A, B, F, route=route)
    u, lam, _ = solve_kkt_sparse(A, B, F)
    assert np.abs(sol.lam - lam).max() <= TOL and np.abs(sol.u - u).max() <= TOL
    assert_qp_kkt(A, B, F, sol.u, sol.lam)
    assert sol.n_gamma == len(np.unique(B.indices))


@pytest.mark.parametrize("route", ["solves", "nested"])
def test_two_blocks_with_contact(route):
    A, B, F = two_membranes(12)
    sol = solve_reduced_qp(A, B, F, route=route)
    assert sol.route == route                    # one route for both blocks
    assert_qp_kkt(A, B, F, sol.u, sol.lam)
    assert 0 < sol.pdas.active.sum() < B.shape[0]  # a genuine contact set, not all or nothing
    u, lam, _ = solve_kkt_sparse(A, B, F)
    assert np.abs(sol.lam - lam).max() <= TOL * max(1.0, np.abs(lam).max())


def test_floor_with_the_contact_set_reproduces_the_qp_solution():
    A, B, F = thin_obstacle(14, lambda x, y: -10.0 * np.ones_like(x))
    sol = solve_reduced_qp(A, B, F)
    u, lam = linear_saddle_solve(A, B, F, sol.pdas.active)
    assert np.abs(u - sol.u).max() <= 1e-10 * np.abs(sol.u).max()
    assert np.abs(lam - sol.lam).max() <= 1e-10 * np.abs(sol.lam).max()


@pytest.mark.parametrize("n_gamma", [0, 1, 7])
def test_factorization_routes_agree(n_gamma):
    A = lap2d(9)
    n = A.shape[0]
    a, b = gamma_factorization(A, n_gamma, "solves", gamma_dim=None), gamma_factorization(A, n_gamma, "nested", gamma_dim=None)
    c = gamma_factorization(A, n_gamma, "pardiso", gamma_dim=None)
    assert (a.route, b.route, c.route) == ("solves", "nested", "pardiso")
    D = A.toarray()
    X = np.linalg.inv(D)[n - n_gamma:, n - n_gamma:]     # (A⁻¹)_ΓΓ by brute force
    for fac in (a, b, c):
        assert np.allclose(fac.schur @ X, np.eye(n_gamma), atol=1e-10)
        rhs = np.arange(n, dtype=float)
        assert np.allclose(D @ fac.solve(rhs), rhs, atol=1e-10)
    assert np.allclose(a.steklov, X, atol=1e-12)


def test_bad_route_and_shapes():
    A, B, F = random_problem(0)
    with pytest.raises(InputError, match="route"):
        solve_reduced_qp(A, B, F, route="fastest")
    with pytest.raises(InputError, match="F"):
        solve_reduced_qp(A, B, F[:-1])
