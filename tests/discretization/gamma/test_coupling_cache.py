"""The trace basis values are sparsified once per point set (``GammaTrace.cached_sparse_basis``):
a sweep of multiplier spaces shares one CSR matrix, the couplings equal bit for bit the route that
sparsified the dense values chunk by chunk for every space, and ``forget_cached`` drops both the
dense and the CSR values (the benchmark's fresh state)."""
import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.discretization.gamma import coupling
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.spaces.registry import case_space, ids_valid_for, space_ids
from infsup_contact.errors import InputError
from infsup_contact.models import make_model

SETUPS = [("membranes3d", {"element": "hex"}, 3, 2), ("membranes3d", {"element": "tet"}, 2, 2),
          ("membranes", {}, 5, 2)]


def _sides(model, kw, n, k):
    m = make_model(model)
    return [m.side_operator(m.subdomain_mesh("structured", n + i, i + 1, **kw), k) for i in range(2)]


def _reference(trace, space, k):
    """The former route: the dense basis values, each chunk sparsified again for every space."""
    x, w = trace.gamma.coupling_quadrature(trace, space, k + space.degree)
    phi = trace.gamma.trace_basis(trace, x)
    out = np.zeros((space.dim, phi.shape[1]))
    for rows in coupling._chunks(len(w), space.dim):
        mu = sp.csr_matrix(space.evaluate(x[rows]) * w[rows, None])
        out += (mu.T @ sp.csr_matrix(phi[rows])).toarray()
    return out


@pytest.fixture(scope="module", params=SETUPS, ids=lambda s: f"{s[0]}-{s[1].get('element', '2d')}")
def setup(request):
    model, kw, n, k = request.param
    sides = _sides(model, kw, n, k)
    gamma = sides[0].trace.gamma
    part = gamma.multiplier_partition(*(s.trace.partition for s in sides))
    spaces = []
    for case in ids_valid_for(k, space_ids(gamma.dim)):
        try:
            spaces.append(case_space(case, k, part, gamma))
        except InputError:  # a space the registry refuses on this Γ (e.g. a dual basis without weights)
            pass
    assert len(spaces) >= 3
    return sides, spaces, k


@pytest.mark.parametrize("chunk", [None, 256])
def test_couplings_are_the_per_space_sparsification_bit_for_bit(setup, chunk, monkeypatch):
    sides, spaces, k = setup
    if chunk is not None:  # many chunks: the CSR row slices must equal the sparsified dense slices
        monkeypatch.setattr(coupling, "_CHUNK_ENTRIES", chunk)
    for side in sides:
        side.forget_cached()
        for space in spaces:
            B = coupling_matrix(side.trace, space, k)
            assert B.shape == (space.dim, len(side.trace.gamma_dofs))
            assert np.array_equal(B, _reference(side.trace, space, k))


def test_a_sweep_sparsifies_each_point_set_once_and_forget_drops_both(setup, monkeypatch):
    sides, spaces, k = setup
    side = sides[1]
    side.forget_cached()
    made = []
    csr = sp.csr_matrix
    # the trace's dense values are read-only (cached_basis), the multiplier values are not
    monkeypatch.setattr(sp, "csr_matrix", lambda a, *r, **kw: made.append(
        isinstance(a, np.ndarray) and not a.flags.writeable) or csr(a, *r, **kw))
    for space in spaces + spaces:
        coupling_matrix(side.trace, space, k)
    n_sets = len(side.trace.sparse_cache)
    assert n_sets >= 1
    # one CSR of the trace values per point set, not one per space; an interface with a
    # sparse_trace_basis (the face) makes it without the dense values
    from infsup_contact.discretization.gamma.interface import Interface

    own_sparse = type(side.trace.gamma).sparse_trace_basis is not Interface.sparse_trace_basis
    dense_made = 0 if own_sparse else n_sets
    assert len(side.trace.basis_cache) == dense_made and sum(made) == dense_made
    x, _ = side.trace.gamma.coupling_quadrature(side.trace, spaces[0], k + spaces[0].degree)
    assert side.trace.cached_sparse_basis(x) is side.trace.cached_sparse_basis(x)
    assert np.array_equal(side.trace.cached_sparse_basis(x).toarray(), side.trace.gamma.trace_basis(side.trace, x))
    side.forget_cached()
    assert not side.trace.basis_cache and not side.trace.sparse_cache


@pytest.mark.parametrize("model, kw, n, k", [("membranes3d", {"element": "hex"}, 3, 2),
                                             ("membranes3d", {"element": "tet"}, 2, 1), ("membranes", {}, 4, 2)])
def test_both_sides_couplings_share_the_multiplier_values_bit_for_bit(model, kw, n, k, monkeypatch):
    """coupling_matrices on a matching pair evaluates μ once per chunk for both sides and gives
    each side's coupling_matrix bit for bit (dense, sparse, a longer rule); a non-matching pair's
    rules differ and each side keeps its own values."""
    m = make_model(model)
    calls = []
    real = coupling.weighted_values
    monkeypatch.setattr(coupling, "weighted_values", lambda *a: calls.append(1) or real(*a))
    for sizes, shared in (((n, n), True), ((n, n + 1), False)):
        sides = [m.side_operator(m.subdomain_mesh("structured", sizes[i], i + 1, **kw), k) for i in range(2)]
        gamma = sides[0].trace.gamma
        part = gamma.multiplier_partition(*(s.trace.partition for s in sides))
        for case in ids_valid_for(k, space_ids(gamma.dim))[:4]:
            space = case_space(case, k, part, gamma)
            for extra, sparse in ((0, False), (2, True), (6, False)):
                calls.clear()
                both = coupling.coupling_matrices([s.trace for s in sides], space, k, extra, sparse)
                n_both = len(calls)
                calls.clear()
                alone = [coupling_matrix(s.trace, space, k, extra, sparse) for s in sides]
                assert n_both == (len(calls) // 2 if shared else len(calls)) and n_both >= 1
                for a, b in zip(both, alone):
                    if sparse:
                        assert a.format == b.format == "csr"
                        a, b = a.toarray(), b.toarray()
                    assert a.dtype == b.dtype and np.array_equal(a, b) and np.array_equal(np.signbit(a), np.signbit(b))
