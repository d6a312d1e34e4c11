"""The sandwiches B X Bᵀ in parity blocks (la/parity_sandwich.py): on an equivariant B the blocks
are Q_aᵀ (B X Bᵀ) Q_a and the bound on the dropped part is at round-off; on a B that is not
equivariant the bound holds (≥ the dropped part, computed densely) and a large one refuses
(None); combining terms keeps both properties."""
import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.discretization.gamma.symmetry import group_elements, isotypic_bases
from infsup_contact.la import parity_sandwich as ps
from infsup_contact.la import reflection


def _grid_reflections(n):
    """x → n−1−x and y → n−1−y on an n × n grid of points, as permutations of the points."""
    idx = np.arange(n * n).reshape(n, n)
    return idx[::-1, :].ravel(), idx[:, ::-1].ravel()


def _average(M, rows, cols):
    """Σ_b P_b M P'_bᵀ / |G| over the group elements (rows, cols): an equivariant M."""
    out = np.zeros_like(M)
    for r, c in zip(rows, cols):
        out[np.ix_(r, c)] += M
    return out / len(rows)


def _problem(seed=0, m_side=7, n_side=9):
    """(B dense m × n, equivariant and banded-sparse; X SPD invariant; Q bases; ((P_c, X_c), ...))."""
    rng = np.random.default_rng(seed)
    rows, cols = group_elements(_grid_reflections(m_side)), group_elements(_grid_reflections(n_side))
    m, n = m_side ** 2, n_side ** 2
    B = rng.standard_normal((m, n)) * (rng.random((m, n)) < 0.15)
    B = _average(B, rows, cols)
    A = rng.standard_normal((n, n))
    X = _average(A @ A.T / n + np.eye(n), cols, cols)
    X = 0.5 * (X + X.T)
    Q = isotypic_bases(_grid_reflections(m_side))
    P = isotypic_bases(_grid_reflections(n_side))
    parts = tuple((Pc.tocsr(), 0.5 * (Pc.T @ X @ Pc + (Pc.T @ X @ Pc).T)) for Pc in P)
    return B, X, Q, parts


def _exact_dropped(B, X, Q, op):
    """‖Qᵀ B X Bᵀ Q − diag(blocks)‖_F, dense."""
    Qm = np.hstack([q.toarray() for q in Q])
    full = Qm.T @ B @ X @ B.T @ Qm
    start = 0
    for b in op.blocks:
        e = start + b.shape[0]
        full[start:e, start:e] -= b
        start = e
    return float(np.linalg.norm(full))


def test_equivariant_coupling_gives_the_blocks_of_the_whole_sandwich():
    B, X, Q, parts = _problem()
    op = ps.parity_sandwich(sp.csr_matrix(B), parts, Q)
    assert op is not None and len(op.blocks) == 4
    assert sum(b.shape[0] for b in op.blocks) == B.shape[0]
    S = B @ X @ B.T
    *blocks, distance = reflection.ReflectionSplit(None, Q).blocks(S)
    for mine, whole in zip(op.blocks, blocks):
        np.testing.assert_allclose(mine, whole, rtol=0, atol=1e-12 * np.linalg.norm(S))
    assert op.distance <= 1e-13 and distance <= 1e-13
    np.testing.assert_allclose(np.asarray(op), S, rtol=0, atol=1e-12 * np.linalg.norm(S))
    assert reflection.ReflectionSplit(None, Q).blocks(op)[-1] == op.distance


@pytest.mark.parametrize("size", [1e-15, 1e-13, 1e-10, 1e-7])
def test_the_bound_covers_what_a_non_equivariant_coupling_drops(size):
    B, X, Q, parts = _problem(seed=1)
    noise = np.random.default_rng(2).standard_normal(B.shape) * (B != 0)
    Bp = B + size * np.abs(B).max() * noise
    ps_relative = ps.RELATIVE_DROP
    op = _unchecked(Bp, parts, Q)
    exact = _exact_dropped(Bp, X, Q, op)
    assert op.dropped >= exact > 0.0
    assert op.dropped <= 1e4 * exact  # a bound, not a blanket
    refused = ps.parity_sandwich(sp.csr_matrix(Bp), parts, Q) is None
    assert refused == (op.distance > ps_relative)
    assert refused == (size >= 1e-10)  # the bound grows with the perturbation: refused from 1e-10 here


def _unchecked(B, parts, Q):
    """parity_sandwich with any bound accepted."""
    saved = ps.RELATIVE_DROP
    try:
        ps.RELATIVE_DROP = np.inf
        return ps.parity_sandwich(sp.csr_matrix(B), parts, Q)
    finally:
        ps.RELATIVE_DROP = saved


def test_combined_terms_keep_their_bound():
    B1, X1, Q, parts1 = _problem(seed=3)
    B2, X2, _, parts2 = _problem(seed=4)
    noise = np.random.default_rng(5).standard_normal(B1.shape) * (B1 != 0)
    B1 = B1 + 1e-9 * np.abs(B1).max() * noise
    T1, T2 = _unchecked(B1, parts1, Q), _unchecked(B2, parts2, Q)
    S = ps.combine([T1, T2], (1.0, 4.0))
    whole = B1 @ X1 @ B1.T + B2 @ X2 @ B2.T / 4.0
    Qm = np.hstack([q.toarray() for q in Q])
    full = Qm.T @ whole @ Qm
    start = 0
    for b in S.blocks:
        e = start + b.shape[0]
        np.testing.assert_array_equal(b, b.T)
        full[start:e, start:e] -= b
        start = e
    assert S.dropped >= np.linalg.norm(full)


def test_components_that_do_not_match_are_refused():
    B, X, Q, parts = _problem(seed=6)
    swapped = (parts[1], parts[1], parts[2], parts[3])  # two components onto one part
    assert ps._matching([[sp.csr_matrix(Q[a].T @ B @ P) for P, _ in swapped] for a in range(4)]) is None
    assert ps.parity_sandwich(sp.csr_matrix(B), swapped, Q) is None


def test_the_split_takes_its_tolerance_from_here():
    assert reflection.INVARIANCE_RTOL is ps.INVARIANCE_RTOL and ps.RELATIVE_DROP == ps.INVARIANCE_RTOL / 4
