"""One H-Gram route at every size (face/norms/tensor.py, cellwise.py): the exponential sum in the
parity blocks against the reference route (the direct double sums, whole matrix), on every face
space family the route serves, on both sides of the former size gate, and the blocks it passes on
to the pencils (la/face_parity.py ParityGram, la/reflection.py usable).

The tolerance: the exponential sum's weights are within EXP_SUM_RTOL = 1e-13 relative of
1/(π√(m² + n²)), so each partial sum is within that factor of the direct one in the Loewner order;
the Richardson combination R = S(2n) + (S(2n) − S(n))/(2^p − 1) (twice) multiplies the bound by at
most (1 + 2/3)² < 3, and the rest is round-off of sums of dim ~10³ terms: 1e-11 relative in the
Gram's own metric (the generalized eigenvalues of (G_new − G_ref, G_ref)), far below any stated
truncation error (1e-6)."""
import numpy as np
import pytest
import scipy.linalg as sla

from infsup_contact.discretization.face.norms import cellwise as fc
from infsup_contact.discretization.face.norms import tensor as fn
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.discretization.segment.multipliers import make_space
from infsup_contact.discretization.face.spaces.tensor import FaceSpace
from infsup_contact.discretization.spaces import registry
from infsup_contact.solvers.symmetry import reflection_split

LOEWNER_RTOL = 1e-11


def _space(case, k, n):
    xs = np.linspace(0.0, 1.0, n + 1)
    return registry.case_space(case, k, TensorPartition(xs, xs), SQUARE)


def _loewner_distance(G, G_ref):
    """max |λ| of (G − G_ref) x = λ G_ref x: the relative change of any pencil's eigenvalue."""
    return float(np.max(np.abs(sla.eigh(G - G_ref, G_ref, eigvals_only=True))))


@pytest.mark.parametrize("case,k,n", [("T3", 1, 6), ("R5.2", 1, 7), ("R5.4", 2, 5), ("T3", 2, 5),
                                      ("DUAL", 2, 5), ("R5.2", 2, 4)])
def test_tensor_spaces_new_route_equals_the_reference(case, k, n):
    """Hexahedra's tensor face spaces, k = 1, 2: the same levels (n_max, stated error to round-off),
    G within LOEWNER_RTOL of the direct sums, the parity blocks handed on."""
    space = _space(case, k, n)
    G, info = fn.gram_h_face(space)
    G_ref, info_ref = fn.gram_h_face(space, reference=True)
    assert info["n_max"] == info_ref["n_max"] and info["n_start"] == info_ref["n_start"]
    assert info["nmax_rel_error"] == pytest.approx(info_ref["nmax_rel_error"], rel=1e-6)
    assert _loewner_distance(G, G_ref) < LOEWNER_RTOL
    assert "parity" in info and "parity" not in info_ref


@pytest.mark.parametrize("case", ["DUAL-Q9", "TDUAL-Q8", "PWLIN-Q9", "DUAL-Q9-ALL", "TDUAL-Q9"])
def test_cellwise_spaces_new_route_equals_the_reference(case):
    """The cellwise face spaces (QUAD9 dual and standard, HEX20's QUAD8 dual) likewise."""
    space = _space(case, 2, 4)
    G, info = fc.gram_h_cellwise(space)
    G_ref, info_ref = fc.gram_h_cellwise(space, reference=True)
    assert info["n_max"] == info_ref["n_max"]
    assert _loewner_distance(G, G_ref) < LOEWNER_RTOL
    assert "parity" in info


@pytest.mark.parametrize("n", [19, 20])
def test_both_sides_of_the_former_gate(n):
    """dim 38² = 1,444 and 40² = 1,600 (the exponential sum used to start above 1,500): the same G
    as the direct sums on either side; the long-series levels (start, cap) still switch at 1,500,
    so n_max and the stated error stay those of the route before. Two levels (rtol, n_cap) keep
    the direct reference cheap."""
    f = make_space(np.linspace(0, 1, n + 1), 1, False, False)   # discontinuous P1: 2n per direction
    space = FaceSpace(f, f, TensorPartition(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1)))
    assert (space.dim > fn.LONG_SERIES_MIN_DIM) == (n == 20)
    n0 = fn.start_level(max(16, 4 * n), 2.0, space.dim)
    G, info = fn.gram_h_face(space, rtol=1.0, n_cap=2 * n0)
    G_ref, info_ref = fn.gram_h_face(space, rtol=1.0, n_cap=2 * n0, reference=True)
    assert info["n_max"] == info_ref["n_max"] == 2 * n0
    assert _loewner_distance(G, G_ref) < LOEWNER_RTOL


@pytest.mark.parametrize("case,k,n", [("R5.2", 2, 4), ("DUAL-Q9", 2, 4), ("T3", 1, 6)])
def test_the_summed_blocks_are_the_split_of_the_assembled_gram(case, k, n):
    """ParityGram.in_bases (the blocks in the reflections' split, a signed gather) equals the
    split of the assembled G (ReflectionSplit.blocks) to round-off: the pencils may take them."""
    space = _space(case, k, n)
    G, info = SQUARE.gram(space, "H")
    split = reflection_split(space, SQUARE.quadrature(space.breakpoints, 2 * k)[0])
    assert split is not None and len(split.bases) == 4
    given = info["parity"].in_bases(split.bases)
    *resplit, distance = split.blocks(G)
    assert distance < 1e-13
    for a, b in zip(given, resplit):
        assert np.abs(a - b).max() <= 1e-14 * np.abs(G).max()


def test_other_bases_are_refused():
    """A basis that is not a signed permutation of one component's (here: two components merged
    and a column rotated) gets None: the caller splits G itself."""
    space = _space("R5.2", 2, 4)
    _, info = SQUARE.gram(space, "H")
    parity = info["parity"]
    import scipy.sparse as sp
    merged = sp.hstack([parity.bases[0], parity.bases[1]]).tocsr()
    assert parity.in_bases([merged, parity.bases[2], parity.bases[3]]) is None
    Q = parity.bases[0].toarray()
    Q[:, :2] = Q[:, :2] @ np.array([[0.6, -0.8], [0.8, 0.6]])
    assert parity.in_bases([sp.csr_matrix(Q), *parity.bases[1:]]) is None
    assert all(np.array_equal(a, b) for a, b in zip(parity.in_bases(parity.bases), parity.blocks))


def test_the_blocks_in_their_own_bases_are_copies_and_a_signed_permutation_is_gathered():
    """in_bases of the Gram's own bases: the blocks' entries, bit for bit, in new arrays (a caller
    may factorize them in place); a basis with columns swapped and one negated: the block with
    those rows and columns swapped and negated, exactly."""
    import scipy.sparse as sp

    _, info = SQUARE.gram(_space("R5.2", 2, 4), "H")
    parity = info["parity"]
    own = parity.in_bases(parity.bases)
    for a, b in zip(own, parity.blocks):
        assert np.array_equal(a, b) and not np.shares_memory(a, b)
        a[0, 0] += 1.0
    assert not any(np.array_equal(a, b) for a, b in zip(own, parity.blocks))   # the Gram kept its own
    Q = parity.bases[1].toarray()
    p = np.arange(Q.shape[1])
    p[[0, 1]] = [1, 0]
    sign = np.ones(Q.shape[1])
    sign[2] = -1.0
    moved = parity.in_bases([parity.bases[0], sp.csr_matrix(Q[:, p] * sign), *parity.bases[2:]])
    assert np.array_equal(moved[1], parity.blocks[1][np.ix_(p, p)] * np.outer(sign, sign))


@pytest.mark.parametrize("case,k,n", [("R5.2", 2, 4), ("T3", 1, 6), ("DUAL", 2, 5)])
def test_the_l2_blocks_are_the_split_of_the_l2_gram(case, k, n):
    """The L² Gram's parity blocks (tensor.l2_parity, Kronecker products of the 1D blocks) equal the
    split of G_x ⊗ G_y to round-off."""
    space = _space(case, k, n)
    G, info = SQUARE.gram(space, "L2")
    split = reflection_split(space, SQUARE.quadrature(space.breakpoints, 2 * k)[0])
    given = info["parity"].in_bases(split.bases)
    *resplit, distance = split.blocks(G)
    for a, b in zip(given, resplit):
        assert np.abs(a - b).max() <= 1e-14 * np.abs(G).max()
