"""Small synthetic face tables (study/face_claims.py, report/sections/face.py) for the tests: rows of
the face β table whose kernel is the dimension count (or as told) and whose β follows a given
law of N; shared by tests/study/test_face_claims.py and the paper build of tests/report/test_paper.py."""
from __future__ import annotations

import pandas as pd

from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.study.claims.membranes3d import face_claims, matching_kernel, planar_kernel

CLAIMS_CFG = {"slope_tolerance": 0.15, "beta_floor": 1e-3, "confidence": 0.95, "fit_window": 5}
NS = (4, 6, 8, 10, 12)


def face_rows(case, k, element="hex", beta_h=lambda n: 0.8, beta_l2=lambda n: 0.8 * n ** -0.5, kernel=None,
          pairs=((4, 5), (6, 7))):
    spec = SPACES[case]
    out = []
    for n1, n2 in [(n, n) for n in NS] + list(pairs):
        gamma = SQUARE if element == "hex" else SQUARE_TRIG
        count = matching_kernel(spec, k, n2, gamma) if n1 == n2 else planar_kernel(spec, k, n1, n2, gamma)
        dim = count if kernel is None else kernel(n1, n2, count)
        for norm, b in (("H", beta_h(n2)), ("L2", beta_l2(n2))):
            out.append(dict(element=element, case=case, k=k, family="structured", N1=n1, N2=n2, norm=norm,
                            beta=0.0 if dim else b, kernel_dim=dim, structural_kernel_dim=count,
                            kernel_decision="clear", kernel_margin_decades=5.0, smallest_nonzero=0.5))
    return pd.DataFrame(out)



def small_face_tables() -> dict:
    """``beta`` and ``claims`` of a stable and an unstable space on hexahedra and tetrahedra, and
    the three face studies' tables with their claims (:func:`small_study_tables`)."""
    beta = pd.concat([face_rows("T3", 1), face_rows("R5.2", 1), face_rows("T3", 1, element="tet")],
                     ignore_index=True)
    return {"beta": beta, "claims": face_claims(beta, CLAIMS_CFG, {"hex": SQUARE, "tet": SQUARE_TRIG}),
            **small_study_tables()}


THETAS = (1.0, 0.5, 0.2, 0.1, 0.05, 0.03, 0.02, 0.015, 0.01)
FIT_THETA_MAX = 0.05


def patch_rows(case, k, element="hex", err=lambda passes: 1e-13 if passes else 1.0, passes=True,
               pairs=((4, 5), (7, 8))) -> pd.DataFrame:
    """Rows of results/tables/membranes3d/patch.csv for one (case, k, element): errors ``err(passes)``."""
    return pd.DataFrame([dict(scene="face-patch", case=case, k=k, family="structured", element=element, N1=a, N2=b,
                              lambda_max_rel_error=err(passes), u_max_rel_error=err(passes) / 10, kernel_dim=0,
                              passes=passes) for a, b in pairs])


def alpha_rows(element="QUAD8", alphas=(0.1, 0.125, 0.2, 0.3), n=4) -> pd.DataFrame:
    """Rows of results/tables/membranes3d/alpha.csv: the weights from face_dual (two evaluations of the same
    numbers here), accepted where positive, β_h = 1 there."""
    from infsup_contact.discretization.face.spaces.dual_bases import weight_fractions

    out = []
    for a in alphas:
        w = float(weight_fractions(element, a).min())
        ok = w > 1e-12
        out += [dict(element=element, alpha=a, N=n, norm=norm, min_weight=w, min_weight_gauss=w, cond_A=10.0,
                     weights_positive=ok, accepted=ok, refused=not ok, beta=1.0 if ok else float("nan"),
                     kernel_dim=0 if ok else -1) for norm in ("H", "L2")]
    return pd.DataFrame(out)


def edge_rows(case, k, beta_h=lambda t: t / 2, cond=lambda t: 10.0, n=4, kappa_rel=0.0) -> pd.DataFrame:
    """Rows of results/tables/membranes3d/edge_dropping.csv for one (case, k): β_H = beta_h(θ), β_L2 = β_H / 10
    (its κ-scaled route off by ``kappa_rel``), every cond_*_kappa = cond(θ), unscaled 1/θ²."""
    out = []
    for t in THETAS:
        b = beta_h(t)
        out.append(dict(case=case, k=k, N=n, N2=2 * n, theta=t, beta_H=b, beta_L2=b / 10,
                        beta_L2_kappa=b / 10 * (1 + kappa_rel), beta_H_resolved=True, beta_L2_resolved=True,
                        beta_L2_kappa_resolved=True, h_capped=False, cond_D=1 / t ** 2, cond_S=1 / t ** 2,
                        cond_D_kappa=cond(t), cond_S_kappa=cond(t), fit_theta_max=FIT_THETA_MAX))
    return pd.DataFrame(out)


def small_study_tables() -> dict:
    """``patch``, ``alpha``, ``edge`` and their ``study_claims`` (hexahedra): a space with and one
    without the constants, QUAD8 around its threshold, a full-order k = 1 space decaying like θ
    and a stable lower-order k = 2 space bounded."""
    from infsup_contact.study.claims.membranes3d_studies import face_study_claims

    patch = pd.concat([patch_rows("R5.2", 1), patch_rows("T3", 1, passes=False)], ignore_index=True)
    alpha = alpha_rows()
    edge = pd.concat([edge_rows("R5.2", 1), edge_rows("T4", 2, beta_h=lambda t: 1.0)], ignore_index=True)
    claims = face_study_claims(patch, alpha, edge, CLAIMS_CFG, {"hex": SQUARE}, FIT_THETA_MAX)
    return {"patch": patch, "alpha": alpha, "edge": edge, "study_claims": claims}
