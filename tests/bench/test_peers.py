"""Peer QP solvers reproduce our contact solution (same QP, same sign convention)."""
import numpy as np
import pytest

from infsup_contact import bench
from infsup_contact.bench import contact_routes, peers
from infsup_contact.contact.contact import solve_contact
from infsup_contact.study.contact.scenes import membranes


@pytest.fixture(scope="module", params=[1, 2], ids=["k1", "k2"])
def problem(request):
    k, n = request.param, 8
    sc, sides, Bs, F = contact_routes._contact_problem(n, k)
    A, B, Fv = peers.contact_qp(sides, Bs, F, (sc.c1, sc.c2))
    sol = solve_contact(membranes(), "T3", k, "structured", n, n, time_floor=False)
    u = np.concatenate([gf.vec.FV().NumPy()[s.free] for gf, s in zip(sol.u, sol.sides)])
    return A, B, Fv, u, sol.lam


def test_qp_data_is_our_kkt_system(problem):
    """A u = F + Bᵀλ, λ ≥ 0, B u ≥ 0, λ∘Bu = 0 for our solution: the QP is ours."""
    A, B, F, u, lam = problem
    scale = np.abs(F).max()
    assert np.abs(A @ u - F - B.T @ lam).max() <= 1e-12 * scale
    g = B @ u
    assert lam.min() >= -1e-14 * np.abs(lam).max() and g.min() >= -1e-12 * np.abs(g).max()
    assert np.abs(lam * g).max() <= 1e-12 * np.abs(lam).max() * np.abs(g).max()
    assert (lam > 0).any()  # a genuine contact problem: some constraints active


@pytest.mark.parametrize("name", peers.PEERS)
def test_peer_reproduces_ours_to_1e8(problem, name):
    A, B, F, u, lam = problem
    tol, res, reached, trials = bench.tune_peer(peers.SOLVERS[name], A, B, F, u, lam,
                                                peers.TOLERANCES)
    assert reached, trials
    du, dl = peers.relative_differences(res, u, lam)
    assert du <= 1e-8 and dl <= 1e-8
    assert res.iterations > 0 and res.tolerance == tol


@pytest.mark.parametrize("method", ["qdldl", "faer"])
def test_clarabel_methods_agree(problem, method):
    A, B, F, u, lam = problem
    s = np.abs(F).max()
    res = peers.solve_clarabel(A, B, F / s, 1e-12, method=method)
    du, dl = peers.relative_differences(res, u / s, lam / s)
    assert du <= 1e-8 and dl <= 1e-8


@pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")  # qpsolvers calls osqp.solve()
@pytest.mark.parametrize("solver,opts", [("osqp", dict(eps_abs=1e-10, eps_rel=1e-10, polishing=True)),
                                         ("clarabel", dict(tol_gap_abs=1e-12, tol_gap_rel=1e-12,
                                                           tol_feas=1e-12, tol_ktratio=1e-12))])
def test_sign_convention_through_qpsolvers(problem, solver, opts):
    """qpsolvers' own convention (G x ≤ h, z ≥ 0) gives the same λ: our translation is right."""
    A, B, F, u, lam = problem
    s = np.abs(F).max()
    res = peers.solve_qpsolvers(A, B, F / s, solver, **opts)
    du, dl = peers.relative_differences(res, u / s, lam / s)
    assert du <= 1e-7 and dl <= 1e-7
    assert res.lam.min() >= -1e-8 * np.abs(res.lam).max()


def test_osqp_multiplier_sign_on_a_toy_qp():
    """min ½|x|² − x1 − x2 s.t. x1 ≤ 1/2 written as −x1 ≥ −1/2: λ = 1/2 ≥ 0."""
    import scipy.sparse as sp

    A = sp.identity(2, format="csc")
    B = sp.csr_matrix(np.array([[-1.0, 0.0]]))  # B x ≥ 0  ⇔  x1 ≤ 0
    F = np.array([1.0, 1.0])
    for name in peers.PEERS:
        res = peers.SOLVERS[name](A, B, F, 1e-10)
        # KKT: x = F + Bᵀλ, x1 = 0 ⇒ λ = 1
        assert np.allclose(res.u, [0.0, 1.0], atol=1e-7), name
        assert np.allclose(res.lam, [1.0], atol=1e-7), name
