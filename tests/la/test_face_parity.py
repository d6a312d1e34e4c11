"""The face's H Gram series in the parity blocks of the axis reflections (la/face_parity.py, discretization/face_parity_bases.py):
the sine coefficients' parity, the block route against the whole-matrix route (tensor and
cellwise spaces), and the refusals (a graded partition, an R that does not intertwine)."""
import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.discretization.face.norms import cellwise as fc
from infsup_contact.discretization.face.norms import tensor as fn
from infsup_contact.discretization.face.norms import parity_bases as fpb
from infsup_contact.la import face_parity as fp
from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.segment.norms import sine_coefficients
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition


def _space(case, k, xs):
    part = TensorPartition(xs, xs)
    return registry.case_space(case, k, part, SQUARE)


@pytest.mark.parametrize("case,k", [("R5.2", 2), ("T3", 1), ("R5.4", 2), ("DUAL", 2)])
def test_even_functions_have_odd_sine_indices_only(case, k):
    """sin(mπ(1 − x)) = (−1)^{m+1} sin(mπx): an even function's coefficient vanishes at even m,
    an odd one's at odd m (to round-off), and the two parities span the 1D space."""
    sx = _space(case, k, np.linspace(0.0, 1.0, 8)).factors[0]
    even, odd = fpb.axis_parity(sx)
    assert even.shape[1] + odd.shape[1] == sx.dim
    n = np.arange(1, 41, dtype=float)
    c = sine_coefficients(sx, n)
    scale = np.abs(c).max()
    assert np.abs(even.T @ c[:, 1::2]).max() <= 1e-13 * scale
    assert np.abs(odd.T @ c[:, 0::2]).max() <= 1e-13 * scale
    assert np.abs(even.T @ c[:, 0::2]).max() > 0.1 * scale


@pytest.mark.parametrize("case,k,n", [("T3", 2, 7), ("R5.2", 2, 6), ("R5.4", 2, 6), ("DUAL", 2, 6), ("R5.2", 1, 9)])
def test_tensor_blocks_equal_the_whole_series(monkeypatch, case, k, n):
    """gram_h_face on the parity blocks (the route of every size) is the whole-matrix
    exponential-sum route to round-off, with the same n_max."""
    space = _space(case, k, np.linspace(0.0, 1.0, n + 1))
    G_blocks, info_blocks = fn.gram_h_face(space)
    monkeypatch.setattr(fpb, "tensor_parities", lambda s: None)
    G_whole, info_whole = fn.gram_h_face(space)
    assert info_blocks["n_max"] == info_whole["n_max"]
    assert np.abs(G_blocks - G_whole).max() <= 1e-13 * np.abs(G_whole).max()
    assert np.array_equal(G_blocks, G_blocks.T)


@pytest.mark.parametrize("case", ["DUAL-Q9", "TDUAL-Q8", "PWLIN-Q9", "DUAL-Q9-ALL"])
def test_cellwise_blocks_equal_the_whole_series(monkeypatch, case):
    """The cellwise spaces: R̃_c S_P,c R̃_cᵀ per block, assembled, against R S_P Rᵀ."""
    space = _space(case, 2, np.linspace(0.0, 1.0, 7))
    R, P = fc.projection(space)
    assert fc._parity_route(space, R, P) is not None
    G_blocks, info_blocks = fc.gram_h_cellwise(space)
    monkeypatch.setattr(fc, "_parity_route", lambda *a: None)
    G_whole, info_whole = fc.gram_h_cellwise(space)
    assert info_blocks["n_max"] == info_whole["n_max"]
    assert np.abs(G_blocks - G_whole).max() <= 1e-13 * np.abs(G_whole).max()


def test_a_graded_partition_keeps_the_whole_series(monkeypatch):
    space = _space("R5.2", 1, np.array([0.0, 0.1, 0.35, 0.7, 1.0]))
    assert fpb.tensor_parities(space) is None


def test_an_r_that_does_not_intertwine_is_refused():
    """Q_aᵀ R T_b must vanish for a ≠ b: a perturbed R is refused, the exact one accepted."""
    space = _space("DUAL-Q9", 2, np.linspace(0.0, 1.0, 5))
    R, P = fc.projection(space)
    from infsup_contact.discretization.gamma.symmetry import axis_reflections, isotypic_bases
    bases = isotypic_bases(axis_reflections(space, fc.piece_rule(P.breakpoints, 3)[0]))
    T = fp.tensor_bases(fpb.tensor_parities(P))
    assert fp.intertwined(R, bases, T) is not None
    bad = R.tolil()
    bad[0, 0] += 1e-6 * abs(R).max()
    assert fp.intertwined(sp.csr_matrix(bad), bases, T) is None


def test_assemble_inverts_the_blocks():
    """assemble(Q, [Q_cᵀ G Q_c]) = G for a G commuting with both reflections."""
    space = _space("R5.2", 2, np.linspace(0.0, 1.0, 5))
    T = fp.tensor_bases(fpb.tensor_parities(space))
    rng = np.random.default_rng(0)
    blocks = []
    for Q in T:
        A = rng.standard_normal((Q.shape[1], Q.shape[1]))
        blocks.append(A + A.T)
    G = fp.assemble(T, blocks)
    for Q, B in zip(T, blocks):
        np.testing.assert_allclose(Q.T @ G @ Q, B, atol=1e-13 * np.abs(B).max())
    for a, Qa in enumerate(T):
        for b, Qb in enumerate(T):
            if a != b:
                assert np.abs(Qa.T @ G @ Qb).max() <= 1e-13 * np.abs(G).max()


@pytest.mark.parametrize("case", ["R5.2", "DUAL-Q9"])
def test_deferred_assembly_gives_the_same_gram_when_read(case):
    """Inside deferred_assembly a Gram summed in parity blocks comes as its ParityGram, not
    assembled; read densely (np.asarray, dense) it is bit for bit the eager route's G, read-only,
    assembled once; outside, the eager G."""
    space = _space(case, 2, np.linspace(0.0, 1.0, 6))
    G_eager, info_eager = SQUARE.gram(space, "H")
    assert isinstance(G_eager, np.ndarray) and isinstance(info_eager["parity"], fp.ParityGram)
    with fp.deferred_assembly():
        G_lazy, info_lazy = SQUARE.gram(space, "H")
    assert isinstance(G_lazy, fp.ParityGram) and G_lazy is info_lazy["parity"]
    assert "dense" not in G_lazy.__dict__  # nothing assembled yet
    assert G_lazy.shape == G_eager.shape and G_lazy.nbytes == sum(B.nbytes for B in G_lazy.blocks)
    dense = np.asarray(G_lazy)
    assert np.array_equal(dense, G_eager) and not dense.flags.writeable
    assert fp.dense(G_lazy) is dense and fp.dense(G_eager) is G_eager
    assert info_lazy["n_max"] == info_eager["n_max"]


@pytest.mark.parametrize("case", ["R5.2", "T3"])
def test_the_deferred_l2_gram_is_the_kron_and_its_diagonal_needs_no_matrix(monkeypatch, case):
    """Inside deferred_assembly a tensor space's L² Gram comes in its parity blocks; its diagonal
    (the kernel decision's scaling) is bit for bit that of G_x ⊗ G_y without forming it, its
    dense matrix bit for bit the eager one, its blocks the eager route's parity blocks."""
    space = _space(case, 2, np.linspace(0.0, 1.0, 6))
    G_eager, info_eager = SQUARE.gram(space, "L2")
    with fp.deferred_assembly():
        G_lazy, info_lazy = SQUARE.gram(space, "L2")
    assert isinstance(G_lazy, fn.KronParityGram) and info_lazy["parity"] is G_lazy
    assert {k: v for k, v in info_lazy.items() if k != "parity"} == {k: v for k, v in info_eager.items() if k != "parity"}
    assert np.array_equal(fp.diagonal(G_lazy), np.diag(G_eager)) and "dense" not in G_lazy.__dict__
    assert all(np.array_equal(a, b) for a, b in zip(G_lazy.blocks, info_eager["parity"].blocks))
    assert np.array_equal(np.asarray(G_lazy), G_eager) and np.array_equal(fp.diagonal(G_eager), np.diag(G_eager))


@pytest.mark.parametrize("case,k,n", [("R5.2", 2, 6), ("T5", 2, 7)])
def test_a_levels_blocks_side_by_side_are_the_blocks_one_after_the_other(monkeypatch, case, k, n):
    """parity_blocks runs its parities' columns and its four block products as concurrent tasks
    (one BLAS thread each): on two threads the blocks are those of one thread bit for bit, and
    each block is its own exponential sum's T_cᵀ S T_c of the unsplit series to round-off."""
    space = _space(case, k, np.linspace(0.0, 1.0, n + 1))
    parities = fpb.tensor_parities(space)
    monkeypatch.setenv("MKL_NUM_THREADS", "1")
    serial = fn.partial_gram_blocks(space, 96, parities)
    monkeypatch.setenv("MKL_NUM_THREADS", "2")
    side_by_side = fn.partial_gram_blocks(space, 96, parities)
    assert all(np.array_equal(a, b) for a, b in zip(serial, side_by_side))
    whole = fn.partial_gram(space, 96)
    scale = np.abs(whole).max()
    for T, block in zip(fp.tensor_bases(parities), serial):
        assert np.abs(np.asarray(T.T @ whole @ T) - block).max() <= 1e-13 * scale


@pytest.mark.parametrize("case", ["DUAL-Q9", "TDUAL-Q8", "PWLIN-Q9", "DUAL-Q9-ALL"])
def test_the_deferred_cellwise_l2_gram_is_its_blocks_and_the_dense_one_when_read(case):
    """Inside deferred_assembly a cellwise space's L² Gram comes in the parity blocks of the
    axis reflections, summed from the sparse G: assembled, the blocks give the dense Gram to
    round-off; read, it is the dense Gram bit for bit, its diagonal the same entries."""
    space = _space(case, 2, np.linspace(0.0, 1.0, 6))
    dense, _ = fc.gram_cellwise(space, "L2")
    with fp.deferred_assembly():
        G, info = fc.gram_cellwise(space, "L2")
    assert isinstance(G, fc.SparseParityGram) and info["parity"] is G
    assert sum(Q.shape[1] for Q in G.bases) == space.dim
    assembled = fp.assemble(G.bases, G.blocks)
    assert np.abs(assembled - dense).max() <= 1e-14 * np.abs(dense).max()
    assert np.array_equal(G.diagonal(), np.diag(dense))
    assert np.array_equal(np.asarray(G), dense)


def test_a_cellwise_l2_gram_without_the_reflections_stays_dense(monkeypatch):
    """Where the basis is not mapped onto itself by both reflections the L² Gram stays the dense
    matrix inside deferred_assembly too."""
    space = _space("DUAL-Q9", 2, np.linspace(0.0, 1.0, 6))
    monkeypatch.setattr(fc, "axis_reflections", lambda *a: None)
    with fp.deferred_assembly():
        G, info = fc.gram_cellwise(space, "L2")
    assert isinstance(G, np.ndarray) and "parity" not in info
