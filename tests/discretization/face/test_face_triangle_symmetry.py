"""Symmetries of Γ on the triangle face spaces (face_triangle_symmetry): the point reflection and
the transposition induce involutions π, σ of the dofs under which the computed sine coefficients
obey μ_mn(φ_π(g)) = (−1)^{m+n} μ_mn(φ_g) and μ_mn(φ_σ(g)) = μ_nm(φ_g); none where the grid
lacks the symmetry; the partial H Gram through them equals the plain product."""
import numpy as np
import pytest

from infsup_contact.discretization.face.norms import triangles as ftn
from infsup_contact.discretization.face.symmetry import reflection, transposition
from infsup_contact.discretization.face.spaces.triangles import TriangleSpace
from infsup_contact.discretization.spaces.registry import case_space
from infsup_contact.discretization.face.shapes.square import SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition

FAMILIES = [  # (s, continuous, vanish, dual)
    (0, False, False, False), (1, False, False, False), (2, False, False, False),
    (1, True, False, False), (1, True, True, False), (2, True, False, False), (2, True, True, False),
    (1, True, False, True), (1, True, True, True), (2, True, False, True), (2, True, True, True)]
UNIFORM = TensorPartition(np.linspace(0, 1, 5), np.linspace(0, 1, 4))
# symmetric about 1/2 but not uniform: two shapes per direction
SYMMETRIC = TensorPartition(np.array([0.0, 0.2, 0.5, 0.8, 1.0]), np.array([0.0, 0.3, 0.7, 1.0]))
SQUARE_GRID = TensorPartition(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
SYMMETRIC_SQUARE = TensorPartition(SYMMETRIC.xs, SYMMETRIC.xs)
GRADED = TensorPartition(np.array([0.0, 0.3, 0.5, 1.0]), np.array([0.0, 0.2, 0.7, 1.0]))


@pytest.mark.parametrize("part", [UNIFORM, SYMMETRIC], ids=["uniform", "symmetric"])
@pytest.mark.parametrize("s,continuous,vanish,dual", FAMILIES)
def test_reflection_is_an_involution_with_signed_coefficients(part, s, continuous, vanish, dual):
    space = TriangleSpace(part, s, continuous, vanish, dual)
    pi = reflection(space)
    assert pi is not None and np.array_equal(pi[pi], np.arange(space.dim))
    m = np.arange(1, 15, dtype=float)
    C = ftn.sine_coefficients_chunk(space, m, 14)
    sign = (-1.0) ** (m[:, None] + m[None, :])
    assert np.abs(C[pi] - sign[None] * C).max() < 1e-13 * np.abs(C).max()


@pytest.mark.parametrize("s,continuous,vanish,dual", [(0, False, False, False), (2, True, True, True)])
def test_no_reflection_on_a_graded_partition(s, continuous, vanish, dual):
    assert reflection(TriangleSpace(GRADED, s, continuous, vanish, dual)) is None


@pytest.mark.parametrize("part", [UNIFORM, SQUARE_GRID, SYMMETRIC_SQUARE], ids=["uniform", "square", "symmetric"])
@pytest.mark.parametrize("s,continuous,vanish,dual", [(0, False, False, False), (1, False, False, False),
                                                      (2, True, True, False), (1, True, False, False),
                                                      (2, True, False, True), (1, True, True, True)])
def test_gram_by_symmetries_is_the_plain_product(monkeypatch, part, s, continuous, vanish, dual):
    """S(40) with the reflection's halves, the transposition's n ≥ m, both or neither (the plain
    Σ C Cᵀ), in one block of rows m and in blocks of 7: equal to round-off, SPD."""
    space = TriangleSpace(part, s, continuous, vanish, dual)
    pi, sigma = ftn._symmetries(space)
    assert pi is not None and (sigma is not None) == (part is not UNIFORM)
    grams = [ftn.partial_gram(space, 40)]
    monkeypatch.setattr(ftn, "chunk_rows", lambda space, n_max: 7)
    for use in ((pi, sigma), (pi, None), (None, sigma), (None, None)):
        monkeypatch.setattr(ftn, "_symmetries", lambda space, use=use: use)
        grams.append(ftn.partial_gram(space, 40))
    plain = grams[-1]
    for G in grams[:-1]:
        assert np.abs(G - plain).max() < 1e-13 * np.abs(plain).max()
    assert np.linalg.eigvalsh(grams[0]).min() > 0


@pytest.mark.parametrize("s,continuous,vanish,dual", FAMILIES)
def test_transposition_swaps_the_frequencies(s, continuous, vanish, dual):
    """σ on a square grid: an involution with μ_mn(φ_σ(g)) = μ_nm(φ_g); none on a 4 × 3 grid."""
    space = TriangleSpace(SYMMETRIC_SQUARE, s, continuous, vanish, dual)
    sigma = transposition(space)
    assert sigma is not None and np.array_equal(sigma[sigma], np.arange(space.dim))
    m = np.arange(1, 15, dtype=float)
    C = ftn.sine_coefficients_chunk(space, m, 14)
    assert np.abs(C[sigma] - C.transpose(0, 2, 1)).max() < 1e-13 * np.abs(C).max()
    assert transposition(TriangleSpace(UNIFORM, s, continuous, vanish, dual)) is None


def test_face_cases_of_the_tetrahedral_study_are_symmetric():
    """Every triangle space of the tet face at k = 2 on a uniform grid (the DAG's) takes the halves."""
    part = TensorPartition(np.linspace(0, 1, 4), np.linspace(0, 1, 4))
    for case in ("T3", "R5.2", "T4", "R5.4", "T5", "DUAL", "PWLIN-T6"):
        space = case_space(case, 2, part, SQUARE_TRIG)
        assert isinstance(space, TriangleSpace) and reflection(space) is not None, case


def test_halves_need_consecutive_frequencies():
    from infsup_contact.discretization.face.symmetry import ReflectedGram
    from infsup_contact.errors import InputError

    space = TriangleSpace(UNIFORM, 1, True, False)
    acc = ReflectedGram(reflection(space))
    with pytest.raises(InputError, match="m/n"):
        acc.add(np.zeros((space.dim, 2, 3)), np.array([1.0, 3.0]), np.arange(1.0, 4.0))


@pytest.mark.parametrize("part", [UNIFORM, SQUARE_GRID, SYMMETRIC_SQUARE], ids=["uniform", "square", "symmetric"])
@pytest.mark.parametrize("s,continuous,vanish,dual", [(0, False, False, False), (2, True, True, False),
                                                      (1, True, False, True)])
def test_the_richardson_sums_grow_by_increments(monkeypatch, part, s, continuous, vanish, dual):
    """S(n) + (terms with max(m, n') > n, up to 2n) = S(2n) summed afresh, to round-off, with every
    symmetry on or off and in blocks of 5 rows that straddle n (the loop's n0, 2n0, 4n0)."""
    space = TriangleSpace(part, s, continuous, vanish, dual)
    monkeypatch.setattr(ftn, "chunk_rows", lambda space, n_max: 5)
    for use in (ftn._symmetries(space), (None, None)):
        monkeypatch.setattr(ftn, "_symmetries", lambda space, use=use: use)
        partial = ftn.incremental_partial_gram(space)
        for n in (12, 24, 48):
            fresh = ftn.partial_gram(space, n)
            assert np.abs(partial(n) - fresh).max() < 1e-13 * np.abs(fresh).max()


def _grid_symmetries():
    """π (point reflection) and σ (transposition) of a 5 × 5 grid of dofs, plus two dofs at the
    centre that π fixes and σ swaps: every kind of orbit (σ-pairs of π-pairs with either sign,
    π-pairs σ fixes or maps onto their partner, π-fixed dofs σ swaps or fixes)."""
    idx = np.arange(25).reshape(5, 5)
    pi = np.concatenate([idx[::-1, ::-1].ravel(), [25, 26]])
    sigma = np.concatenate([idx.T.ravel(), [26, 25]])
    return pi, sigma


def test_klein_gram_is_the_reflected_gram_plus_its_transpose():
    """KleinGram's S against ReflectedGram's H + H[σ, σ] from the same coefficients (any: the
    identities hold for every H), to round-off; both are SPD sums of the same columns."""
    from infsup_contact.discretization.face.symmetry import KleinGram, ReflectedGram

    pi, sigma = _grid_symmetries()
    coeffs = np.random.default_rng(5).standard_normal((pi.size, 6, 8))
    m, n = np.arange(3.0, 9.0), np.arange(2.0, 10.0)
    klein, halves = KleinGram(pi, sigma), ReflectedGram(pi)
    assert sorted(klein.even_rows) == sorted(halves.even_rows)
    for acc in (klein, halves):
        acc.add(coeffs[acc.even_rows], m, n)
    H = halves.gram()
    expected = H + H[np.ix_(sigma, sigma)]
    S = klein.gram()
    assert np.abs(S - expected).max() <= 1e-13 * np.abs(expected).max()
    assert np.abs(S - S.T).max() <= 1e-13 * np.abs(S).max()
    assert sum(G.shape[0] for G in klein.G.values()) == klein.even_rows.size + klein.rep.size  # every coordinate once


def test_klein_gram_refuses_a_transposition_that_does_not_commute():
    from infsup_contact.discretization.face.symmetry import KleinGram
    from infsup_contact.errors import InputError

    pi, sigma = _grid_symmetries()
    wrong = sigma.copy()
    wrong[[0, 1, 5]] = wrong[[1, 5, 0]]  # not an involution any more
    with pytest.raises(InputError, match="sigma"):
        KleinGram(pi, wrong)
