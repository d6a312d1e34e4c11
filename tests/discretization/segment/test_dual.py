"""Dual (biorthogonal) mortar multipliers: biorthogonality, dimensions, nodal coupling."""
import numpy as np
import pytest

from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.discretization.segment.dual import local_dual_coefficients, nodal_integrals
from infsup_contact.discretization.segment.meshes import mesh_pair, multiplier_breakpoints
from infsup_contact.discretization.segment.multipliers import local_basis_space, local_shapes
from infsup_contact.discretization.segment.norms import gram, gram_h
from infsup_contact.discretization.spaces.registry import SPACES, case_space
from infsup_contact.errors import InputError
from infsup_contact.models.membranes import side_operator


def nonuniform(n, seed=3):
    rng = np.random.default_rng(seed)
    x = np.sort(np.r_[0.0, rng.uniform(0.02, 0.98, n - 1), 1.0])
    assert np.all(np.diff(x) > 1e-3)
    return x


def mixed_mass(space_a, space_b, x, degree):
    """∫ a_i b_j on the common partition x, exact for piecewise polynomials of ``degree``."""
    t, w = np.polynomial.legendre.leggauss(degree // 2 + 1)
    a, b = x[:-1, None], x[1:, None]
    q = (0.5 * (a + b) + 0.5 * (b - a) * t).ravel()
    wq = (0.5 * (b - a) * w).ravel()
    return (space_a.evaluate(q) * wq[:, None]).T @ space_b.evaluate(q), space_b.evaluate(q).T @ wq


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_newton_cotes_weights_positive(k):
    d = nodal_integrals(k)
    assert np.all(d > 0) and np.isclose(d.sum(), 1.0, rtol=0, atol=1e-14)


@pytest.mark.parametrize("k", [1, 2, 3, 4])
@pytest.mark.parametrize("case, trace_case", [("DUAL", "T3"), ("DUAL-ALL", "R5.2")])
def test_biorthogonal_on_nonuniform_partitions(k, case, trace_case):
    """∫ ψ_i φ_j = δ_ij ∫ φ_j against the nodal basis of W_h (zero at the ends for DUAL)."""
    x = nonuniform(7)
    psi, phi = case_space(case, k, x, SEGMENT), case_space(trace_case, k, x, SEGMENT)
    M, integrals = mixed_mass(psi, phi, x, 2 * k)
    assert psi.dim == phi.dim
    assert np.all(integrals > 0)
    np.testing.assert_allclose(M, np.diag(integrals), rtol=0, atol=1e-13 * integrals.max())


@pytest.mark.parametrize("k", [1, 2, 3, 4])
@pytest.mark.parametrize("case", ["DUAL", "DUAL-ALL"])
def test_partition_of_unity_and_dimension(k, case):
    """Σ_j ψ_j = 1 (the constants are reproduced, also next to Γ's ends) and dim as counted."""
    x = nonuniform(5, seed=8)
    psi = case_space(case, k, x, SEGMENT)
    t = np.linspace(0.001, 0.999, 301)
    np.testing.assert_allclose(psi.evaluate(t).sum(axis=1), 1.0, atol=1e-12)
    assert psi.dim == SPACES[case].dimension(k, 5)
    assert SPACES[case].structural_kernel(k, 5) == (0 if case == "DUAL" else 2)


def test_k1_construction_as_stated():
    """k = 1: ψ = 2φ_a − φ_b per interior interval, the constant 1 on the end intervals."""
    np.testing.assert_allclose(local_dual_coefficients(1, [0, 1]), [[2, -1], [-1, 2]], atol=1e-13)
    np.testing.assert_allclose(local_dual_coefficients(1, [1]), [[0, 0], [1, 1]], atol=1e-13)
    np.testing.assert_allclose(local_dual_coefficients(1, [0]), [[1, 1], [0, 0]], atol=1e-13)


@pytest.mark.parametrize("k", [2, 3, 4])
def test_end_interval_functions_have_degree_k_minus_1(k):
    """Next to Γ's ends the dual functions lie in P_{k−1}: their top Lagrange-to-monomial
    coefficient vanishes."""
    C = local_dual_coefficients(k, np.arange(1, k + 1))
    t = np.linspace(0, 1, k + 1)
    values = C @ local_shapes(k, t).T          # ψ_a at k + 1 points
    top = np.polyfit(t, values.T, k)[0]        # coefficient of t^k of each ψ_a
    np.testing.assert_allclose(top, 0.0, atol=1e-10 * np.abs(values).max())


@pytest.mark.parametrize("k", [1, 2, 3])
def test_coupling_with_own_trace_is_nodal(k):
    """On matching meshes B2 of DUAL against Ω2's trace, written in the nodal (Lagrange) basis of
    W_h, is diagonal with the weights ∫ φ_j: the constraint is nodal (one weighted gap per
    trace node). NGSolve's own trace basis is hierarchical for k >= 2, so B is taken to the
    nodal basis by the values V[j, d] = φ^NGSolve_d(x_j) at the nodes: B_nodal = B V⁻¹."""
    m1, m2 = mesh_pair("structured", 6, 6)
    side = side_operator(m2, k)
    x = multiplier_breakpoints(m1, m2)
    dual, nodal = case_space("DUAL", k, x, SEGMENT), case_space("T3", k, x, SEGMENT)
    B = coupling_matrix(side.trace, dual, k)
    rows, cols, vals = SEGMENT.trace_values(side.trace, nodal.nodes())
    V = np.zeros((nodal.dim, B.shape[1]))
    np.add.at(V, (rows, cols), vals)
    B_nodal = B @ np.linalg.inv(V)
    _, integrals = mixed_mass(nodal, nodal, x, 2 * k)
    np.testing.assert_allclose(B_nodal, np.diag(integrals), rtol=0, atol=1e-12 * integrals.max())


@pytest.mark.parametrize("k", [1, 2])
def test_gram_routes_agree_for_dual(k):
    """Log kernel and sine series give the same H^{-1/2}_00 Gram for a non-Lagrange basis."""
    space = case_space("DUAL", k, nonuniform(6, seed=4), SEGMENT)
    G1, _ = gram(space, "H")
    G2, _ = gram_h(space, rtol=1e-9)
    np.testing.assert_allclose(G1, G2, rtol=0, atol=1e-8 * np.abs(G1).max())


def test_local_basis_space_rejects_malformed():
    x = np.linspace(0, 1, 4)
    with pytest.raises(InputError, match="dofs"):
        local_basis_space(x, 1, np.zeros((3, 3), dtype=int))
    with pytest.raises(InputError, match="dofs"):
        local_basis_space(x, 1, np.array([[0, 1], [1, 3], [3, 4]]))  # 2 is never used
    with pytest.raises(InputError, match="coefficients"):
        local_basis_space(x, 1, np.array([[0, 1], [1, 2], [2, 3]]), [[1, np.nan], [0, 1]])
