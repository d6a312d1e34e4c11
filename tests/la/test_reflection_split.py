"""The large route's pencils split by the reflections of the face (la/reflection.py, solvers/symmetry.py): the
permutations of real face bases and the character formula for the components' dimensions, the
block identity Σ_c Q_c M_c Q_cᵀ = M, the kernel's components, and β rows identical (to the
Lanczos accuracy) with and without the split."""
import numpy as np
import pytest
import scipy.linalg as sla

from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.la import bottom, reflection, threaded
from infsup_contact.solvers import infsup, spectra, symmetry
from infsup_contact.solvers.kernel import KernelDecision
from infsup_contact.solvers.request import MeshOptions


def _space(case, k, n, gamma=SQUARE):
    g = np.linspace(0.0, 1.0, n + 1)
    part = TensorPartition(g, g)
    return registry.case_space(case, k, part, gamma), part


def _elements(split):
    """The group's permutations P_b, b = 0 .. 2^g − 1 (P_b = Π_{i ∈ b} π_i)."""
    out = [np.arange(split.pis[0].size)]
    for pi in split.pis:
        out += [pi[e] for e in out]
    return out


def _character(c, b):
    return (-1.0) ** bin(b & c).count("1")


def _invariant_spd(split, seed, shift=1.0):
    """A random SPD matrix averaged over the group: P_b M P_bᵀ = M for every b."""
    els = _elements(split)
    m = els[0].size
    A = np.random.default_rng(seed).standard_normal((m, m))
    A = A @ A.T + shift * m * np.eye(m)
    return sum(A[np.ix_(e, e)] for e in els) / len(els)


@pytest.mark.parametrize("case,k,gamma", [("T3", 2, SQUARE), ("R5.2", 2, SQUARE), ("DUAL-ALL", 1, SQUARE),
                                          ("PWLIN-Q9", 2, SQUARE), ("R5.4", 2, SQUARE), ("R5.2", 1, SQUARE_TRIG)])
def test_the_reflections_permute_the_basis(case, k, gamma):
    """Quadrilaterals: x → 1 − x and y → 1 − y (two commuting involutions, four components);
    Kuhn triangles: the point reflection only. Each component has the dimension of the character
    formula (1/|G|) Σ_b χ_c(b) tr P_b, and Q = [Q_0, ...] is orthogonal."""
    space, part = _space(case, k, 5, gamma)
    x = gamma.quadrature(part, 2 * k)[0]
    split = symmetry.reflection_split(space, x)
    assert split is not None
    maps = ([lambda y: np.column_stack([1.0 - y[:, 0], y[:, 1]]), lambda y: np.column_stack([y[:, 0], 1.0 - y[:, 1]])]
            if gamma is SQUARE else [lambda y: 1.0 - y])
    assert len(split.pis) == len(maps)
    for pi, T in zip(split.pis, maps):
        assert np.array_equal(pi[pi], np.arange(space.dim))                       # an involution
        np.testing.assert_allclose(space.evaluate(T(x)), space.evaluate(x)[:, pi], atol=1e-12)
    els = _elements(split)
    for a in split.pis:
        for b in split.pis:
            assert np.array_equal(a[b], b[a])                                     # they commute
    traces = [np.count_nonzero(e == np.arange(space.dim)) for e in els]
    for c, size in enumerate(split.sizes):
        assert size == sum(_character(c, b) * t for b, t in enumerate(traces)) / len(els)
    Q = np.hstack([q.toarray() for q in split.bases])
    np.testing.assert_allclose(Q.T @ Q, np.eye(space.dim), atol=1e-14)


def test_a_graded_partition_has_no_split():
    xs = np.array([0.0, 0.1, 0.35, 0.7, 1.0])
    part = TensorPartition(xs, xs)
    space = registry.case_space("R5.2", 1, part, SQUARE)
    assert symmetry.reflection_split(space, SQUARE.quadrature(part, 2)[0]) is None


def test_blocks_reconstruct_an_invariant_matrix_and_detect_a_non_invariant_one():
    space, part = _space("R5.2", 2, 4)
    split = symmetry.reflection_split(space, SQUARE.quadrature(part, 4)[0])
    M = _invariant_spd(split, 0)
    *blocks, distance = split.blocks(M)
    assert len(blocks) == 4 and distance <= reflection.INVARIANCE_RTOL  # the split's own test of invariance
    rebuilt = sum(Q @ Mc @ Q.T for Q, Mc in zip(split.bases, blocks))
    np.testing.assert_allclose(rebuilt, M, atol=1e-12 * np.abs(M).max())
    M[0, 1] += 1e-6 * np.abs(M).max()
    M[1, 0] = M[0, 1]
    assert split.blocks(M)[-1] > reflection.INVARIANCE_RTOL


@pytest.mark.parametrize("dims", [(0, 0, 0, 0), (3, 0, 0, 0), (2, 5, 0, 1), (1, 1, 2, 3)])
def test_split_pencils_equal_the_unsplit_route(dims):
    """A synthetic invariant pencil with an invariant kernel of dims[c] modes in component c: the
    values above the kernel and λ_max of the blocks are the unsplit route's (bottom_spectra)."""
    space, part = _space("R5.2", 2, 4)
    split = symmetry.reflection_split(space, SQUARE.quadrature(part, 4)[0])
    els, m = _elements(split), space.dim
    rng = np.random.default_rng(1)
    cols = []
    for c, dc in enumerate(dims):  # component c: v = Σ_b χ_c(b) w ∘ P_b
        for _ in range(dc):
            w = rng.standard_normal(m)
            cols.append(sum(_character(c, b) * w[e] for b, e in enumerate(els)))
    Z = np.column_stack(cols) if cols else np.zeros((m, 0))
    A = _invariant_spd(split, 2)
    if Z.shape[1]:  # S = P_⊥ A P_⊥ with P_⊥ the Euclidean projector off span Z: S Z = 0, invariant
        Q = sla.qr(Z, mode="economic")[0]
        Pp = np.eye(m) - Q @ Q.T
        A = Pp @ A @ Pp
        A = 0.5 * (A + A.T)
    G = _invariant_spd(split, 3, shift=0.2)
    d = Z.shape[1]
    kernel = KernelDecision(d, d, 0, np.inf, "clear", 0.0, np.zeros(0), d, Z if d else None)
    plain = spectra.bottom_spectra(A, {"H": spectra.gram_factor(G)}, kernel if d else None)["H"]
    parts = split.components(Z) if d else None
    if d:
        assert tuple(P.shape[1] for P in parts) == dims
    factors = {"H": tuple(spectra.gram_factor(b) for b in split.blocks(G)[:-1])}
    halves = spectra.split_spectra(split, A, factors, kernel if d else None, parts)["H"]
    assert halves.kernel_dim == plain.kernel_dim == d
    assert halves.smallest_nonzero == pytest.approx(plain.smallest_nonzero, rel=1e-9)
    assert halves.beta == pytest.approx(plain.beta, rel=1e-9, abs=0.0)
    assert halves.gap == pytest.approx(plain.gap, rel=1e-2)


@pytest.mark.parametrize("dims", [(0, 0, 0, 0), (2, 0, 1, 0)])
def test_split_pencils_side_by_side_are_the_pencils_one_after_the_other(monkeypatch, dims):
    """split_pencils solves every (norm, block) pencil as a concurrent task (one BLAS thread each):
    on two threads its values and λ_max are those of one thread bit for bit, with and without a
    deflated kernel, for two norms."""
    space, part = _space("R5.2", 2, 6)
    split = symmetry.reflection_split(space, SQUARE.quadrature(part, 4)[0])
    els, m = _elements(split), space.dim
    rng = np.random.default_rng(5)
    cols = [sum(_character(c, b) * w[e] for b, e in enumerate(els))
            for c, dc in enumerate(dims) for w in rng.standard_normal((dc, m))]
    A = _invariant_spd(split, 2)
    if cols:
        Q = sla.qr(np.column_stack(cols), mode="economic")[0]
        Pp = np.eye(m) - Q @ Q.T
        A = 0.5 * (Pp @ A @ Pp + (Pp @ A @ Pp).T)
    parts = split.components(np.column_stack(cols)) if cols else None
    factors = {nm: tuple(spectra.gram_factor(b) for b in split.blocks(_invariant_spd(split, seed, shift=0.2))[:-1])
               for nm, seed in (("H", 3), ("L2", 4))}
    monkeypatch.setenv("MKL_NUM_THREADS", "1")
    with threaded.as_task():  # every MKL call on one thread, as in the tasks
        serial = reflection.split_pencils(split, A, factors, parts, 6)
    monkeypatch.setenv("MKL_NUM_THREADS", "2")
    side_by_side = reflection.split_pencils(split, A, factors, parts, 6)
    assert serial.keys() == side_by_side.keys() == factors.keys()
    for nm in factors:
        (v1, t1), (v2, t2) = serial[nm], side_by_side[nm]
        assert np.array_equal(v1, v2) and t1 == t2 and len(v1) == 6 and np.all(v1 > 0)


def test_a_kernel_that_is_not_the_sum_of_its_parts_is_refused():
    space, part = _space("R5.2", 2, 4)
    split = symmetry.reflection_split(space, SQUARE.quadrature(part, 4)[0])
    v = np.random.default_rng(4).standard_normal(space.dim)
    assert split.components(v[:, None]) is None       # a generic vector: neither even nor odd


@pytest.mark.parametrize("case", ["T3", "R5.2", "DUAL-ALL"])
def test_face_rows_with_and_without_the_split(case, monkeypatch):
    """The iterative route (DENSE_MAX_M = 0) on a real face, hexahedra k = 2, 5:6, with the split
    and with it switched off: the same kernels, β to 1e-9."""
    from infsup_contact.models import MODELS
    monkeypatch.setattr(bottom, "DENSE_MAX_M", 0)
    calls, split_spectra = [], spectra.split_spectra
    monkeypatch.setattr(spectra, "split_spectra", lambda *a, **kw: calls.append(1) or split_spectra(*a, **kw))
    rows = {}
    for on in (True, False):
        if not on:
            monkeypatch.setattr(symmetry, "reflection_split", lambda space, x: None)
        rows[on] = infsup.beta_rows("structured", 2, 5, 6, [case], model=MODELS["membranes3d"], mesh=MeshOptions(element="hex"))
        assert bool(calls) == on  # the split was taken, and then switched off
        calls.clear()
    for a, b in zip(rows[True], rows[False]):
        assert (a["kernel_dim"], a["kernel_decision"]) == (b["kernel_dim"], b["kernel_decision"])
        if a["kernel_detected"] == 0:  # σ_{d+1}/η: the first value above the kernel, either way
            assert a["kernel_margin_decades"] == pytest.approx(b["kernel_margin_decades"], abs=1e-3)
        assert a["beta"] == pytest.approx(b["beta"], rel=1e-9, abs=1e-12)
        assert a["smallest_nonzero"] == pytest.approx(b["smallest_nonzero"], rel=1e-8)
        assert a["beta_v1_zero"] == pytest.approx(b["beta_v1_zero"], rel=1e-9, abs=1e-12)


def test_the_split_kernel_is_the_unsplit_one_on_a_real_face(monkeypatch):
    """split_bottom_kernel on W of R5.2 (k = 2, hexahedra 5:6: 16 modes beyond the dimension
    count) decides what bottom_kernel decides: the count, the first value above it, η; its
    vectors span a kernel of W (‖W Z‖ <= η) and are orthonormal."""
    from infsup_contact.models import MODELS
    from infsup_contact.solvers.kernel import bottom_kernel
    captured = {}
    original = symmetry.split_bottom_kernel

    def spy(W, split, proven, error):
        captured.update(W=W, split=split, proven=proven, error=error)
        return original(W, split, proven, error)

    monkeypatch.setattr(bottom, "DENSE_MAX_M", 0)
    monkeypatch.setattr(symmetry, "split_bottom_kernel", spy)
    infsup.beta_rows("structured", 2, 5, 6, ["R5.2"], model=MODELS["membranes3d"], mesh=MeshOptions(element="hex"), norms=("L2",))
    W, split, proven, error = (captured[k] for k in ("W", "split", "proven", "error"))
    halves, whole = original(W, split, proven, error), bottom_kernel(W, proven, error)
    assert halves is not None and halves.dim == whole.dim > 0 and halves.detected == whole.detected
    assert halves.tol == pytest.approx(whole.tol, rel=1e-10)  # σ_max by Lanczos (eigsh tol 1e-10) either way
    assert halves.singular[-2] == pytest.approx(whole.singular[-2], rel=1e-3)   # σ_{d+1}
    Z = halves.vectors
    np.testing.assert_allclose(Z.T @ Z, np.eye(Z.shape[1]), atol=1e-10)
    assert np.linalg.norm(W @ Z, axis=0).max() <= halves.tol


def test_an_interface_operator_that_is_not_invariant_is_solved_unsplit():
    """split_spectra returns None for an S off invariance (the caller's unsplit route)."""
    space, part = _space("R5.2", 2, 4)
    split = symmetry.reflection_split(space, SQUARE.quadrature(part, 4)[0])
    S, G = _invariant_spd(split, 5), _invariant_spd(split, 6)
    factors = {"H": tuple(spectra.gram_factor(b) for b in split.blocks(G)[:-1])}
    assert spectra.split_spectra(split, S, factors) is not None
    S[0, 2] += 1e-8 * np.abs(S).max()
    S[2, 0] = S[0, 2]
    assert spectra.split_spectra(split, S, factors) is None


@pytest.mark.parametrize("n", [1, 7, 130])
def test_symmetric_permutation_is_the_fancy_index(n):
    """symmetric_permutation(A, p) copies the entries of A[np.ix_(p, p)], bit for bit, for a
    permutation p and for a selection with repeats (and keeps the dtype)."""
    from infsup_contact.la.reflection import symmetric_permutation

    rng = np.random.default_rng(n)
    A = rng.standard_normal((n, n))
    for p in (rng.permutation(n), rng.integers(0, n, size=max(n // 2, 1))):
        got = symmetric_permutation(A, p)
        assert got.dtype == A.dtype and np.array_equal(got, A[np.ix_(p, p)])
