"""The bottom of the spectrum without dense eigensolvers (la/bottom.py, kernel.bottom_kernel,
spectra.bottom_spectrum): each against the dense route it replaces above DENSE_MAX_M."""
from dataclasses import replace

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from infsup_contact.la import bottom
from infsup_contact.solvers import infsup, routes, spectra
from infsup_contact.solvers.kernel import MARGIN_DECADES, bottom_kernel, coupling_kernel
from infsup_contact.solvers.request import MeshOptions


@pytest.mark.parametrize("m, d", [(5, 0), (60, 3), (300, 40)])
def test_at_most_below_certifies_the_count(m, d):
    """Weyl: C − τI + ω Z Zᵀ is positive definite for Z the d lowest eigenvectors iff τ < λ_{d+1};
    with any other Z a True is still never wrong (at most d eigenvalues below τ)."""
    rng = np.random.default_rng(m + d)
    Q = np.linalg.qr(rng.standard_normal((m, m)))[0]
    ev = np.concatenate([np.geomspace(1e-14, 1e-12, d), np.linspace(1.0, 4.0, m - d)])
    C = (Q * ev) @ Q.T
    C = 0.5 * (C + C.T)
    Z = Q[:, :d]
    assert bottom.at_most_below(C, 0.5, Z, 4.0)                      # λ_{d+1} = 1 > τ
    if d < m - 1:
        assert not bottom.at_most_below(C, 1.5, Z, 4.0)              # λ_{d+1} < τ: d + 1 below
    for trial in range(20):
        tau = rng.uniform(0.0, 4.5)
        W = np.linalg.qr(rng.standard_normal((m, d)))[0] if d else Z
        if bottom.at_most_below(C, tau, W, 4.0):
            assert np.sum(ev < tau) <= d


def _kernel_matrix(rows, m, d, seed):
    """A sparse W (rows × m) with an exact kernel of dimension d: d columns repeat others."""
    rng = np.random.default_rng(seed)
    W = sp.random(rows, m - d, density=0.05, random_state=rng, format="csc") + sp.eye(rows, m - d)
    return sp.hstack([W, W[:, :d] * 2.0]).tocsr()


@pytest.mark.parametrize("d", [0, 1, 40])
def test_bottom_kernel_equals_the_dense_svd(d):
    W = _kernel_matrix(400, 300, d, seed=d)
    dense = coupling_kernel(W.toarray(), proven=d)
    it = bottom_kernel(W, proven=d)
    assert len(it.singular) == d + 2  # the iterative route answered (d values, σ_{d+1}, σ_max)
    assert (it.dim, it.numerical, it.decision) == (dense.dim, dense.numerical, dense.decision) == (d, d, "clear")
    assert it.margin_decades == pytest.approx(dense.margin_decades, abs=1e-3)  # VALUE_RTOL
    V = it.vectors
    assert V.shape == (300, d)
    np.testing.assert_allclose(V.T @ V, np.eye(d), atol=1e-12)
    if d:
        assert np.linalg.norm(W @ V, axis=0).max() <= it.tol


def test_bottom_kernel_counts_modes_beyond_the_proof():
    """Proven 0, kernel 40: the iteration finds all 40 (one Lanczos vector per multiple
    eigenvalue would find one)."""
    W = _kernel_matrix(400, 300, 40, seed=3)
    it = bottom_kernel(W, proven=0)
    assert (it.dim, it.detected, len(it.singular)) == (40, 40, 42)


def _pencil(m, d, seed):
    rng = np.random.default_rng(seed)
    C = rng.standard_normal((m - d, m))
    Q = np.linalg.qr(rng.standard_normal((m, m)))[0]
    G = Q @ np.diag(rng.uniform(0.5, 2.0, m)) @ Q.T
    return C.T @ C, G, sla.null_space(C)


@pytest.mark.parametrize("d", [0, 5])
def test_bottom_spectrum_equals_the_dense_pencil(d):
    S, G, Z = _pencil(200, d, seed=d)
    L = spectra.gram_factor(G)
    W = np.vstack([S, np.zeros((10, 200))])  # a kernel decision with that kernel
    kernel = coupling_kernel(W, proven=d)
    dense = spectra.spectrum(S, factor=L, kernel=kernel)
    it = spectra.bottom_spectrum(S, L, replace(kernel, vectors=Z))
    assert (it.kernel_dim, it.beta == 0.0) == (dense.kernel_dim, d > 0)
    assert it.smallest_nonzero == pytest.approx(dense.smallest_nonzero, rel=1e-9)
    assert it.beta == pytest.approx(dense.beta, rel=1e-9)
    np.testing.assert_allclose(it.bottom[d:], dense.bottom[d:d + len(it.bottom) - d], rtol=1e-9)
    assert np.all(it.bottom[:d] == 0.0)
    assert it.gap == pytest.approx(dense.gap, rel=1e-2)
    if d:
        with pytest.raises(ValueError, match="needs its basis"):
            spectra.bottom_spectrum(S, L, kernel)


@pytest.mark.parametrize("case", ["T3", "R5.2", "R5.4", "DUAL-ALL"])
def test_face_rows_agree_between_routes(case, monkeypatch):
    """β rows of a real face (k = 2, hexahedra, 5:6: modes beyond the proof) by the dense and
    the iterative route."""
    rows = {}
    monkeypatch.setattr(routes, "LONGER_RULE_LARGE", routes.LONGER_RULE)  # the same W' both ways
    for limit in (10 ** 9, 0):
        monkeypatch.setattr(bottom, "DENSE_MAX_M", limit)
        from infsup_contact.models import MODELS
        rows[limit] = infsup.beta_rows("structured", 2, 5, 6, [case], model=MODELS["membranes3d"], mesh=MeshOptions(element="hex"))
    for a, b in zip(rows[10 ** 9], rows[0]):
        assert (a["kernel_dim"], a["kernel_decision"], a["kernel_check"]) == \
            (b["kernel_dim"], b["kernel_decision"], b["kernel_check"])
        if a["kernel_detected"] == 0:  # the margin is σ_{d+1}/η: the same number
            assert b["kernel_margin_decades"] == pytest.approx(a["kernel_margin_decades"], abs=1e-3)
        else:  # it also holds η/σ_d of a zero mode, each route's own round-off (its digits differ
            # between BLAS kernels): each is on the side of MARGIN_DECADES its shared decision says
            clear = a["kernel_decision"] == "clear"
            assert all((r["kernel_margin_decades"] >= MARGIN_DECADES) == clear for r in (a, b))
        assert b["beta"] == pytest.approx(a["beta"], rel=1e-9, abs=1e-12)
        assert b["smallest_nonzero"] == pytest.approx(a["smallest_nonzero"], rel=1e-7)
        if a["kernel_dim"]:  # β(v1 = 0) <= β_h = 0: not computed above the gate; below it the root of
            # an eigenvalue within the pencil's round-off η = λ_{d+1}/gap (S2 <= S: its η is smaller)
            eta = a["smallest_nonzero"] ** 2 / a["gap_over_roundoff"]
            assert b["beta_v1_zero"] == 0.0 <= a["beta_v1_zero"] ** 2 <= eta
        else:
            assert b["beta_v1_zero"] == pytest.approx(a["beta_v1_zero"], rel=1e-9)


def test_the_shorter_entry_rule_moves_the_margin_little(monkeypatch):
    """Above DENSE_MAX_M, W' comes from a rule one point longer instead of three: both are
    exact, so η = s + 2‖W − W'‖ changes by round-off only (T3, k = 2, 5:6). Not compared digit
    for digit (both ‖W − W'‖ are round-off, 2‖W − W'‖ ≈ 0.2 s here): each η lies in [s, 2s],
    s = max(rows, m) ε σ_max the SVD's share, so the margins σ_{d+1}/η differ by < log10(2);
    an inexact rule would add its quadrature error, decades above s."""
    from infsup_contact.models import MODELS
    monkeypatch.setattr(bottom, "DENSE_MAX_M", 0)
    margins = []
    for extra in (routes.LONGER_RULE, 2):
        monkeypatch.setattr(routes, "LONGER_RULE_LARGE", extra)
        row = infsup.beta_rows("structured", 2, 5, 6, ["T3"], model=MODELS["membranes3d"], mesh=MeshOptions(element="hex"),
                               norms=("L2",))[0]
        margins.append(row["kernel_margin_decades"])
    assert abs(margins[0] - margins[1]) < np.log10(2.0)
