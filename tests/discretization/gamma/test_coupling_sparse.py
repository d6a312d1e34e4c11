"""The couplings from the spaces' nonzero patterns (``space.local_values``, no dense n_q × dim M
multiplier values) and the face's sparse trace basis (``sparse_trace_basis``, no dense n_q × n_Γ
values) equal, bit for bit, the former route that sparsified the dense values
``csr_matrix(space.evaluate(x) * w)`` chunk by chunk and accumulated ``out += (μᵀ φ).toarray()``:
for every registered space on the segment (1D; membranes and elastic bodies), the tensor face (Q_s products and cellwise
QUAD4/8/9 bases) and the triangulated face (P_s), k = 1, 2, matching and non-matching meshes,
the normal and the longer rules, one chunk and many."""
import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.discretization.gamma import coupling
from infsup_contact.discretization.gamma.coupling import coupling_matrix, weighted_values
from infsup_contact.discretization.spaces.registry import case_space, ids_valid_for, space_ids
from infsup_contact.errors import InputError
from infsup_contact.models import make_model

# (model, mesh kwargs, N1, N2, k, multiplier mesh)
SETUPS = [("membranes3d", {"element": "hex"}, 3, 3, 2, "omega2"),
          ("membranes3d", {"element": "hex"}, 5, 6, 1, "union"),
          ("membranes3d", {"element": "hex"}, 2, 3, 2, "omega1"),
          ("membranes3d", {"element": "tet"}, 2, 3, 2, "union"),
          ("membranes3d", {"element": "tet"}, 3, 3, 1, "omega2"),
          ("membranes", {}, 5, 6, 2, "union"),
          ("elastic", {}, 4, 5, 2, "union")]


def _dense_route(trace, space, k, extra_degree=0):
    """The former :func:`coupling_matrix`: dense trace and multiplier values, sparsified."""
    x, w = trace.gamma.coupling_quadrature(trace, space, k + space.degree + extra_degree)
    phi = sp.csr_matrix(trace.gamma.trace_basis(trace, x))
    out = np.zeros((space.dim, phi.shape[1]))
    for rows in coupling._chunks(len(w), space.dim):
        mu = sp.csr_matrix(space.evaluate(x[rows]) * w[rows, None])
        out += (mu.T @ phi[rows]).toarray()
    return out


# the tetrahedra's faces have the most quadrature points: their chunk-by-chunk runs below take
# longest, so they start first under xdist (tests/conftest.py)
@pytest.fixture(scope="module", params=[pytest.param(s, marks=pytest.mark.slow_first) if s[1].get("element") == "tet"
                                        else s for s in SETUPS],
                ids=lambda s: f"{s[0]}-{s[1].get('element', '2d')}-{s[2]}:{s[3]}-k{s[4]}-{s[5]}")
def setup(request):
    model, kw, n1, n2, k, mm = request.param
    m = make_model(model)
    build = getattr(m, "mesh", None)
    if build is None:
        from infsup_contact.discretization.segment.meshes import subdomain_mesh as build
    sides = [m.side_operator(build("structured", n, i + 1, **kw), k) for i, n in enumerate((n1, n2))]
    gamma = sides[0].trace.gamma
    part = gamma.multiplier_partition(*(s.trace.partition for s in sides), mm)
    spaces = []
    for case in ids_valid_for(k, space_ids(gamma.dim)):
        try:
            spaces.append(case_space(case, k, part, gamma))
        except InputError:  # a space the registry refuses on this Γ
            pass
    assert len(spaces) >= 3
    return sides, spaces, k


def test_every_space_has_a_pattern_equal_to_its_dense_values(setup):
    sides, spaces, k = setup
    trace = sides[0].trace
    for space in spaces:
        x, w = trace.gamma.coupling_quadrature(trace, space, k + space.degree)
        vals, dofs = space.local_values(x)
        assert vals.shape == dofs.shape and len(vals) == len(x)
        live = np.where(dofs >= 0, dofs, space.dim)  # dead → a column past the end
        assert np.all(np.diff(np.sort(live, axis=1), axis=1)[np.sort(live, axis=1)[:, 1:] < space.dim] > 0)
        dense = np.zeros((len(x), space.dim + 1))
        dense[np.arange(len(x))[:, None], live] = vals
        assert np.array_equal(dense[:, :-1], space.evaluate(x))
        mu, ref = weighted_values(space, x, w), sp.csr_matrix(space.evaluate(x) * w[:, None])
        assert mu.has_canonical_format and ref.has_canonical_format
        for a in ("indptr", "indices", "data"):
            assert np.array_equal(getattr(mu, a), getattr(ref, a)), (type(space).__name__, a)


@pytest.mark.parametrize("extra_degree", [0, 2, 6])
@pytest.mark.parametrize("chunk", [None, 4096])
def test_couplings_equal_the_dense_route_bit_for_bit(setup, extra_degree, chunk, monkeypatch):
    sides, spaces, k = setup
    if chunk is not None:  # several chunks: the accumulation order must be the same
        monkeypatch.setattr(coupling, "_CHUNK_ENTRIES", chunk)
    for side in sides:
        for space in spaces:
            B = coupling_matrix(side.trace, space, k, extra_degree)
            assert B.shape == (space.dim, len(side.trace.gamma_dofs))
            assert np.array_equal(B, _dense_route(side.trace, space, k, extra_degree)), type(space).__name__


def test_a_space_without_a_pattern_takes_the_dense_route(setup):
    sides, spaces, k = setup

    from infsup_contact.discretization.gamma.protocol import SpaceDefaults

    class DenseOnly(SpaceDefaults):  # the protocol with the default local_values (None: no pattern)
        def __init__(self, space):
            self.s = space
            self.dim, self.degree, self.breakpoints = space.dim, space.degree, space.breakpoints
            self.continuous, self.evaluate = space.continuous, space.evaluate

        @property
        def pieces(self):
            return self.s.pieces

    trace = sides[1].trace
    for space in spaces[:3]:
        assert np.array_equal(coupling_matrix(trace, DenseOnly(space), k), coupling_matrix(trace, space, k))


def test_the_face_trace_basis_is_the_csr_of_its_dense_values(setup):
    sides, spaces, k = setup
    for side in sides:
        trace = side.trace
        for space in spaces[:2]:
            x, _ = trace.gamma.coupling_quadrature(trace, space, k + space.degree + 2)
            phi = trace.gamma.sparse_trace_basis(trace, x)
            if phi is None:  # no sparse route of its own (the segment): the caller converts the dense
                break
            ref = sp.csr_matrix(trace.gamma.trace_values(trace, x))
            assert phi.has_canonical_format and phi.shape == ref.shape
            for a in ("indptr", "indices", "data"):
                assert np.array_equal(getattr(phi, a), getattr(ref, a))
            if k > 1:  # NGSolve's basis is hierarchical for k ≥ 2: no partition of unity
                continue
            # k = 1, the nodal basis: Σ_d φ_d = 1 on the cells whose vertices are all free
            inner = ~trace.gamma.at_boundary(trace.partition, x)
            assert inner.any() and np.allclose(np.asarray(phi.sum(axis=1)).ravel()[inner], 1.0, atol=1e-13)


@pytest.mark.parametrize("extra", [0, 2])
def test_sparse_couplings_and_their_scaling_are_the_dense_ones_bit_for_bit(setup, monkeypatch, extra):
    """The large route's CSR B (``sparse=True``) and its scaled W (kernel.scaled_couplings) hold
    the dense route's entries exactly, with many chunks as with one."""
    from infsup_contact.discretization.gamma.coupling import trace_l2_norms
    from infsup_contact.solvers.kernel import scaled_couplings

    sides, spaces, k = setup
    def five_chunks(n_points, dim):
        made.append(n_points)
        step = -(-n_points // 5)
        return [slice(i, min(i + step, n_points)) for i in range(0, n_points, step)]

    for pieces in (None, 5):  # one chunk (the default size), then five (one point each was 40 s on the tetrahedra)
        made = []
        if pieces:
            monkeypatch.setattr(coupling, "_chunks", five_chunks)
        for space in spaces:
            dense = [coupling_matrix(s.trace, space, k, extra_degree=extra) for s in sides]
            sparse = [coupling_matrix(s.trace, space, k, extra_degree=extra, sparse=True) for s in sides]
            assert all(sp.isspmatrix_csr(B) and np.array_equal(B.toarray(), D) for B, D in zip(sparse, dense))
            rows = [trace_l2_norms(s.trace, k) for s in sides]
            cols = np.linspace(0.5, 2.0, space.dim)
            W = scaled_couplings(sparse, rows, cols)
            assert sp.issparse(W) and np.array_equal(W.toarray(), scaled_couplings(dense, rows, cols))
        assert not pieces or (made and min(made) >= pieces)  # every call chunked, in five


@pytest.mark.parametrize("element,k,n", [("hex", 1, 4), ("hex", 2, 3), ("tet", 2, 3), ("hex20", 2, 3)])
def test_face_trace_norms_from_the_sparse_basis_are_the_dense_sums(element, k, n):
    """trace_l2_norms on the face (from the sparse trace basis) against the dense values' sums
    w @ Φ²: the same sums in another order, to round-off; on Q1 hexahedra also an exact integral:
    the trace dofs are the tensor hats of Γ's N − 1 inner nodes per direction (u = 0 on the lateral
    faces), whose 1D squares integrate to 2h/3, so Σ_d ‖φ_d‖² = (2 (N − 1) h / 3)²."""
    from infsup_contact.solvers.request import MeshOptions
    from infsup_contact.solvers.side_cache import SideCache
    from infsup_contact.models import MODELS

    side = SideCache().pair(MODELS["membranes3d"], "structured", k, n, n, MeshOptions(element=element))[0]
    trace = side.trace
    x, w = trace.gamma.quadrature(trace.partition, 2 * k)
    dense = np.sqrt(w @ trace.gamma.trace_basis(trace, x) ** 2)
    sparse = coupling.trace_l2_norms(trace, k)
    np.testing.assert_allclose(sparse, dense, rtol=1e-14, atol=0)
    if element == "hex" and k == 1:
        assert np.sum(sparse ** 2) == pytest.approx((2.0 * (n - 1) / (3.0 * n)) ** 2, rel=1e-13)
