"""The face's dense pencils in the reflections' blocks (solvers/spectra.py dense_split_spectra,
solvers/routes.py) with the Gram summed in blocks (face/norms/tensor.py, cellwise.py): the β rows
of the route before (the direct Gram sums, whole pencils) to round-off.

Tolerance: the Gram moves by at most 1e-11 in its own metric (tests/discretization/face/
test_gram_routes.py), so every eigenvalue by that factor; the block eigensolves differ from the
whole one by the round-off of a backward-stable solver, m ε λ_max absolute, which at these
pencils' conditioning (λ_max / λ_min ≲ 1e3) is below 1e-10 relative."""
import functools

import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.discretization.face.norms import cellwise as fc
from infsup_contact.discretization.face.norms import tensor as fn
from infsup_contact.discretization.spaces import registry
from infsup_contact.models import MODELS
from infsup_contact.solvers import spectra, symmetry
from infsup_contact.solvers.infsup import beta_table
from infsup_contact.solvers.request import BetaRequest, MeshOptions

RTOL = 1e-9


def _reference_route(monkeypatch):
    """The route before: direct Gram sums (whole matrices), the dense pencils whole."""
    monkeypatch.setattr(fn, "gram_h_face", functools.partial(fn.gram_h_face, reference=True))
    monkeypatch.setattr(fc, "gram_h_cellwise", functools.partial(fc.gram_h_cellwise, reference=True))
    split_of = symmetry.split_of
    monkeypatch.setattr(symmetry, "split_of",
                        lambda *a, face_only=False, **kw: None if face_only else split_of(*a, **kw))
    monkeypatch.setattr(symmetry, "split_dense_kernel", lambda *a, **kw: None)


@pytest.mark.parametrize("k,n1,n2,cases,element", [
    (2, 4, 4, ("T3", "R5.2", "DUAL-Q9"), "hex"),
    (1, 5, 6, ("R5.4", "T3"), "hex"),
    (2, 3, 3, ("TDUAL-Q8",), "hex20"),
    (1, 3, 3, ("T3", "R5.2"), "tet"),       # Kuhn triangles: the point reflection, two components
])
def test_rows_equal_the_route_before(monkeypatch, k, n1, n2, cases, element):
    request = BetaRequest("structured", k, n1, n2, cases, ("omega2",), ((1.0, 1.0), (1.0, 4.0)), ("H", "L2"),
                          model=MODELS["membranes3d"], mesh=MeshOptions(element=element))
    calls = []
    dense_split = spectra.dense_split_spectra
    monkeypatch.setattr(spectra, "dense_split_spectra", lambda *a, **kw: calls.append(1) or dense_split(*a, **kw))
    new = beta_table(request)
    assert calls, "the dense pencils were not solved in blocks"
    with monkeypatch.context() as m:
        _reference_route(m)
        calls.clear()
        old = beta_table(request)
        assert not calls
    assert len(new) == len(old)
    for a, b in zip(new, old):
        assert (a["case"], a["norm"], a["c2"]) == (b["case"], b["norm"], b["c2"])
        for key in ("kernel_dim", "n_max", "kernel_decision", "dim_M"):
            assert a[key] == b[key], key
        for key in ("beta", "smallest_nonzero", "beta_v1_zero"):
            assert a[key] == pytest.approx(b[key], rel=RTOL, abs=1e-14), key
        assert a["nmax_rel_error"] == pytest.approx(b["nmax_rel_error"], rel=1e-6)
        assert a["gap_over_roundoff"] == pytest.approx(b["gap_over_roundoff"], rel=1e-6)
        assert a["kernel_margin_decades"] == pytest.approx(b["kernel_margin_decades"], rel=1e-9)
        assert (a["kernel_detected"], a["kernel_check"]) == (b["kernel_detected"], b["kernel_check"])


def test_a_pencil_that_is_not_invariant_is_solved_whole():
    """An S with a block across components above INVARIANCE_RTOL: no split (None)."""
    from infsup_contact.discretization.face.shapes.square import SQUARE
    from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition

    xs = np.linspace(0.0, 1.0, 5)
    space = registry.case_space("R5.2", 2, TensorPartition(xs, xs), SQUARE)
    split = symmetry.reflection_split(space, SQUARE.quadrature(space.breakpoints, 4)[0])
    G = SQUARE.gram(space, "L2")[0]
    factors = {"L2": tuple(spectra.gram_factor(B) for B in split.blocks(G)[:-1])}
    S = G @ G
    whole = spectra.spectrum(S, G)
    blocked = spectra.dense_split_spectra(split, S, factors)["L2"]
    assert blocked.beta == pytest.approx(whole.beta, rel=1e-12)
    np.testing.assert_allclose(blocked.bottom, whole.bottom, rtol=1e-12)
    S_bad = S.copy()
    S_bad[0, 1] += 1e-6 * np.abs(S).max()
    S_bad[1, 0] = S_bad[0, 1]
    assert spectra.dense_split_spectra(split, S_bad, factors) is None


@pytest.mark.parametrize("case,k,n1,n2", [("R5.4", 1, 4, 4), ("T3", 2, 3, 4), ("R5.2", 2, 4, 4)])
def test_the_components_kernel_is_the_whole_svds(case, k, n1, n2):
    """split_dense_kernel: the same dimension, error level and margin as coupling_kernel on the
    whole W where it decides (it must, on these symmetric faces: the kernel is the proven one),
    and no decision where modes beyond the proof would be counted (proven understated)."""
    from infsup_contact.discretization.gamma.coupling import coupling_matrix, trace_l2_norms
    from infsup_contact.solvers.kernel import coupling_kernel, scaled_couplings
    from infsup_contact.solvers.side_cache import SideCache

    sides = SideCache().pair(MODELS["membranes3d"], "structured", k, n1, n2, MeshOptions())
    gamma = sides[0].trace.gamma
    g_h = gamma.multiplier_partition(*(s.trace.partition for s in sides), "omega2")
    space = registry.case_space(case, k, g_h, gamma)
    rows = [trace_l2_norms(s.trace, k) for s in sides]
    cols = np.sqrt(np.diag(gamma.gram(space, "L2")[0]))
    W = scaled_couplings([coupling_matrix(s.trace, space, k) for s in sides], rows, cols)
    structural = gamma.proven_kernel(space, k, [s.trace for s in sides],
                                     gamma.trace_sum_dimension(k, *(s.trace.partition for s in sides)))
    split = symmetry.split_of(space, gamma, g_h, k)
    whole = coupling_kernel(W, structural)
    blocked = symmetry.split_dense_kernel(W, split, structural)
    assert blocked is not None
    assert (blocked.dim, blocked.decision) == (whole.dim, whole.decision)
    assert blocked.tol == pytest.approx(whole.tol, rel=1e-12)
    assert blocked.margin_decades == pytest.approx(whole.margin_decades, rel=1e-9)
    if whole.dim:
        assert symmetry.split_dense_kernel(W, split, 0) is None
    # with vectors (the large route's fallback when a block's certificate is too close to round-off):
    # the same decision, and an orthonormal basis of the same kernel as the whole SVD's
    with_vectors = symmetry.split_dense_kernel(W, split, structural, vectors=True)
    assert (with_vectors.dim, with_vectors.margin_decades) == (blocked.dim, blocked.margin_decades)
    V = with_vectors.vectors
    assert V.shape == (W.shape[1], whole.dim)
    np.testing.assert_allclose(V.T @ V, np.eye(whole.dim), atol=1e-12)
    assert np.linalg.norm(W @ V) <= max(whole.tol, 1e-300) * max(whole.dim, 1)
    if whole.dim:  # the same subspace: the projector onto the whole SVD's kernel fixes V
        Vw = coupling_kernel(W, structural, vectors=True).vectors
        np.testing.assert_allclose(Vw @ (Vw.T @ V), V, atol=1e-10)


def test_the_large_route_takes_the_blocks_svds_where_a_certificate_fails(monkeypatch):
    """R5.4 on a symmetric face (kernel from ∂Γ's lines): with every block's certificate refused
    (as at k = 2, N = 48, where σ_{d+1}² comes within the floor of round-off), the large route
    decides on the blocks' dense SVDs, not the whole W's, and the row is the dense route's."""
    from infsup_contact.solvers import kernel as kernel_mod
    from infsup_contact.solvers import routes

    request = BetaRequest("structured", 1, 4, 4, ("R5.4",), ("omega2",), ((1.0, 1.0),), ("H",),
                          model=MODELS["membranes3d"], mesh=MeshOptions(element="hex"))
    dense = beta_table(request)
    monkeypatch.setattr(routes, "is_large", lambda space: True)
    monkeypatch.setattr(symmetry, "certified_bottom", lambda *a, **kw: None)
    whole = []
    monkeypatch.setattr(routes, "bottom_kernel", lambda *a, **kw: whole.append(1) or kernel_mod.bottom_kernel(*a, **kw))
    large = beta_table(request)
    assert not whole, "the whole W's SVD decided"
    assert large[0]["kernel_dim"] == dense[0]["kernel_dim"] > 0
    assert large[0]["beta"] == pytest.approx(dense[0]["beta"], abs=1e-12)



@pytest.mark.parametrize("case,k,n", [("R5.4", 2, 6), ("R5.2", 2, 6), ("T3", 2, 6)])
def test_the_components_kernel_side_by_side_is_the_serial_one(monkeypatch, case, k, n):
    """split_bottom_kernel and split_dense_kernel decide on the components side by side (two
    workers): the decision, its values and kernel vectors bit for bit those of the components one
    after the other."""
    from infsup_contact.la import threaded

    W, split, structural = _kernel_problem(case, k, n)
    calls = []

    def side_by_side(fn, items):
        calls.append(1)
        return threaded.run_concurrently([lambda x=x: fn(x) for x in items], workers=2)
    routes = [lambda: symmetry.split_bottom_kernel(W, split, structural),                  # the large route's
              lambda: symmetry.split_dense_kernel(W.toarray(), split, structural),           # the dense route's
              lambda: symmetry.split_dense_kernel(W.toarray(), split, structural, vectors=True)]
    for route in routes:
        monkeypatch.setattr(symmetry, "concurrent_map", side_by_side)
        together = route()
        monkeypatch.setattr(symmetry, "concurrent_map", lambda fn, items: [fn(x) for x in items])
        serial = route()
        assert calls and serial is not None and together is not None
        _assert_same_fields(together, serial)
        assert serial.dim == structural


def test_the_cross_norm_is_the_dense_products():
    """split_dense_kernel's ‖O‖_F from sparse products: on blocks whose cross products are not
    round-off (random columns, mostly zero rows, an empty block) the value of the dense
    formula (2 Σ_{a<b} ‖B_aᵀ B_b‖_F²)^{1/2}."""
    rng = np.random.default_rng(3)
    blocks = [rng.standard_normal((300, m)) * (rng.random((300, 1)) < 0.2) for m in (40, 37, 0, 29)]
    dense = np.sqrt(2.0 * sum(np.linalg.norm(blocks[a].T @ blocks[b]) ** 2
                              for b in range(4) for a in range(b)))
    assert dense > 1.0
    assert symmetry._cross_norm([sp.csc_matrix(B) for B in blocks]) == pytest.approx(dense, rel=1e-12)


def test_the_components_kernel_takes_a_sparse_coupling():
    """split_dense_kernel of the sparse W (the large route's fallback) is, field by field and bit
    for bit, that of W made dense: the blocks W Q_c hold the same sums of W's nonzeros either way."""
    W, split, structural = _kernel_problem("R5.4", 2, 6)
    for vectors in (False, True):
        a = symmetry.split_dense_kernel(W, split, structural, vectors=vectors)
        b = symmetry.split_dense_kernel(W.toarray(), split, structural, vectors=vectors)
        assert a is not None and a.dim == structural > 0
        _assert_same_fields(a, b)


def _kernel_problem(case: str, k: int, n: int) -> tuple:
    """(W: the scaled sparse couplings, the space's reflection split, the structural kernel) of a
    case on the hex pair n:n, what the components' kernel decision receives."""
    from infsup_contact.discretization.gamma.coupling import coupling_matrix, trace_l2_norms
    from infsup_contact.solvers.kernel import scaled_couplings
    from infsup_contact.solvers.side_cache import SideCache

    sides = SideCache().pair(MODELS["membranes3d"], "structured", k, n, n, MeshOptions())
    gamma = sides[0].trace.gamma
    g_h = gamma.multiplier_partition(*(s.trace.partition for s in sides), "omega2")
    space = registry.case_space(case, k, g_h, gamma)
    cols = np.sqrt(np.diag(gamma.gram(space, "L2")[0]))
    W = scaled_couplings([coupling_matrix(s.trace, space, k, sparse=True) for s in sides],
                         [trace_l2_norms(s.trace, k) for s in sides], cols)
    structural = gamma.proven_kernel(space, k, [s.trace for s in sides],
                                     gamma.trace_sum_dimension(k, *(s.trace.partition for s in sides)))
    return W, symmetry.split_of(space, gamma, g_h, k), structural


def _assert_same_fields(a, b) -> None:
    """Two kernel decisions equal field by field, arrays bit for bit."""
    import dataclasses

    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        assert np.array_equal(x, y) if isinstance(x, np.ndarray) else x == y, f.name


@pytest.mark.parametrize("k,n,cases,element,blocked", [
    (2, 10, ("T3", "R5.4", "DUAL-Q9"), "hex", True),   # four components on both sides
    (2, 12, ("TDUAL-Q8", "T3"), "hex20", True),
    # the Kuhn tetrahedra's body parts (a 3D involution) are not the face's point reflection:
    # C = Qᵀ B P is not block diagonal, the bound refuses and the terms are computed whole
    (2, 10, ("T3",), "tet", False),
])
def test_interface_terms_in_parity_blocks_give_the_rows_of_the_whole_terms(monkeypatch, k, n, cases, element,
                                                                            blocked):
    """B_i X_i B_iᵀ from the bodies' parity blocks (la/parity_sandwich.py) against the whole
    sandwich split afterwards: the same rows to the eigensolvers' round-off (module text)."""
    from infsup_contact.la import parity_sandwich
    from infsup_contact.solvers import interface_operator

    request = BetaRequest("structured", k, n, n, cases, ("omega2",), ((1.0, 1.0), (1.0, 4.0)), ("H", "L2"),
                          model=MODELS["membranes3d"], mesh=MeshOptions(element=element))
    taken = []
    sandwich = parity_sandwich.parity_sandwich
    monkeypatch.setattr(interface_operator, "parity_sandwich",
                        lambda *a: taken.append(sandwich(*a)) or taken[-1])
    new = beta_table(request)
    assert taken and all((t is not None) == blocked for t in taken), "the blocks were not taken (refused) as stated"
    assert all(t.distance < 1e-13 for t in taken if t is not None)
    monkeypatch.setattr(interface_operator, "_parity_terms", lambda *a: None)
    old = beta_table(request)
    assert len(new) == len(old)
    for a, b in zip(new, old):
        for key in ("kernel_dim", "n_max", "kernel_decision", "dim_M", "case", "norm", "c2"):
            assert a[key] == b[key], key
        for key in ("beta", "smallest_nonzero", "beta_v1_zero"):
            assert a[key] == pytest.approx(b[key], rel=RTOL, abs=1e-14), key
        assert a["gap_over_roundoff"] == pytest.approx(b["gap_over_roundoff"], rel=1e-6)


def test_the_sides_interface_terms_side_by_side_are_the_terms_in_turn(monkeypatch):
    """The two sides' terms in parity blocks are computed as two concurrent tasks where the request
    has two threads: from the same couplings, sides and split, the same blocks and bounds, bit for
    bit, as one after the other on one thread."""
    from infsup_contact.la import threaded
    from infsup_contact.solvers import interface_operator

    request = BetaRequest("structured", 2, 12, 12, ("DUAL-Q9",), ("omega2",), ((1.0, 1.0),), ("H",),
                          model=MODELS["membranes3d"], mesh=MeshOptions())
    given, terms = [], interface_operator._parity_terms
    monkeypatch.setattr(interface_operator, "_parity_terms", lambda *a: given.append(a) or terms(*a))
    beta_table(request)
    assert given
    monkeypatch.setenv("MKL_NUM_THREADS", "1")
    with threaded.as_task():
        in_turn = terms(*given[0])
    monkeypatch.setenv("MKL_NUM_THREADS", "2")
    side_by_side = terms(*given[0])
    assert len(in_turn) == len(side_by_side) == 2
    for a, b in zip(side_by_side, in_turn):
        assert a.dropped == b.dropped and len(a.blocks) == len(b.blocks) == 4
        assert all(np.array_equal(x, y) for x, y in zip(a.blocks, b.blocks))


def _trace_rows(case, k, n):
    """(W, split, structural) of :func:`_kernel_problem` and the row components of the sides'
    parity parts on Γ (or None)."""
    from infsup_contact.solvers import routes
    from infsup_contact.solvers.side_cache import SideCache

    sides = SideCache().pair(MODELS["membranes3d"], "structured", k, n, n, MeshOptions())
    return (*_kernel_problem(case, k, n), routes._trace_components(sides))


@pytest.mark.parametrize("case,k,n", [("R5.4", 2, 6), ("T3", 2, 6), ("R5.2", 1, 8)])
def test_the_kernel_on_the_trace_components_rows_is_the_whole_blocks(case, k, n):
    """split_dense_kernel on the rows of the matching trace component (the bodies' parity parts on Γ)
    decides as on the whole blocks W Q_c: the same count, decision and margin to round-off; the
    kept rows' singular values interlace the block's (σ_i(A) <= σ_i([A; O])) and the dropped
    energy is the block's rest."""
    W, split, structural, rows = _trace_rows(case, k, n)
    assert rows is not None and sum(R.shape[1] for R in rows) == W.shape[0]
    for vectors in (False, True):
        whole = symmetry.split_dense_kernel(W, split, structural, vectors=vectors)
        reduced = symmetry.split_dense_kernel(W, split, structural, vectors=vectors, row_bases=rows)
        assert whole is not None and reduced is not None
        assert (reduced.dim, reduced.decision, reduced.numerical) == (whole.dim, whole.decision, whole.numerical)
        assert reduced.margin_decades == pytest.approx(whole.margin_decades, rel=1e-9)
    blocks = [(W @ Q).tocsc() for Q in split.bases]
    kept, dropped = symmetry.row_components(blocks, rows)
    for A, B in zip(kept, blocks):
        assert A.shape[0] < B.shape[0] and A.shape[1] == B.shape[1]
        sa = np.sort(np.linalg.svd(A.toarray(), compute_uv=False))[::-1]
        sb = np.sort(np.linalg.svd(B.toarray(), compute_uv=False))[::-1]
        assert np.all(sa <= sb[:len(sa)] * (1 + 1e-12) + 1e-14 * sb[0])
    total = sum(sp.linalg.norm(B) ** 2 for B in blocks)
    assert 0.0 <= dropped <= 1e-24 * total


def test_rows_of_another_group_are_kept_whole():
    """The Kuhn tetrahedra's body parts are not the face's point reflection: their trace components
    do not hold W Q_c, and row_components keeps every row (the blocks unchanged, nothing dropped)."""
    from infsup_contact.discretization.gamma.coupling import coupling_matrix, trace_l2_norms
    from infsup_contact.solvers.kernel import scaled_couplings
    from infsup_contact.solvers import routes
    from infsup_contact.solvers.side_cache import SideCache

    sides = SideCache().pair(MODELS["membranes3d"], "structured", 2, 4, 4, MeshOptions(element="tet"))
    gamma = sides[0].trace.gamma
    g_h = gamma.multiplier_partition(*(s.trace.partition for s in sides), "omega2")
    space = registry.case_space("T3", 2, g_h, gamma)
    W = scaled_couplings([coupling_matrix(s.trace, space, 2, sparse=True) for s in sides],
                         [trace_l2_norms(s.trace, 2) for s in sides], np.ones(space.dim))
    split = symmetry.split_of(space, gamma, g_h, 2)
    rows = routes._trace_components(sides)
    assert split is not None and rows is not None
    blocks = [(W @ Q).tocsc() for Q in split.bases]
    kept, dropped = symmetry.row_components(blocks, rows)
    assert kept is blocks and dropped == 0.0
