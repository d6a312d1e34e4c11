"""The sparse projection of the cellwise face spaces and the shared series of their piece space
(:mod:`infsup_contact.discretization.face.norms.cellwise`): two routes agree, the sharing
changes no number, and it holds one piece space at a time."""
import contextlib

import numpy as np
import pytest

from infsup_contact.discretization.face.norms import cellwise as fcn
from infsup_contact.discretization.gamma.coupling import weighted_values
from infsup_contact.discretization.face.spaces.cellwise import CellwiseFaceSpace
from infsup_contact.discretization.face.norms.tensor import gram_l2_face
from infsup_contact.discretization.segment.multipliers import make_space
from infsup_contact.discretization.segment.norms import gram_l2
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError

GRID = TensorPartition(np.array([0.0, 0.2, 0.45, 0.7, 1.0]), np.array([0.0, 0.35, 0.6, 1.0]))
SPACES = [("QUAD9", "dual", True), ("QUAD9", "dual", False), ("QUAD8", "transformed_dual", True),
          ("QUAD9", "transformed_dual", True), ("QUAD4", "dual", True), ("QUAD9", "pwlin", True),
          ("QUAD9", "standard", True), ("QUAD8", "transformed", False)]


def _space(element, basis, vanish):
    return CellwiseFaceSpace(GRID, element, basis, vanish_on_boundary=vanish)


@pytest.mark.parametrize("element,basis,vanish", SPACES)
def test_sparse_values_are_evaluate(element, basis, vanish):
    space = _space(element, basis, vanish)
    x, w = fcn.piece_rule(space.pieces, 3)
    assert np.array_equal(fcn._at(space, x).toarray(), space.evaluate(x))
    assert np.array_equal(weighted_values(space, x, w).toarray(), space.evaluate(x) * w[:, None])


@pytest.mark.parametrize("s", [0, 1, 2, 3])
def test_block_inverse_mass_inverts_the_broken_mass(s):
    f = make_space(np.array([0.0, 0.1, 0.4, 0.45, 1.0]), s, False, False)
    assert np.allclose(fcn.block_inverse_mass(f) @ gram_l2(f), np.eye(f.dim), atol=1e-11)


def test_block_inverse_mass_refuses_a_continuous_space():
    with pytest.raises(InputError, match="discontinuous"):
        fcn.block_inverse_mass(make_space(np.linspace(0, 1, 5), 2, True, False))


@pytest.mark.parametrize("element,basis,vanish", SPACES)
def test_projection_agrees_with_the_dense_solve(element, basis, vanish):
    """R by blocks equals C G_P⁻¹ by a dense solve (the former route), and R P reproduces μ."""
    space = _space(element, basis, vanish)
    R, P = fcn.projection(space)
    x, w = fcn.piece_rule(P.breakpoints, space.piece_degree + 1)
    C = (space.evaluate(x) * w[:, None]).T @ P.evaluate(x)
    dense = np.linalg.solve(gram_l2_face(P), C.T).T
    assert np.abs(R.toarray() - dense).max() <= 1e-12 * np.abs(dense).max()
    xc, _ = fcn.piece_rule(P.breakpoints, space.piece_degree + 3)
    assert np.allclose(P.evaluate(xc) @ R.T.toarray(), space.evaluate(xc), atol=1e-12)
    cells = [len(g) - 1 for g in (P.breakpoints.xs, P.breakpoints.ys)]
    s = space.piece_degree      # continuous Q_s of the pieces, or discontinuous Q_s
    expected = [s * c + 1 if space.continuous else (s + 1) * c for c in cells]
    assert P.dim == expected[0] * expected[1]


@pytest.mark.parametrize("element,basis,vanish", SPACES[:3])
def test_l2_gram_is_the_dense_quadrature(element, basis, vanish):
    space = _space(element, basis, vanish)
    x, w = fcn.piece_rule(space.pieces, space.piece_degree + 1)
    E = space.evaluate(x)
    assert np.allclose(fcn.gram_l2_cellwise(space), (E * w[:, None]).T @ E, rtol=0, atol=1e-15)


def test_shared_sums_change_no_number_and_hold_one_piece_space():
    spaces = [_space(*a) for a in SPACES[:4]] + [_space("QUAD9", "pwlin", True)]
    alone = [fcn.gram_h_cellwise(s, rtol=1e-5) for s in spaces]
    assert fcn._shared is None
    with fcn.shared_piece_sums():
        shared = [fcn.gram_h_cellwise(s, rtol=1e-5) for s in spaces[:4]]
        cells_key = fcn._shared["key"]
        assert len(fcn._shared["sums"]) >= 3            # n0, 2 n0, 4 n0 at least
        with fcn.shared_piece_sums():                    # a nested block shares the outer one
            shared.append(fcn.gram_h_cellwise(spaces[4], rtol=1e-5))
        assert fcn._shared["key"] != cells_key           # pwlin's pieces replaced the cells' sums
    assert fcn._shared is None
    for (Ga, ia), (Gs, is_) in zip(alone, shared):
        assert np.array_equal(Ga, Gs) and ia == is_


def test_gram_sessions_of_the_interfaces():
    assert isinstance(SEGMENT.gram_session(), contextlib.nullcontext)
    with SQUARE.gram_session():
        assert fcn._shared == {}
    assert fcn._shared is None


def test_the_raised_start_gives_the_same_gram_when_the_last_levels_agree():
    """start_level: on the exponential-sum route a p = 2 series starts 4 n0 higher; the
    extrapolation uses the last three levels only, so it returns the very matrix of the
    levels from n0 whenever both stop at the same n_max."""
    from infsup_contact.discretization.face.norms import tensor as fn
    from infsup_contact.discretization.face.spaces.tensor import FaceSpace

    f = make_space(np.linspace(0, 1, 21), 1, False, False)      # dim 40² = 1600 > 1500, p = 2
    space = FaceSpace(f, f, TensorPartition(np.linspace(0, 1, 21), np.linspace(0, 1, 21)))
    assert space.dim > fn.LONG_SERIES_MIN_DIM and fn.start_level(80, 2.0, space.dim) == 4 * 80
    assert fn.start_level(80, 4.0, space.dim) == 80 and fn.start_level(80, 2.0, 1500) == 80
    G_raised, info = fn.gram_h_face(space, rtol=1e-5)
    G_from_n0, info0 = fn.gram_h_face(space, rtol=1e-5, n_start=80)
    assert info["n_start"] == 320 and info0["n_start"] == 80
    if info["n_max"] == info0["n_max"]:
        assert np.array_equal(G_raised, G_from_n0)
    else:                           # n_max ≥ 4·320 > the levels' stop: a later, tighter pair
        assert info["n_max"] > info0["n_max"]
        assert np.abs(G_raised - G_from_n0).max() <= 10 * 1e-5 * np.abs(G_raised).max()
