"""The kernel of (4.5) decided from Bᵀ (solvers/kernel.py): its proven part, its error level,
its margin, and its agreement with the pencil."""
import numpy as np
import pandas as pd
import pytest
import scipy.linalg as sla

from infsup_contact.discretization.gamma.coupling import coupling_matrix, trace_l2_norms
from infsup_contact.discretization.segment.norms import gram
from infsup_contact.models.membranes import MEMBRANES
from infsup_contact.solvers.interface_operator import combine_terms, interface_terms
from infsup_contact.solvers.side_cache import SideCache
from infsup_contact.discretization.spaces.registry import case_space
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.routes import space_kernel
from infsup_contact.solvers.spectra import spectrum
from infsup_contact.solvers.kernel import (CLOSE, GAP_DECADES, MARGIN_DECADES, coupling_kernel, kernel_from_gap,
                                           right_singular, scaled_couplings)
from infsup_contact.criteria import stability as verdict
from infsup_contact.criteria import claims

EPS = np.finfo(float).eps


def _with_singular_values(s, rows, seed=0):
    """A rows × len(s) matrix with exactly the singular values s (random orthogonal factors)."""
    rng = np.random.default_rng(seed)
    U, _ = np.linalg.qr(rng.standard_normal((rows, len(s))))
    V, _ = np.linalg.qr(rng.standard_normal((len(s), len(s))))
    return U @ np.diag(s) @ V.T


# ------------------------------------------------------------------ the rule on plain matrices

@pytest.mark.parametrize("rows,m", [(1283, 700), (1282, 700), (2000, 300), (600, 300), (300, 600), (40, 1)])
def test_right_singular_is_the_whole_svds_bit_for_bit(rows, m):
    """right_singular: s and Vᵀ of scipy's dgesdd on W, bit for bit, on both sides of dgesdd's
    threshold ⌊11 m / 6⌋ (1283 × 700 goes through R alone, 1282 × 700 through W), wide and
    one-column W, with W's memory reused (Fortran order) or not. The rows are mostly zero, as a
    coupling's are (only the trace dofs under a multiplier's support)."""
    rng = np.random.default_rng(rows + m)
    W = rng.standard_normal((rows, m)) * (rng.random((rows, 1)) < 0.3)
    _, s, vt = sla.svd(W, full_matrices=m > rows)
    for got in (right_singular(W), right_singular(W.copy(order="F"), overwrite=True)):
        assert np.array_equal(got[0], s) and np.array_equal(got[1], vt)
    with_vectors = coupling_kernel(W, vectors=True)  # the decision's values and basis are the SVD's
    assert np.array_equal(with_vectors.singular[-len(s):], np.sort(s))


def test_exact_zero_singular_values_are_counted_with_a_wide_margin():
    W = _with_singular_values(np.r_[0.0, 0.0, np.linspace(1e-3, 2.0, 20)], 40)
    d = coupling_kernel(W)
    assert (d.dim, d.proven, d.detected, d.decision) == (2, 0, 2, "clear")
    # computed zeros sit near ε·σ_max, log10(max(rows, cols)) decades below η; 1e-3 is 11 above
    assert d.margin_decades > MARGIN_DECADES


def test_more_multipliers_than_rows_is_a_proven_kernel():
    W = np.random.default_rng(1).standard_normal((5, 8))  # rank <= 5: three proven zero modes
    d = coupling_kernel(W)
    assert (d.dim, d.proven, d.detected) == (3, 3, 0)
    assert d.singular[:3].tolist() == [0.0, 0.0, 0.0]


def test_a_singular_value_near_the_error_level_is_a_close_decision():
    W = _with_singular_values(np.r_[1.0, 0.5, np.ones(10)], 12)
    eta = 12 * EPS * 1.0
    for s_min in (3 * eta, eta / 3):  # just above, just below η: either count is luck
        d = coupling_kernel(_with_singular_values(np.r_[s_min, 0.5, np.ones(10)], 12))
        assert d.decision == CLOSE and abs(d.margin_decades) < MARGIN_DECADES, d
    assert coupling_kernel(W).decision == "clear"


def test_the_proof_is_never_lost_and_an_exceeded_error_level_is_flagged():
    # a proof of one zero mode on a matrix whose singular values are all O(1): the stated
    # error level would have been exceeded; the kernel keeps the proven mode, the decision is close
    d = coupling_kernel(_with_singular_values(np.linspace(0.5, 1.0, 6), 10), proven=1)
    assert d.dim == 1 and d.numerical == 0 and d.decision == CLOSE and d.margin_decades < 0


def test_a_smoothly_decaying_bottom_is_not_a_kernel_unless_it_reaches_the_error_level():
    s = 10.0 ** -np.arange(0, 20, 1.0)  # 1, 1e-1, …, 1e-19: crosses η ≈ 5e-15 with no gap
    d = coupling_kernel(_with_singular_values(s, 30))
    assert d.dim == int(np.sum(s <= 30 * EPS)) and d.decision == CLOSE  # one decade apart at best


# ------------------------------------------------------------------ on the paper's spaces

def _sides(family, k, n1, n2):
    return SideCache().pair(MEMBRANES, family, k, n1, n2)


def _kernel_pieces(case, k, n1, n2, mm="omega2", family="structured"):
    sides = _sides(family, k, n1, n2)
    gamma = sides[0].trace.gamma
    x1, x2 = (s.trace.partition for s in sides)
    space = case_space(case, k, gamma.multiplier_partition(x1, x2, mm), gamma)
    couplings = [coupling_matrix(s.trace, space, k) for s in sides]
    structural = max(space.dim - gamma.trace_sum_dimension(k, x1, x2), 0)
    return sides, space, couplings, structural


@pytest.mark.parametrize("n", [4, 8, 16])
def test_r54_k1_checkerboard_is_the_kernel_to_round_off(n):
    """R5.4 at k = 1 (piecewise constants against hats) on matching meshes: μ = (−1)^j on the
    j-th interval is orthogonal to every hat; its residual ‖W m‖/‖m‖ sits far below η."""
    sides, space, couplings, structural = _kernel_pieces("R5.4", 1, n, n)
    mid = 0.5 * (space.breakpoints[1:] + space.breakpoints[:-1])
    m = np.linalg.lstsq(space.evaluate(mid), (-1.0) ** np.arange(n), rcond=None)[0]
    G = gram(space, "L2")[0]
    W = scaled_couplings(couplings, [trace_l2_norms(s.trace, 1) for s in sides], np.sqrt(np.diag(G)))
    y = m * np.sqrt(np.diag(G))  # the same μ in the scaled coordinates
    d = space_kernel(couplings, sides, space, 1, structural)
    assert np.linalg.norm(W @ y) / np.linalg.norm(y) < d.tol / 100
    assert d.dim == structural == 1


@pytest.mark.parametrize("case,k,n1,n2,mm", [("R5.4", 2, 17, 16, "union"), ("R5.2", 4, 17, 16, "union"),
                                             ("T3", 3, 9, 8, "omega1"), ("DUAL", 2, 12, 12, "omega2")])
def test_entry_roundoff_is_far_below_the_error_level(case, k, n1, n2, mm):
    """The entries are exact Gauss sums: a rule with more points changes W by round-off only.
    η counts twice that change for a rule three points longer; an independent estimate from a
    rule six points longer stays below η/2."""
    sides, space, couplings, structural = _kernel_pieces(case, k, n1, n2, mm)
    more = []
    for s in sides:
        x, w = s.trace.gamma.coupling_quadrature(s.trace, space, k + space.degree + 12)
        more.append((space.evaluate(x) * w[:, None]).T @ s.trace.gamma.trace_basis(s.trace, x))
    norms = [trace_l2_norms(s.trace, k) for s in sides]
    scale = np.sqrt(np.diag(gram(space, "L2")[0]))
    W, W_more = scaled_couplings(couplings, norms, scale), scaled_couplings(more, norms, scale)
    eta = space_kernel(couplings, sides, space, k, structural).tol
    assert np.linalg.norm(W - W_more, 2) < eta / 2


def test_svd_backward_error_is_far_below_the_error_level():
    """The second error term: orthogonal transformations leave the singular values unchanged,
    so the spread of the computed ones over several is the SVD's own error."""
    sides, space, couplings, structural = _kernel_pieces("R5.4", 3, 17, 16, "union")
    W = scaled_couplings(couplings, [trace_l2_norms(s.trace, 3) for s in sides],
                         np.sqrt(np.diag(gram(space, "L2")[0])))
    eta = coupling_kernel(W, structural).tol  # the SVD's term alone
    rng = np.random.default_rng(0)
    base = np.sort(sla.svdvals(W))
    for _ in range(3):
        Q1, _r = np.linalg.qr(rng.standard_normal((W.shape[0],) * 2))
        Q2, _r = np.linalg.qr(rng.standard_normal((W.shape[1],) * 2))
        assert np.max(np.abs(np.sort(sla.svdvals(Q1 @ W @ Q2)) - base)) < eta / 4


PENCIL_SWEEP = [(c, k, n1, n2, mm, fam) for fam in ("structured", "unstructured") for k in (1, 2, 3)
                for c in ("T3", "R5.2", "R5.4", "DUAL") for n1, n2, mm in ((6, 6, "omega2"), (7, 6, "union"),
                                                                             (5, 7, "omega1"))]


def test_kernel_of_bt_agrees_with_the_pencil_wherever_the_pencil_is_clear():
    """ker B A⁻¹ Bᵀ = ker Bᵀ: the pencil's own gap rule, where its gap is clear by a decade
    more than it demands, counts the same kernel as the singular values of Bᵀ."""
    compared = 0
    for case, k, n1, n2, mm, fam in PENCIL_SWEEP:
        sides, space, couplings, structural = _kernel_pieces(case, k, n1, n2, mm, fam)
        ours = space_kernel(couplings, sides, space, k, structural)
        S = combine_terms(interface_terms(couplings, sides), (1.0, 1.0))
        for norm in ("H", "L2"):
            G = gram(space, norm)[0]
            ev = sla.eigh(S, G, eigvals_only=True)
            d, gap = kernel_from_gap(ev)
            assert ours.dim >= structural
            if gap >= 10.0 ** (GAP_DECADES + 1):
                compared += 1
                assert d == ours.dim, (case, k, n1, n2, mm, fam, norm, d, ours)
            assert spectrum(S, G, kernel=ours).kernel_dim == ours.dim
    assert compared >= len(PENCIL_SWEEP)  # most of the sweep is clear in both norms


@pytest.mark.parametrize("n1,n2", [(17, 16), (16, 17)])
def test_union_of_a_16_17_pair_keeps_the_proven_kernels_in_both_norms(n1, n2):
    """The issue's second symptom: R5.4 in L² on the union partition lost its proven mode."""
    rows = beta_rows("structured", 2, n1, n2, ["T3", "R5.2", "R5.4"], "union", norms=("H", "L2"))
    got = {(r["case"], r["norm"]): r["kernel_dim"] for r in rows}
    assert got == {(c, nm): d for c, d in (("T3", 0), ("R5.2", 2), ("R5.4", 1)) for nm in ("H", "L2")}
    for r in rows:
        assert r["kernel_decision"] == "clear" and r["kernel_check"] == "agree", r
        assert (r["beta"] == 0.0) == (r["kernel_dim"] > 0)


def test_rows_say_which_part_is_proven_and_which_detected():
    for r in beta_rows("structured", 2, 4, 4, ["R5.4", "T3"], norms=("H",)):
        assert r["kernel_dim"] == r["structural_kernel_dim"] + r["kernel_detected"]
        assert r["kernel_margin_decades"] >= MARGIN_DECADES


# ------------------------------------------------------------------ claims resting on a close decision

def _rows(decisions, dims=(1, 1, 1)):
    return pd.DataFrame(dict(N2=[4, 8, 16], N1=[4, 8, 16], beta=[0.0, 0.0, 0.0], kernel_dim=list(dims),
                             structural_kernel_dim=[1, 1, 1], smallest_nonzero=[0.3, 0.15, 0.07],
                             kernel_decision=list(decisions), kernel_margin_decades=[5.0, 0.4, 5.0],
                             case="R5.4", k=2, family="structured", norm="H", multiplier_mesh="omega2",
                             c1=1.0, c2=1.0))


def test_a_kernel_claim_resting_on_a_close_decision_is_inconclusive():
    assert claims.kernel_claim(_rows(["clear"] * 3), 1)[0] == claims.PASS
    v, text = claims.kernel_claim(_rows(["clear", "close", "clear"]), 1)
    assert v == claims.INCONCLUSIVE and "N = 8" in text
    assert claims.kernel_at_least(_rows(["clear", "close", "clear"]), 1)[0] == claims.INCONCLUSIVE
    # the same close row with a wrong count is still not a FAIL by luck
    assert claims.kernel_claim(_rows(["clear", "close", "clear"], dims=(1, 2, 1)), 1)[0] == claims.INCONCLUSIVE


def test_a_verdict_resting_on_a_close_decision_is_inconclusive():
    assert verdict.stability_verdict(_rows(["clear"] * 3), 0.15, 1e-3, 0.95)["verdict"] == verdict.UNSTABLE
    assert verdict.stability_verdict(_rows(["clear", "close", "clear"]), 0.15, 1e-3, 0.95)["verdict"] \
        == verdict.INCONCLUSIVE
