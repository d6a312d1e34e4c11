"""Small synthetic face tables (study/face_claims.py, report/face.py) for the tests: rows of
the face β table whose kernel is the dimension count (or as told) and whose β follows a given
law of N; shared by tests/test_face_claims.py and the paper build of tests/test_paper.py."""
from __future__ import annotations

import pandas as pd

from infsup_contact.discretization.registry import SPACES
from infsup_contact.discretization.square import SQUARE, SQUARE_TRIG
from infsup_contact.study.face_claims import face_claims, matching_kernel, planar_kernel

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
    """``beta`` and ``claims`` of a stable and an unstable space on hexahedra and tetrahedra."""
    beta = pd.concat([face_rows("T3", 1), face_rows("R5.2", 1), face_rows("T3", 1, element="tet")],
                     ignore_index=True)
    return {"beta": beta, "claims": face_claims(beta, CLAIMS_CFG, {"hex": SQUARE, "tet": SQUARE_TRIG})}
