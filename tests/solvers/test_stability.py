"""The paper's stability claims on small meshes: slopes of log β_h against log h.

Stable pairs (Thm 3, 4, 5) have a β_h bounded away from 0 (slope ≈ 0 in the H^{-1/2}_00
norm), the L²(Γ) norm makes them look like h^{1/2} (Remark 3.1), and R5.4's eigenvalue
above its one-dimensional kernel decays.
"""
import numpy as np
import pytest

from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.request import MeshOptions

STABLE = [("T3", k) for k in (1, 2, 3, 4)] + [("T4", k) for k in (2, 3, 4)] + [("T5", k) for k in (2, 3, 4)]


def _slope(ns, values):
    return np.polyfit(np.log(1.0 / np.asarray(ns)), np.log(values), 1)[0]


def _series(family, k, case, ns, norm, key="beta"):
    return np.array([[r[key] for r in beta_rows(family, k, n, n, [case], norms=[norm])][0] for n in ns])


@pytest.mark.parametrize("case,k", STABLE)
def test_stable_pairs_bounded_structured(case, k):
    ns = [4, 8, 16, 32] if k <= 2 else [4, 8, 16]
    beta = _series("structured", k, case, ns, "H")
    assert beta.min() > 0.3 and abs(_slope(ns, beta)) < 0.05, beta


@pytest.mark.parametrize("family", ["perturbed", "unstructured"])
@pytest.mark.parametrize("case,k", [("T3", 1), ("T3", 2), ("T4", 2), ("T4", 3), ("T5", 2), ("T5", 3)])
def test_stable_pairs_bounded_other_families_odd_and_even(family, case, k):
    ns = [4, 5, 8, 9, 16]
    beta = _series(family, k, case, ns, "H")
    assert beta.min() > 0.3 and abs(_slope(ns, beta)) < 0.1, beta


@pytest.mark.parametrize("case,k", [("T3", 1), ("T3", 2), ("T4", 2), ("T5", 2), ("T5", 3)])
def test_l2_norm_shows_half_slope(case, k):
    """Remark 3.1: in L²(Γ) the stable pairs decay like h^{1/2}."""
    ns = [8, 16, 32]
    assert _slope(ns, _series("structured", k, case, ns, "L2")) == pytest.approx(0.5, abs=0.1)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_r54_eigenvalue_above_kernel_decays(k):
    ns = [4, 8, 16]
    above = _series("structured", k, "R5.4", ns, "H", key="smallest_nonzero")
    assert np.all(np.diff(above) < 0) and _slope(ns, above) > 0.7, above


def test_multiplier_meshes_with_one_partition_share_rows_equal_to_separate_runs():
    """On a matching pair G_h is the same partition for omega2, omega1 and union: the rows
    copied within one call equal those a call for that multiplier mesh alone computes.
    On a non-matching pair the partitions differ and so do the β_h."""
    from infsup_contact.solvers.infsup import beta_rows, beta_rows_all
    numbers = ["beta", "kernel_dim", "smallest_nonzero", "beta_v1_zero", "dim_M"]
    mms = ["omega2", "omega1", "union"]
    for n1, n2, shared in ((6, 6, True), (7, 6, False)):
        together = beta_rows_all("perturbed", 2, n1, n2, ["T3", "R5.4"], mms, ((1.0, 2.0),), ("H",), mesh=MeshOptions(seed=3))
        for mm in mms:
            alone = beta_rows("perturbed", 2, n1, n2, ["T3", "R5.4"], mm, 1.0, 2.0, ("H",), mesh=MeshOptions(seed=3))
            got = [r for r in together if r["multiplier_mesh"] == mm]
            assert [[r[c] for c in numbers] for r in got] == [[r[c] for c in numbers] for r in alone]
        betas = {mm: [r["beta"] for r in together if r["multiplier_mesh"] == mm] for mm in mms}
        assert (betas["omega2"] == betas["union"] == betas["omega1"]) == shared
