"""The ledger states round-off-level quantities against their tolerance (study/claims/tolerance.py):
its evidence is the same text whatever round-off a route or a machine leaves in a passing value,
and it prints the value where the value does not pass."""
import numpy as np
import pandas as pd
import pytest

from helpers.face_tables import CLAIMS_CFG, FIT_THETA_MAX, edge_rows, patch_rows

from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.study.claims import arc, elastic, membranes, membranes3d_studies as fsc
from infsup_contact.study.claims.tolerance import LOWER, passes, within


def test_within_states_the_tolerance_when_passing_and_the_value_when_not():
    assert within("max err", 3.3e-13, 1e-8) == within("max err", 7.1e-10, 1e-8) == "max err <= 1e-08 (the tolerance)"
    failing = within("max err", 0.25, 1e-8)
    assert "0.25" in failing and "not <= 1e-08" in failing
    assert "-2e-06" in within("margin", -2e-6, -1e-6, LOWER) and within("margin", 0.3, -1e-6, LOWER).startswith("margin >=")
    for bad in (np.nan, np.inf):                       # a non-finite value never passes
        assert not passes(bad, 1e-8) and "not <=" in within("max err", bad, 1e-8)
    with pytest.raises(ValueError, match="bound"):
        within("max err", 0.0, 1e-8, "<")


def _face_patch_claims(holding_err):
    table = pd.concat([patch_rows("R5.2", 1, err=lambda p: holding_err), patch_rows("T3", 1, passes=False)])
    claims = fsc.face_study_claims(table, None, None, CLAIMS_CFG, {"hex": SQUARE}, FIT_THETA_MAX)
    return claims.set_index("claim_id")


def test_face_patch_evidence_does_not_depend_on_the_round_off_of_a_pass():
    a, b = _face_patch_claims(1.43e-9), _face_patch_claims(7.84e-10)   # two routes' round-off, both passing
    hold, lack = fsc.patch_claim_id("R5.2", 1, "hex"), fsc.patch_claim_id("T3", 1, "hex")
    assert a.loc[hold, "evidence"] == b.loc[hold, "evidence"] and a.loc[hold, "verdict"] == "PASS"
    assert "e-09" not in a.loc[hold, "evidence"] and "e-10" not in b.loc[hold, "evidence"]
    assert "= 1," in a.loc[lack, "evidence"]                            # the failing error is printed
    between = 10 * fsc.PATCH_RTOL                                        # above round-off, below failure
    inconclusive = _face_patch_claims(between).loc[hold]
    assert inconclusive.verdict == "INCONCLUSIVE" and f"{between:.3g}" in inconclusive.evidence


@pytest.mark.parametrize("rel_a, rel_b", [(2.46e-10, 5.77e-10), (0.0, 7.02e-08)])
def test_kappa_invariance_evidence_does_not_depend_on_the_round_off_of_a_pass(rel_a, rel_b):
    cid = fsc.edge_claim_id("kappa-beta", "R5.2", 1, 4)

    def evidence(rel):
        claims = fsc.face_study_claims(None, None, edge_rows("R5.2", 1, kappa_rel=rel), CLAIMS_CFG, {}, FIT_THETA_MAX)
        return claims.set_index("claim_id").loc[cid, "evidence"]

    assert evidence(rel_a) == evidence(rel_b)
    assert "0.01" in evidence(1e-2)                                        # a failure prints its value


def test_sufficiency_evidence_does_not_depend_on_round_off():
    def evidence(noise):
        beta = pd.DataFrame({"beta": [0.5, 0.3, 0.0], "beta_v1_zero": [0.5 + noise, 0.2, 0.0]})
        return membranes.sufficiency_claim(beta)

    assert evidence(6.4e-8) == evidence(-3e-9) and evidence(6.4e-8)[0] == "PASS"
    verdict, text = evidence(0.01)                                         # β_h below its restriction: fails
    assert verdict == "FAIL" and "-0.01" in text


def test_arc_route_agreement_is_stated_against_its_tolerance():
    def joined(rel):
        return pd.DataFrame({"beta": [1.0, 0.5], "beta_paper": [1.0 + rel, 0.5], "kernel_dim": [0, 0],
                             "kernel_dim_paper": [0, 0]})

    assert arc._round_off(joined(1.68e-14)) == arc._round_off(joined(0.0))
    verdict, text = arc._round_off(joined(1e-6))
    assert verdict == "FAIL" and "1e-06" in text


def _elastic_patch(err):
    rows = [dict(case=case, k=1, N1=a, N2=b, kernel_dim=0, lambda_max_rel_error=e, lambda_end_rel_error=e,
                 lambda_middle_rel_error=e / 2, u_max_rel_error=e / 10, passes=e < elastic.PASS_RTOL)
            for case, e in (("R5.2", err), ("T3", 1.0)) for a, b in ((5, 4), (7, 3))]
    return elastic.patch_claims(pd.DataFrame(rows)).set_index("claim_id").evidence


def test_elastic_patch_evidence_does_not_depend_on_the_round_off_of_a_pass():
    a, b = _elastic_patch(1.3e-13), _elastic_patch(3.8e-13)
    assert a["elastic-patch-Rem5.2-k1"] == b["elastic-patch-Rem5.2-k1"]
    assert "middle half 0.5" in a["elastic-patch-Thm3-k1"]                # the failing space keeps its values


def test_elastic_patch_bound_is_the_tables():
    from infsup_contact.study.patch.segment import PASS_RTOL

    assert elastic.PASS_RTOL == PASS_RTOL
