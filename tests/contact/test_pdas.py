"""Mathematical checks of the PDAS contact solvers (no stored result numbers).

Problems are synthetic: A a finite-difference Laplacian (SPD, sparse), B a few
constraint rows, F seeded random or a simple load.  References are the KKT conditions
themselves, an independent sparse saddle-point route, a general-purpose optimiser, and
brute-force enumeration of active sets on tiny problems.
"""
import itertools

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import minimize

from infsup_contact.contact.kkt import solve_kkt_sparse
from infsup_contact.contact.pdas import PdasDidNotConverge, PdasResult, solve_pdas
from infsup_contact.errors import InputError

TOL = 1e-10


# ---------------------------------------------------------------- problem builders
def lap1d(n):
    """−u'' with homogeneous Dirichlet data, n interior nodes, scaled by h (FE-like)."""
    h = 1.0 / (n + 1)
    return sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n), format="csc") / h


def lap2d(n):
    """5-point −Δ on the unit square, n×n interior nodes (FE-like scaling)."""
    h = 1.0 / (n + 1)
    T = lap1d(n) * h
    eye = sp.identity(n)
    return (sp.kron(T, eye) + sp.kron(eye, T)).tocsc()


def reduce(A, B, F):
    """Γ-reduction K = B A⁻¹ Bᵀ, g0 = B A⁻¹ F (dense, small m)."""
    lu = spla.splu(sp.csc_matrix(A))
    B = sp.csr_matrix(B)
    K = B @ lu.solve(B.T.toarray())
    return 0.5 * (K + K.T), B @ lu.solve(F), lu


def point_rows(idx, n):
    """Rows e_i (point constraints u_i ≥ 0)."""
    idx = np.asarray(idx)
    return sp.csr_matrix((np.ones(len(idx)), (np.arange(len(idx)), idx)), shape=(len(idx), n))


def thin_obstacle(n, load):
    """Membrane on the unit square pressed against a line obstacle at mid-height.

    u ≥ 0 on the grid row y ≈ 1/2: the Γ-reduced problem is 1D along that row with a
    non-local K (as for the two-membrane contact), B = trace rows.
    """
    A = lap2d(n)
    h = 1.0 / (n + 1)
    X, Y = np.meshgrid(np.linspace(h, 1 - h, n), np.linspace(h, 1 - h, n), indexing="xy")
    B = point_rows((n // 2) * n + np.arange(n), n * n)
    F = h * h * load(X, Y).ravel()
    return A, B, F


def random_problem(seed, n=15, m=10):
    rng = np.random.default_rng(seed)
    A = lap2d(n)
    B = sp.random(m, n * n, density=0.03, random_state=rng,
                  data_rvs=rng.standard_normal).tocsr()
    B = B[np.flatnonzero(np.abs(B).sum(axis=1).A1 > 0)]  # drop empty rows
    F = rng.standard_normal(n * n) * 5.0 / n
    return A, B, F


# ---------------------------------------------------------------- KKT helpers
def assert_lcp_solution(res, K, g0, tol=TOL):
    assert isinstance(res, PdasResult)
    np.testing.assert_allclose(res.gap, g0 + K @ res.lam, atol=tol, rtol=0)
    assert res.complementarity <= tol and np.max(np.abs(res.lam * res.gap)) <= tol
    assert res.min_gap >= -tol and res.gap.min() >= -tol
    assert res.min_lambda >= -tol and res.lam.min() >= -tol


def assert_qp_kkt(A, B, F, u, lam, tol=TOL):
    """KKT of min ½uᵀAu − Fᵀu s.t. Bu ≥ 0: Au − F − Bᵀλ = 0, λ ≥ 0, Bu ≥ 0, λ∘Bu = 0."""
    scale = max(1.0, np.abs(F).max())
    assert np.abs(A @ u - F - B.T @ lam).max() <= tol * scale
    g = B @ u
    assert lam.min() >= -tol and g.min() >= -tol and np.abs(lam * g).max() <= tol


def enumerate_lcp(K, g0):
    """All solutions of a tiny non-degenerate LCP by trying every active set."""
    sols = []
    for mask in itertools.product([False, True], repeat=len(g0)):
        S = np.array(mask)
        lam = np.zeros(len(g0))
        if S.any():
            lam[S] = np.linalg.solve(K[np.ix_(S, S)], -g0[S])
        g = g0 + K @ lam
        if lam.min() >= -1e-12 and g.min() >= -1e-12:
            sols.append(lam)
    return sols


# ---------------------------------------------------------------- (a), (b), (c)
@pytest.mark.parametrize("seed", range(6))
def test_random_constraints_reduced_vs_sparse(seed):
    A, B, F = random_problem(seed)
    K, g0, lu = reduce(A, B, F)
    res = solve_pdas(K, g0)
    assert_lcp_solution(res, K, g0)                                   # (a)
    u_red = lu.solve(F + B.T @ res.lam)
    u, lam, its = solve_kkt_sparse(A, B, F)                           # (b)
    assert np.abs(lam - res.lam).max() <= TOL
    assert np.abs(u - u_red).max() <= TOL
    assert its == res.iterations
    assert_qp_kkt(A, B, F, u_red, res.lam)                            # (c)
    assert not res.nonunique and res.kernel_dim == 0 and res.kernel_dim_K == 0


def test_random_problems_have_nontrivial_contact():
    # Guards the above against vacuous all-inactive instances.
    n_active = [solve_pdas(*reduce(*random_problem(s))[:2]).active.sum() for s in range(6)]
    assert all(0 < k for k in n_active) and any(k < 10 for k in n_active)


def test_qp_minimiser_against_slsqp():
    rng = np.random.default_rng(7)
    n = 5
    A = lap2d(n)
    B = sp.csr_matrix(rng.standard_normal((4, n * n)) * (rng.random((4, n * n)) < 0.3))
    F = rng.standard_normal(n * n)
    K, g0, lu = reduce(A, B, F)
    res = solve_pdas(K, g0)
    u = lu.solve(F + B.T @ res.lam)
    Ad, Bd = A.toarray(), B.toarray()

    def J(v):
        return 0.5 * v @ Ad @ v - F @ v

    opt = minimize(J, np.zeros(n * n), jac=lambda v: Ad @ v - F, method="SLSQP",
                   constraints=[dict(type="ineq", fun=lambda v: Bd @ v, jac=lambda v: Bd)],
                   options=dict(ftol=1e-14, maxiter=500))
    assert opt.success
    assert res.active.any()  # the constraint matters
    assert J(u) <= opt.fun + 1e-8 * abs(opt.fun)
    assert abs(J(u) - opt.fun) <= 1e-6 * abs(opt.fun)
    assert np.abs(u - opt.x).max() <= 1e-4 * np.abs(u).max()


# ---------------------------------------------------------------- (d) singular K
def test_duplicate_rows_give_nonunique_min_norm():
    n = 60
    A = lap1d(n)
    B = point_rows([15, 40, 40], n)  # the same constraint twice
    F = -np.ones(n) / (n + 1)        # pushes down: both points in contact
    K, g0, lu = reduce(A, B, F)
    res = solve_pdas(K, g0)
    assert_lcp_solution(res, K, g0)
    assert res.active.all()
    assert res.nonunique and res.kernel_dim == 1 and res.kernel_dim_K == 1
    # min-norm representative splits the duplicated multiplier evenly
    assert abs(res.lam[1] - res.lam[2]) <= TOL
    # same displacement and same total multiplier as with the constraint stated once
    ref = solve_pdas(*reduce(A, point_rows([15, 40], n), F)[:2])
    assert not ref.nonunique
    assert abs(res.lam[1] + res.lam[2] - ref.lam[1]) <= TOL and abs(res.lam[0] - ref.lam[0]) <= TOL
    np.testing.assert_allclose(lu.solve(F + B.T @ res.lam),
                               lu.solve(F + point_rows([15, 40], n).T @ ref.lam), atol=TOL)


@pytest.mark.parametrize("loads", [(1.0, 1.3), (1.0, 3.0)])
def test_dependent_rows_min_norm_representative(loads):
    """Rows e_a, e_b, e_a + e_b (rank 2): solutions λ = (α − t, β − t, t), t ∈ [0, min(α, β)].

    (α, β) are the unique multipliers of the rank-2 formulation.  The min-norm
    representative has t* = min((α + β)/3, α, β).  For β ≤ 2α all three are positive
    (kernel on the contact set, kernel_dim = 1); for β > 2α the plain min-norm solve of
    K_𝒜𝒜 has a negative entry, PDAS drops it and the solution is degenerate
    (λ_1 = g_1 = 0): still non-unique, but K on the positive multipliers is regular.
    """
    n, ia, ib = 40, 12, 27
    A = lap1d(n)
    F = np.zeros(n)
    F[ia], F[ib] = -loads[0], -loads[1]
    Bred = point_rows([ia, ib], n)
    B = sp.vstack([Bred, Bred[0] + Bred[1]]).tocsr()
    alpha, beta = solve_pdas(*reduce(A, Bred, F)[:2]).lam
    K, g0, lu = reduce(A, B, F)
    res = solve_pdas(K, g0)
    assert_lcp_solution(res, K, g0)
    t = min((alpha + beta) / 3, alpha, beta)
    np.testing.assert_allclose(res.lam, [alpha - t, beta - t, t], atol=TOL)
    assert res.nonunique and res.kernel_dim_K == 1
    assert res.kernel_dim == (1 if beta <= 2 * alpha else 0)
    np.testing.assert_allclose(lu.solve(F + B.T @ res.lam), lu.solve(F + Bred.T @ [alpha, beta]),
                               atol=TOL)


def gamma_mass_rows(n):
    """B_{j,i} = ∫ μ_j φ_i on the line: P1 multiplier hats at all n + 2 nodes (endpoints
    included, like the unstable choice of Rem. 5.2) against the n interior displacement
    hats (u = 0 at the ends).  dim M = n + 2 > rank = n, so K has a 2D kernel."""
    h = 1.0 / (n + 1)
    j = np.arange(1, n + 1)
    rows = np.concatenate([j, j - 1, j + 1])
    cols = np.concatenate([j - 1, j - 1, j - 1])
    vals = np.concatenate([np.full(n, 2 * h / 3), np.full(2 * n, h / 6)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n + 2, n))


@pytest.mark.parametrize("n", [31, 63])
@pytest.mark.parametrize("load", ["push", "mixed"])
def test_unstable_multiplier_space(n, load):
    f = {"push": lambda X, Y: -1.0 + 0 * X,
         "mixed": lambda X, Y: -8 * np.sin(np.pi * X) * (1 - 2 * X) - 1.0}[load]
    A, trace, F = thin_obstacle(n, f)
    B = sp.csr_matrix(gamma_mass_rows(n) @ trace)
    K, g0, lu = reduce(A, B, F)
    res = solve_pdas(K, g0)
    assert_lcp_solution(res, K, g0)
    assert res.kernel_dim_K == 2 and res.nonunique
    assert res.iterations <= 12
    # λ is not unique but u is: it satisfies the KKT conditions of the strictly convex QP
    u = lu.solve(F + B.T @ res.lam)
    assert_qp_kkt(A, B, F, u, res.lam)
    if load == "push":  # full contact: u = 0 on the line, as with point constraints
        ref = solve_pdas(*reduce(A, trace, F)[:2])
        assert res.active.all() and res.kernel_dim == 2
        np.testing.assert_allclose(u, lu.solve(F + trace.T @ ref.lam), atol=TOL)
    # the min-norm representative is orthogonal to every kernel direction supported on
    # the positive multipliers (no norm can be shaved off along them)
    w, V = np.linalg.eigh(K[np.ix_(res.active, res.active)])
    Z = V[:, w <= 1e-10 * np.linalg.eigvalsh(K).max()]
    assert Z.shape[1] == res.kernel_dim
    assert np.abs(Z.T @ res.lam[res.active]).max(initial=0.0) <= 1e-9 * np.abs(res.lam).max()


def test_sparse_route_refuses_dependent_active_rows():
    n = 30
    A, B = lap1d(n), point_rows([10, 10], n)
    with pytest.raises(np.linalg.LinAlgError):
        solve_kkt_sparse(A, B, -np.ones(n))


def test_zero_row_is_a_degenerate_kernel():
    # A zero row of B gives a zero row of K (nullity 1) with g_j ≡ g0_j = 0, so every
    # λ_j ≥ 0 solves: the min-norm representative takes λ_j = 0 (not in the contact
    # set, kernel_dim = 0), yet the solution is non-unique (feasible kernel direction).
    n = 20
    A = lap1d(n)
    B = sp.vstack([point_rows([5], n), sp.csr_matrix((1, n))]).tocsr()
    K, g0, _ = reduce(A, B, -np.ones(n))
    res = solve_pdas(K, g0)
    assert_lcp_solution(res, K, g0)
    assert res.kernel_dim_K == 1 and res.lam[1] == 0.0 and not res.active[1]
    assert res.nonunique and res.kernel_dim == 0


# ---------------------------------------------------------------- (e) extreme sets
def test_all_inactive_when_loads_pull_apart():
    A, B, F = thin_obstacle(15, lambda X, Y: 1.0 + 0 * X)  # u0 > 0: no contact
    K, g0, _ = reduce(A, B, F)
    assert g0.min() > 0
    res = solve_pdas(K, g0)
    assert not res.active.any() and np.all(res.lam == 0) and res.iterations == 1
    np.testing.assert_array_equal(res.gap, g0)
    u, lam, its = solve_kkt_sparse(A, B, F)
    assert np.all(lam == 0) and its == 1


def test_all_active_when_loads_push_together():
    # −Δu = −1 on both sides of the line with u = 0 on it: u < 0 off the line, so the
    # multiplier (jump of ∂u/∂y) is positive along the whole line.
    A, B, F = thin_obstacle(15, lambda X, Y: -1.0 + 0 * X)
    K, g0, lu = reduce(A, B, F)
    res = solve_pdas(K, g0)
    assert res.active.all() and res.lam.min() > 0
    assert_lcp_solution(res, K, g0)
    assert np.abs(res.gap).max() <= TOL
    u, lam, _ = solve_kkt_sparse(A, B, F)
    assert np.abs(lam - res.lam).max() <= TOL


# ---------------------------------------------------------------- (f) max_iter
def test_max_iter_hands_over_to_nnls_with_history():
    """PDAS stopped by max_iter is finished by the NNLS route: the same verified solution."""
    A, B, F = thin_obstacle(31, lambda X, Y: -8 * np.sin(np.pi * X) * (1 - 2 * X) - 1.0)
    K, g0, _ = reduce(A, B, F)
    full = solve_pdas(K, g0)
    assert full.iterations > 1 and full.route == "pdas"
    capped = solve_pdas(K, g0, max_iter=1)
    hist = capped.history
    assert capped.route == "pdas+nnls" and capped.iterations == 1
    assert {"iteration", "n_active", "residual", "nullity", "n_changed"} <= set(hist[0])
    assert hist[0]["n_changed"] > 0 and hist[0]["residual"] > 0
    assert any(h.get("fallback") == "nnls" and h.get("reason") == "max_iter" for h in hist)
    assert_lcp_solution(capped, K, g0)
    np.testing.assert_allclose(capped.lam, full.lam, atol=TOL * max(1.0, np.abs(full.lam).max()))
    with pytest.raises(PdasDidNotConverge):
        solve_kkt_sparse(A, B, F, max_iter=1)


# ---------------------------------------------------------------- (g) iteration counts
@pytest.mark.parametrize("n", [15, 31, 63, 127])
def test_line_obstacle_iterations_small(n):
    """Obstacle on a line (1D Γ-reduced problem, non-local K): few iterations at all h."""
    A, B, F = thin_obstacle(n, lambda X, Y: -8 * np.sin(np.pi * X) * (1 - 2 * X) - 1.0)
    K, g0, _ = reduce(A, B, F)
    res = solve_pdas(K, g0)
    assert_lcp_solution(res, K, g0)
    assert 0 < res.active.sum() < n and res.route == "pdas"
    assert res.iterations <= 12
    u, lam, its = solve_kkt_sparse(A, B, F)
    assert its == res.iterations and np.abs(lam - res.lam).max() <= TOL


@pytest.mark.parametrize("n", [31, 63])
def test_local_1d_obstacle_is_monotone(n):
    """1D obstacle u ≥ 0 at every node (A an M-matrix): HIK 2002 prove the active sets
    shrink monotonically after the first step.  Here the correction of λ is a point load
    at the edge of the active set, so the set shrinks by one node per side per step and
    the count grows like 1/h — a property of PDAS, not of this implementation."""
    A = lap1d(n)
    x = np.arange(1, n + 1) / (n + 1)
    F = -(10 * np.sin(3 * np.pi * x) + 2) / (n + 1)
    K, g0, _ = reduce(A, sp.identity(n, format="csr"), F)
    res = solve_pdas(K, g0, max_iter=n + 2)
    assert_lcp_solution(res, K, g0)
    sizes = [h["n_active"] for h in res.history if "n_active" in h]
    assert all(b <= a for a, b in zip(sizes, sizes[1:]))
    assert res.iterations <= n + 1


# ---------------------------------------------------------------- cycling fallback
def test_cycling_pdas_falls_back_and_solves():
    # SPD but not an M-matrix: plain PDAS cycles {0} → {0, 1, 2} → {0}.
    K = np.array([[13.0, -10.0, -7.0], [-10.0, 9.0, 7.0], [-7.0, 7.0, 6.0]])
    g0 = np.array([-4.0, 3.0, 0.0])
    res = solve_pdas(K, g0)
    assert res.route == "pdas+nnls"
    assert any(h.get("fallback") == "nnls" and h.get("reason") == "cycle" for h in res.history)
    assert_lcp_solution(res, K, g0)
    (ref,) = enumerate_lcp(K, g0)  # SPD: exactly one solution
    np.testing.assert_allclose(res.lam, ref, atol=TOL)
    assert not res.nonunique and res.kernel_dim_K == 0


def test_infeasible_lcp_raises():
    with pytest.raises(PdasDidNotConverge):
        solve_pdas(np.zeros((2, 2)), np.array([-1.0, 2.0]))


def test_empty_problem():
    res = solve_pdas(np.zeros((0, 0)), np.zeros(0))
    assert res.lam.size == 0 and not res.nonunique


# ---------------------------------------------------------------- input errors
@pytest.mark.parametrize("K, g0, kw", [
    (np.ones((2, 3)), np.zeros(2), {}),
    (np.eye(2), np.zeros(3), {}),
    (np.array([[1.0, 0.5], [0.0, 1.0]]), np.zeros(2), {}),
    (np.diag([1.0, -1.0]), np.zeros(2), {}),
    (np.array([[np.nan, 0], [0, 1.0]]), np.zeros(2), {}),
    (np.eye(2), np.zeros(2), dict(max_iter=0)),
    (np.eye(2), np.zeros(2), dict(max_iter=2.5)),
    (np.eye(2), np.zeros(2), dict(tol=0.0)),
    (np.eye(2), np.zeros(2), dict(kernel_rtol=2.0)),
])
def test_solve_pdas_bad_input(K, g0, kw):
    with pytest.raises(InputError):
        solve_pdas(K, g0, **kw)


def test_solve_kkt_sparse_bad_input():
    A = lap1d(5)
    with pytest.raises(InputError):
        solve_kkt_sparse(A, sp.csr_matrix((2, 4)), np.zeros(5))
    with pytest.raises(InputError):
        solve_kkt_sparse(A, sp.csr_matrix((2, 5)), np.zeros(4))
    with pytest.raises(InputError):
        solve_kkt_sparse(A, sp.csr_matrix((2, 5)), np.zeros(5), max_iter=0)
