"""The nested-dissection order with Γ last: a permutation, Γ last, exact S, low fill."""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.csgraph  # noqa: F401  (sp.csgraph)
import scipy.sparse.linalg as spla

from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.models.membranes import displacement_space, laplace_stiffness, side_operator
from infsup_contact.la.schur import _gamma_last_lu, schur_from_lu
from infsup_contact.models.contract import schur_by_solves
from infsup_contact.discretization.segment.meshes import mesh_pair
from infsup_contact.la.graph import Graph, Twins
from infsup_contact.la.ordering import nested_dissection_gamma_last

SUPERLU_SPD = dict(diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))


def _stiffness(family, n, k):
    """K on the free dofs of Ω2 with the Γ dofs last (as ``interface.side_operator``)."""
    fes = displacement_space(mesh_pair(family, n, n)[1], k)
    trace = SEGMENT.trace(fes)
    free_mask = np.array(fes.FreeDofs(), dtype=bool)
    is_gamma = np.zeros(fes.ndof, dtype=bool)
    is_gamma[trace.gamma_dofs] = True
    free = np.concatenate([np.flatnonzero(free_mask & ~is_gamma), trace.gamma_dofs])
    return laplace_stiffness(fes)[free][:, free].tocsc(), len(trace.gamma_dofs)


def _grid_laplacian(nx, ny):
    """5-point Laplacian on an nx × ny grid (no mesh, no NGSolve)."""
    tx = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(nx, nx))
    ty = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(ny, ny))
    return (sp.kron(sp.identity(ny), tx) + sp.kron(ty, sp.identity(nx))).tocsc()


def _assert_gamma_last_permutation(order, n, n_gamma):
    assert order.shape == (n,)
    assert np.array_equal(np.sort(order), np.arange(n))
    assert np.array_equal(order[n - n_gamma:], np.arange(n - n_gamma, n))


@pytest.mark.parametrize("family", ["structured", "perturbed", "unstructured"])
@pytest.mark.parametrize("k", [1, 2, 3])
def test_order_is_a_permutation_with_gamma_last(family, k):
    K, ng = _stiffness(family, 9, k)
    _assert_gamma_last_permutation(nested_dissection_gamma_last(K, ng), K.shape[0], ng)


@pytest.mark.parametrize("family,n", [("structured", 8), ("perturbed", 7), ("unstructured", 6)])
@pytest.mark.parametrize("k", [1, 2, 3])
def test_schur_from_one_factorization_equals_solve_route(family, n, k):
    for mesh in mesh_pair(family, n, n):
        side = side_operator(mesh, k)
        S_ref = schur_by_solves(side)
        assert np.allclose(side.schur, S_ref, rtol=1e-11, atol=1e-11 * np.abs(S_ref).max())


def test_superlu_keeps_the_given_order():
    """NATURAL + symmetric mode + no pivoting: SuperLU permutes nothing, Γ stays last."""
    K, ng = _stiffness("unstructured", 10, 2)
    lu = _gamma_last_lu(K, ng)
    n = K.shape[0]
    assert np.array_equal(lu.lu.perm_c, np.arange(n))
    assert np.array_equal(lu.lu.perm_r, np.arange(n))
    b = np.random.default_rng(0).standard_normal(n)
    assert np.allclose(K @ lu.solve(b), b, rtol=1e-10, atol=1e-10)
    D = K[:-ng, :-ng].toarray()
    S_dense = K[-ng:, -ng:].toarray() - K[-ng:, :-ng].toarray() @ np.linalg.solve(D, K[:-ng, -ng:].toarray())
    assert np.allclose(schur_from_lu(lu, ng), S_dense, rtol=1e-11, atol=1e-11 * np.abs(S_dense).max())


@pytest.mark.parametrize("family", ["structured", "unstructured"])
def test_fill_close_to_superlu_minimum_degree(family):
    """nnz(L) in our order (Γ last) vs SuperLU's own MMD order of the whole matrix."""
    K, ng = _stiffness(family, 32, 2)
    order = nested_dissection_gamma_last(K, ng)
    ours = spla.splu(K[order][:, order].tocsc(), permc_spec="NATURAL", **SUPERLU_SPD).L.nnz
    mmd = spla.splu(K, permc_spec="MMD_AT_PLUS_A", **SUPERLU_SPD).L.nnz
    assert ours < 1.5 * mmd


def test_beats_no_reordering_on_a_grid():
    """A plain 5-point grid graph (no mesh): far less fill than the natural band order."""
    K = _grid_laplacian(60, 60)
    order = nested_dissection_gamma_last(K, 60)
    _assert_gamma_last_permutation(order, K.shape[0], 60)
    ours = spla.splu(K[order][:, order].tocsc(), permc_spec="NATURAL", **SUPERLU_SPD).L.nnz
    band = spla.splu(K, permc_spec="NATURAL", **SUPERLU_SPD).L.nnz
    assert ours < 0.6 * band


@pytest.mark.parametrize("leaf_size", [1, 4, 1000])
def test_leaf_size_extremes(leaf_size):
    K, ng = _stiffness("perturbed", 6, 2)
    _assert_gamma_last_permutation(nested_dissection_gamma_last(K, ng, leaf_size=leaf_size), K.shape[0], ng)


def test_disconnected_interior_and_formats():
    """Several components, an empty row, a COO input, no Γ at all, only Γ."""
    K = sp.block_diag([_grid_laplacian(7, 5), _grid_laplacian(3, 3), sp.identity(4),
                       sp.csr_matrix((2, 2))]).tocoo()
    n = K.shape[0]
    for ng in (0, 5, n):
        _assert_gamma_last_permutation(nested_dissection_gamma_last(K, ng, leaf_size=4), n, ng)
    csr, csc = (nested_dissection_gamma_last(K.asformat(f), 5) for f in ("csr", "csc"))
    assert np.array_equal(csr, csc)


@pytest.mark.parametrize("seed", range(5))
def test_non_symmetric_pattern_still_gives_a_permutation(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(50, 300))
    K = sp.random(n, n, density=0.03, random_state=seed, format="csr")
    K.indices, K.indptr = K.indices.astype(np.int64), K.indptr.astype(np.int64)
    ng = int(rng.integers(0, n // 4))
    for leaf_size in (1, 24):
        _assert_gamma_last_permutation(nested_dissection_gamma_last(K, ng, leaf_size=leaf_size), n, ng)


def test_bfs_levels_are_graph_distances():
    """The levels read off scipy's BFS order (multi-source) are the true distances."""
    K, ng = _stiffness("unstructured", 7, 2)
    m = K.shape[0] - ng
    graph = Graph(K, m)
    starts = np.array([3, m // 2, m - 1])
    nodes, level = graph.bfs(starts)
    interior = K[:m, :m].tocsr()
    interior.data[:] = 1.0                            # the pattern, stored zeros included
    interior = interior[graph.label][:, graph.label]
    dist = sp.csgraph.shortest_path(interior, unweighted=True, indices=starts).min(axis=0)
    assert np.array_equal(np.sort(nodes), np.arange(m))
    assert np.array_equal(level, dist[nodes])


def test_twins_of_cubic_elements_share_their_neighbourhoods():
    """P3: the two dofs inside an edge are twins, found and expanded consecutively."""
    K, ng = _stiffness("unstructured", 6, 3)
    m = K.shape[0] - ng
    twins = Twins.find(K, m)
    assert twins is not None and twins.count < m
    pattern = K.tocsc()
    rows = [frozenset(pattern.indices[pattern.indptr[i]:pattern.indptr[i + 1]]) for i in range(m)]
    klass = np.cumsum(twins.first) - 1
    for c in range(twins.count):
        members = twins.members[klass == c]
        assert len({rows[i] for i in members}) == 1 and all(i in rows[i] for i in members)
    sizes = np.bincount(klass)
    assert set(sizes) <= {1, 2} and (sizes == 2).sum() > 0
    order = nested_dissection_gamma_last(K, ng)
    where = np.empty(len(order), dtype=int)
    where[order] = np.arange(len(order))
    for c in np.flatnonzero(sizes == 2):
        assert np.ptp(where[twins.members[klass == c]]) == 1
    K2, ng2 = _stiffness("unstructured", 6, 2)                 # P2: no twins worth it
    assert Twins.find(K2, K2.shape[0] - ng2) is None


def test_rejects_bad_arguments():
    K = _grid_laplacian(3, 3)
    with pytest.raises(ValueError):
        nested_dissection_gamma_last(K, 10)
    with pytest.raises(ValueError):
        nested_dissection_gamma_last(K[:, :5], 1)
    with pytest.raises(ValueError):
        nested_dissection_gamma_last(K, 1, leaf_size=0)
