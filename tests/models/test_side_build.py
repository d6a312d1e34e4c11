"""The side build's cheaper routes (issue 52: the 3D side build's overhead) against the
straightforward ones, bit for bit: the symmetry check row block by row block, K_c = Q_cᵀ K Q_c
block by block, the parts' sum by its orbits, and K on the free dofs read from NGSolve's arrays.
Each compares the verdict or the arrays themselves (dtype, order of the stored entries, bits), on
every element whose side takes the route; the new route is run in blocks smaller than the body
so that block boundaries are crossed."""
from __future__ import annotations

import threading
from contextlib import nullcontext

import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.errors import InputError
from infsup_contact.la import body_parity, threaded
from infsup_contact.models import body_symmetry, membranes3d as m3
from infsup_contact.models.membranes import laplace_stiffness


def _same_arrays(a, b) -> bool:
    """Two sparse matrices with the same format, shape and stored arrays, bit for bit."""
    return a.format == b.format and a.shape == b.shape and all(
        getattr(a, f).dtype == getattr(b, f).dtype and np.array_equal(getattr(a, f).view(np.uint8),
                                                                       getattr(b, f).view(np.uint8))
        for f in ("indptr", "indices", "data"))


def _commutes_whole(K, K_image, sigma) -> bool:
    """The straightforward check: max |K[σ][:, σ] − K_image| ≤ COMMUTE_RTOL max |K|, whole and dense."""
    K = sp.csr_matrix(K)
    diff = np.abs((K[sigma][:, sigma] - sp.csr_matrix(K_image)).toarray()).max()
    return bool(diff <= body_symmetry.COMMUTE_RTOL * np.abs(K.data).max())


@pytest.mark.parametrize("element, k", (("hex", 2), ("tet", 2), ("hex20", 2)))
def test_the_blockwise_check_is_the_whole_one(monkeypatch, element, k):
    """:func:`~infsup_contact.models.body_symmetry.commutes` row block by row block (blocks of a few
    rows here, so that every kind of block boundary is crossed), on CSC matrices through their
    transposes: the same verdict as the whole dense check, on symmetries that hold, a stiffness
    entry moved, a pattern changed and a permutation that is no symmetry."""
    monkeypatch.setattr(body_symmetry, "BLOCK_ENTRIES", 97)
    side = m3.side_operator(m3.subdomain_mesh("structured", 3, 1, element=element), k)
    K = side.stiffness
    points, inv = body_symmetry._keys(side.signature, K)
    candidates = [body_symmetry._match(points, inv, T(points), inv) for T in (
        body_symmetry.REFLECT_X, body_symmetry.REFLECT_Y, body_symmetry.SWAP, body_symmetry.ANTISWAP)]
    candidates = [pi for pi in candidates if pi is not None]
    candidates.append(np.random.default_rng(2).permutation(K.shape[0]))
    moved = K.tolil()
    j = int(sp.csr_matrix(K)[0].indices[-1])
    moved[0, j] += 1e-6 * np.abs(K.data).max()
    moved[j, 0] = moved[0, j]
    coo = K.tocoo()  # an explicit zero off the pattern: another pattern, the same K
    zero = sp.csc_matrix((np.append(coo.data, 0.0), (np.append(coo.row, 0), np.append(coo.col, K.shape[0] - 1))),
                         shape=K.shape)
    assert zero.nnz == K.nnz + 1
    verdicts = []
    for image in (K, moved.tocsc(), moved.tocsr(), zero):
        for pi in candidates:
            verdict = body_symmetry.commutes(K if image.format == "csc" else K.tocsr(), image, pi)
            assert verdict == _commutes_whole(K, image, pi)
            verdicts.append(verdict)
    assert any(verdicts) and not all(verdicts)


@pytest.mark.parametrize("element, k", (("hex", 2), ("tet", 2), ("hex20", 2)))
def test_the_orbit_route_of_the_parts_sum_is_the_sparse_products(monkeypatch, element, k):
    """Σ_c Q_{c,Γ} M_c Q_{c,Γ}ᵀ by :func:`~infsup_contact.la.body_parity.orbit_sandwich_sum` (entries
    gathered row block by row block) against scipy's sparse products
    (:func:`~infsup_contact.la.body_parity.sandwich_sum`): bit for bit, on a body's parts with
    symmetric blocks holding a −0 (the products' added zeros turn it into +0) and a block of
    rows smaller than n_Γ; a Q with two entries in a row takes the sparse products."""
    side = m3.side_operator(m3.subdomain_mesh("structured", 3, 1, element=element), k)
    n_gamma = len(side.trace.gamma_dofs)
    parts = body_parity.parity_parts(side.stiffness, n_gamma,
                                     body_symmetry.parity_bases(side.signature, side.stiffness, n_gamma))
    tails = [p.basis[parts.n - n_gamma:][:, p.basis.shape[1] - p.n_gamma:].tocsr() for p in parts.parts]
    rng = np.random.default_rng(3)
    blocks = []
    for Q in tails:
        M = rng.standard_normal((Q.shape[1], Q.shape[1]))
        M = M + M.T
        M[0, 0] = -0.0
        blocks.append(M)
    reference = body_parity.sandwich_sum(tails, blocks, n_gamma)
    monkeypatch.setattr(body_parity, "ROWS", 7)  # blocks and tiles of 7 rows, the last one shorter
    assert np.array_equal(parts._sum(tails, blocks).view(np.int64), reference.view(np.int64))
    assert np.array_equal(body_parity.orbit_sandwich_sum(tails, blocks, n_gamma).view(np.int64),
                          reference.view(np.int64))
    mixed = [Q.tolil() for Q in tails]
    mixed[0][0, 1] = 0.5  # two entries in row 0: no orbit route
    mixed = [Q.tocsr() for Q in mixed]
    assert np.array_equal(parts._sum(mixed, blocks).view(np.int64),
                          body_parity.sandwich_sum(mixed, blocks, n_gamma).view(np.int64))


@pytest.mark.parametrize("element, k", (("hex", 2), ("tet", 2), ("hex20", 2)))
def test_the_blockwise_congruence_is_scipys_product(monkeypatch, element, k):
    """K_c = Q_cᵀ K Q_c by :func:`~infsup_contact.la.body_parity.congruence` (row blocks of 5 here)
    against scipy's whole ``Q.T.tocsr() @ (K @ Q)``: the same arrays, stored entries in the same
    order, bit for bit, for every part of a body."""
    monkeypatch.setattr(body_parity, "CONGRUENCE_ROWS", 5)
    side = m3.side_operator(m3.subdomain_mesh("structured", 3, 1, element=element), k)
    n_gamma = len(side.trace.gamma_dofs)
    K = sp.csr_matrix(side.stiffness)
    for Q in body_symmetry.parity_bases(side.signature, side.stiffness, n_gamma):
        Q = Q.tocsr()
        assert Q.shape[1] > 5
        assert _same_arrays(body_parity.congruence(K, Q), (Q.T.tocsr() @ (K @ Q)).tocsr())


@pytest.mark.parametrize("element, k", (("hex", 1), ("hex", 2), ("tet", 2)))
def test_k_on_the_free_dofs_is_the_whole_ks_restriction(element, k):
    """``laplace_stiffness(fes, free)`` (read from NGSolve's arrays) against the whole K's
    ``K[free][:, free].tocsc()``, and a β_h side's stiffness against a scene side's (which keeps
    the whole K and restricts it): the same arrays."""
    body = m3.subdomain_mesh("structured", 3, 1, element=element)
    fes = m3.displacement_space(body.mesh, k)
    free = np.concatenate([np.flatnonzero(np.array(fes.FreeDofs(), dtype=bool))[::-1], [0]])
    assert _same_arrays(laplace_stiffness(fes, free), laplace_stiffness(fes)[free][:, free].tocsc())
    beta, scene = m3.side_operator(body, k), m3.side_operator(body, k, keep_factor=True)
    assert beta.stiffness_all is None and np.array_equal(beta.free, scene.free)
    assert _same_arrays(beta.stiffness, scene.stiffness)


def test_the_stiffness_on_the_task_manager_is_the_serial_one(monkeypatch):
    """laplace_stiffness assembles on NGSolve's task manager where the request has two threads:
    the same matrix, bit for bit, as the serial assembly (structure and values)."""
    import numpy as np

    from infsup_contact.models import membranes, membranes3d

    body = membranes3d.subdomain_mesh("structured", 6, 1)
    fes = membranes3d.displacement_space(body.mesh, 2, membranes3d.BETA_DIRICHLET)
    monkeypatch.setenv("MKL_NUM_THREADS", "1")
    serial = membranes.laplace_stiffness(fes)
    monkeypatch.setenv("MKL_NUM_THREADS", "2")
    calls = []
    monkeypatch.setattr(membranes.ngsolve, "TaskManager", (lambda tm: lambda *a, **k: calls.append(1) or tm(*a, **k))(
        membranes.ngsolve.TaskManager))
    tasks = membranes.laplace_stiffness(fes)
    assert calls
    for name in ("indptr", "indices", "data"):
        assert np.array_equal(getattr(serial, name), getattr(tasks, name))


def test_the_sums_and_the_mirrored_copies_side_by_side_are_the_serial_ones(monkeypatch):
    """A body's S and X (the parts' sums) and side 2's mirrored S2, X2 are made as two concurrent
    tasks where the request has two threads: the same arrays, bit for bit, as one after the other."""
    bodies = [m3.subdomain_mesh("structured", 4, s) for s in (1, 2)]
    out = {}
    for threads in ("1", "2"):
        monkeypatch.setenv("MKL_NUM_THREADS", threads)
        with threaded.as_task() if threads == "1" else nullcontext():  # MKL on one thread, as in the tasks
            side1 = m3.side_operator(bodies[0], 2)
            side2 = m3.mirror_side(side1, bodies[1], 2)
        out[threads] = [side1.schur, side1.steklov, side2.schur, side2.steklov]
    assert side2.route == "mirror" and all(a is not None for a in out["2"])
    for a, b in zip(out["1"], out["2"]):
        assert a.shape == b.shape and np.array_equal(a, b)


@pytest.mark.parametrize("element, k", (("hex", 2), ("tet", 1), ("hex20", 2)))
def test_a_matching_pair_built_side_by_side_is_the_pair_built_in_turn(monkeypatch, element, k):
    """``Model.matching_pair``: side 1's factorization in a thread of its own, beside side 2's
    mesh, stiffness and mirror search, gives the sides of side_operator and mirror_side one after
    the other, bit for bit (K, S, X, X's blocks, the routes). Hex and tet bodies take the thread
    (seen); HEX20 bodies (scikit-fem) are built in turn."""
    monkeypatch.setenv("MKL_NUM_THREADS", "2")
    b1, b2 = (m3.subdomain_mesh("structured", 4, s, element=element) for s in (1, 2))
    seen, factorized_side = [], m3.factorized_side
    monkeypatch.setattr(m3, "factorized_side",
                        lambda *a, **kw: seen.append(threading.current_thread().name) or factorized_side(*a, **kw))
    pair = m3.matching_pair(b1, lambda: b2, k)
    with threaded.as_task():  # the reference: one side after the other, on one thread
        side1 = m3.side_operator(b1, k)
        reference = (side1, m3.mirror_side(side1, b2, k))
    assert seen[:1] == ([] if element == "hex20" else ["infsup-side1_0"])
    assert [s.route for s in pair] == [s.route for s in reference] and pair[1].route == "mirror"
    for got, want in zip(pair, reference):
        assert _same_arrays(got.stiffness, want.stiffness)
        for name in ("schur", "steklov", "free"):
            a, b = getattr(got, name), getattr(want, name)
            assert (a is None) == (b is None) and (a is None or np.array_equal(a, b))
        assert len(got.steklov_parts or ()) == len(want.steklov_parts or ())
        for (P, X), (P0, X0) in zip(got.steklov_parts or (), want.steklov_parts or ()):
            assert _same_arrays(P.tocsr(), P0.tocsr()) and np.array_equal(X, X0)


def test_a_failing_second_body_fails_the_pair_after_side_1_is_done(monkeypatch):
    """An error in side 2's build is the pair's error, raised once side 1's factorization has
    ended (its thread joined, nothing left running)."""
    monkeypatch.setenv("MKL_NUM_THREADS", "2")
    b1 = m3.subdomain_mesh("structured", 3, 1)

    def broken():
        raise InputError("N2", "a mesh", got="nothing")

    before = threading.active_count()
    with pytest.raises(InputError, match="N2"):
        m3.matching_pair(b1, broken, 2)
    assert threading.active_count() <= before
