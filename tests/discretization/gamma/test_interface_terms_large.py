"""Above ``SPARSE_PRODUCT_MIN_DIM`` the interface terms B X Bᵀ are two sparse-times-dense
products with the side's explicit X = S⁻¹ (potri from the Cholesky factor of S, or the side's own
``steklov``), made once per side: the same matrix as the triangular-solve route B (S⁻¹ Bᵀ) to
round-off; below the gate the terms are the solve route's bit for bit. The gate is lowered here so
that a small face pair takes the large route (dim M > 1500 needs N ≥ 20 at k = 2)."""
import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.spaces.registry import case_space, ids_valid_for, space_ids
from infsup_contact.errors import InputError
from infsup_contact.models import make_model
from infsup_contact.solvers import interface_operator

RTOL = 1e-12


@pytest.fixture(scope="module", params=[("hex", 3, 4, 2), ("tet", 3, 3, 1), ("hex", 6, 7, 2)], ids=lambda p: f"{p[0]}-{p[1]}:{p[2]}-k{p[3]}")
def setup(request):
    element, n1, n2, k = request.param
    m = make_model("membranes3d")
    sides = [m.side_operator(m.mesh("structured", n, i + 1, element=element), k) for i, n in enumerate((n1, n2))]
    # the same operators without their X: the large route then inverts S itself (potri)
    sides += [dataclasses.replace(s, steklov=None) for s in sides if s.steklov is not None]
    gamma = sides[0].trace.gamma
    part = gamma.multiplier_partition(sides[0].trace.partition, sides[1].trace.partition, "union")
    spaces = []
    for case in ids_valid_for(k, space_ids(gamma.dim)):
        try:
            spaces.append(case_space(case, k, part, gamma))
        except InputError:
            pass
    return sides, spaces, k


def _solve_route(B, side):
    """B (X Bᵀ), X Bᵀ by the side's steklov_times (the route below the gate)."""
    return np.asarray(B @ side.steklov_times(B.T))


def test_explicit_steklov_is_the_symmetric_inverse_of_s(setup):
    sides, _, _ = setup
    for side in sides:
        X = side._steklov_explicit
        assert X is side._steklov_explicit  # made once per side
        if side.steklov is not None:
            assert X is side.steklov
            continue
        assert np.array_equal(X, X.T)
        n = len(X)
        assert np.linalg.norm(X @ side.schur - np.eye(n)) < 1e-12 * np.linalg.cond(side.schur) * n
        assert np.allclose(X, np.linalg.inv(side.schur), rtol=0, atol=1e-12 * np.abs(X).max())


def test_large_route_agrees_with_the_solve_route(setup, monkeypatch):
    sides, spaces, k = setup
    monkeypatch.setattr(interface_operator, "SPARSE_PRODUCT_MIN_DIM", 0)
    assert any(s.steklov is None for s in sides)  # the potri inverse is exercised
    for space in spaces:
        Bs = [coupling_matrix(s.trace, space, k) for s in sides[:2]]
        Bs += [Bs[i] for i, s in enumerate(sides[:2]) if s.steklov is not None]
        assert space.dim > interface_operator.SPARSE_PRODUCT_MIN_DIM
        for T, B, side in zip(interface_operator.interface_terms(Bs, sides), Bs, sides):
            ref = _solve_route(B, side)
            assert T.shape == (space.dim, space.dim)
            assert np.linalg.norm(T - ref) <= RTOL * np.linalg.norm(ref)
            assert np.linalg.norm(T - T.T) <= RTOL * np.linalg.norm(ref)
            w = np.linalg.eigvalsh(0.5 * (T + T.T))  # B X Bᵀ is positive semidefinite
            assert w.min() >= -RTOL * w.max()


def test_below_the_gate_the_terms_are_the_solve_routes_bit_for_bit(setup):
    sides, spaces, k = setup
    below = [space for space in spaces if space.dim <= interface_operator.SPARSE_PRODUCT_MIN_DIM]
    assert below
    for space in below:
        Bs = [coupling_matrix(s.trace, space, k) for s in sides[:2]]
        for T, B, side in zip(interface_operator.interface_terms(Bs, sides[:2]), Bs, sides[:2]):
            assert np.array_equal(T, _solve_route(B, side))


def test_a_side_without_a_sandwich_keeps_the_sparse_solve_route(setup, monkeypatch):
    sides, spaces, k = setup
    monkeypatch.setattr(interface_operator, "SPARSE_PRODUCT_MIN_DIM", 0)

    class SolvesOnly:  # the side contract without steklov_sandwich
        def __init__(self, side):
            self.steklov_times = side.steklov_times

    side, space = sides[0], spaces[0]
    B = coupling_matrix(side.trace, space, k)
    (T,) = interface_operator.interface_terms([B], [SolvesOnly(side)])
    assert np.array_equal(T, np.asarray(sp.csr_matrix(B) @ side.steklov_times(B.T)))


def test_forget_cached_drops_the_explicit_inverse(setup):
    sides, _, _ = setup
    side = next(s for s in sides if s.steklov is None)
    side._steklov_explicit
    side.forget_cached()
    assert "_steklov_explicit" not in side.__dict__ and "_schur_cholesky" not in side.__dict__
