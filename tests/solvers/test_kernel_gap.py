"""The numerical kernel of (4.5) from the spectrum's gap (solvers/kernel.py)."""
import numpy as np
import pytest
import scipy.linalg as sla

from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.spectra import spectrum
from infsup_contact.solvers.kernel import GAP_DECADES, kernel_check, kernel_from_gap


def _pencil(eigenvalues, seed=0):
    """S, G with S m = λ G m having exactly ``eigenvalues``: G SPD random, S = G V diag(λ) Vᵀ G."""
    rng = np.random.default_rng(seed)
    n = len(eigenvalues)
    A = rng.standard_normal((n, n))
    G = A @ A.T + n * np.eye(n)
    L = np.linalg.cholesky(G)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    # G = L Lᵀ; with m = L⁻ᵀ Q e_i: S m = λ G m for S = L Q diag(λ) Qᵀ Lᵀ
    S = L @ Q @ np.diag(eigenvalues) @ Q.T @ L.T
    return (S + S.T) / 2, G


@pytest.mark.parametrize("ratio", [1e-1, 1e-2, 1e-3])
def test_geometric_spectrum_decaying_into_roundoff_has_no_kernel(ratio):
    # 1, r, r², … down to far below round-off: no gap anywhere, so no kernel
    ev = ratio ** np.arange(40)[::-1]
    S, G = _pencil(ev)
    sp_ = spectrum(S, G)
    assert sp_.kernel_dim == 0
    assert sp_.gap < 10.0 ** GAP_DECADES


def test_geometric_spectrum_above_roundoff_has_no_kernel_and_beta_is_its_bottom():
    ev = 1e-2 ** np.arange(6)[::-1]  # 1e-10 … 1: all above round-off
    S, G = _pencil(ev)
    sp_ = spectrum(S, G)
    assert sp_.kernel_dim == 0
    assert sp_.beta == pytest.approx(1e-5, rel=1e-3)


@pytest.mark.parametrize("d", [1, 2, 3])
def test_exact_kernel_with_a_gap_is_counted(d):
    ev = np.concatenate([np.zeros(d), np.linspace(1e-3, 1.0, 30)])
    S, G = _pencil(ev, seed=d)
    sp_ = spectrum(S, G)
    assert sp_.kernel_dim == d
    assert sp_.smallest_nonzero == pytest.approx(np.sqrt(1e-3), rel=1e-6)


def test_gap_rule_on_plain_arrays():
    eta_unit = 4 * np.finfo(float).eps  # n = 4, λ_max = 1
    assert kernel_from_gap(np.array([0.0, 0.0, 0.5, 1.0]))[0] == 2
    # the next eigenvalue only 100 η above round-off: not a clear gap
    assert kernel_from_gap(np.array([0.0, 100 * eta_unit, 0.5, 1.0]))[0] == 0
    assert kernel_from_gap(np.array([0.0, 2e3 * eta_unit, 0.5, 1.0]))[0] == 1


def test_kernel_check_words():
    assert kernel_check(2, 2) == "agree"
    assert kernel_check(1, 2) == "below_structural"
    assert kernel_check(3, 2) == "above_structural"


@pytest.mark.parametrize("family", ["structured", "unstructured"])
@pytest.mark.parametrize("k", [1, 3])
def test_rem52_rem54_matching_keep_their_kernels(family, k):
    rows = beta_rows(family, k, 8, 8, ["R5.2", "R5.4", "T3"], norms=("H", "L2"))
    expected = {"R5.2": 2, "R5.4": 1, "T3": 0}
    for r in rows:
        assert r["kernel_dim"] == expected[r["case"]], r
        assert r["kernel_check"] == "agree"
        assert r["gap_over_roundoff"] >= 10.0 ** GAP_DECADES


def test_nonmatching_union_kernel_never_below_the_structural_lower_bound():
    # μ ⊥ W1 + W2 spans at least dim M − dim(W1 + W2) modes: the count is a lower bound
    for r in beta_rows("structured", 2, 17, 16, ["R5.2", "R5.4", "T3"], "union", norms=("H",)):
        assert r["kernel_dim"] >= r["structural_kernel_dim"], r


def test_spectrum_agrees_with_scipy_bottom():
    S, G = _pencil(np.linspace(0.1, 2.0, 12), seed=5)
    ev = sla.eigh(S, G, eigvals_only=True)
    assert spectrum(S, G).beta == pytest.approx(np.sqrt(ev[0]), rel=1e-10)
