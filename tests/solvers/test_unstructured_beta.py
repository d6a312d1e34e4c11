"""β_h of the stable space on unstructured non-matching faces (issue 28, item 1): Netgen meshes of
Ω1 and Ω2 made independently, so no refinement level has matching traces. Thm 3's space
(continuous P_1 vanishing on ∂Γ) keeps β_H bounded under refinement while its β_L² decays like
h^{1/2} (the L² norm is h^{-1/2} times weaker than H^{-1/2}_00 on mesh functions): compared as
ratios between levels, no reference numbers."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.models import make_model
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.request import MeshOptions

MODEL = make_model("membranes3d")
LEVELS = (3, 4, 6)


@pytest.mark.slow_first  # one of the longest tests: started first under xdist (tests/conftest.py)
def test_stable_beta_is_bounded_on_unstructured_refinements():
    case = next(c for c, s in SPACES.items() if s.lagrange == (True, True) and not s.dual and s.degree(1) == 1)
    rows = [pd.DataFrame(beta_rows("unstructured", 1, n, n, cases=[case], model=MODEL, mesh=MeshOptions(element="tet")))
            .set_index("norm").beta for n in LEVELS]
    beta_h = np.array([r["H"] for r in rows])
    beta_l2 = np.array([r["L2"] for r in rows])
    assert np.all(beta_h > 0) and np.all(beta_l2 > 0)
    h_ratio = LEVELS[0] / LEVELS[-1]
    # β_H: no decay beyond a quarter power of h (a bounded sequence); β_L²: the h^{1/2} decay
    assert beta_h.min() / beta_h[0] >= h_ratio ** 0.25
    assert beta_l2[-1] / beta_l2[0] < beta_h[-1] / beta_h[0]
    assert beta_l2[-1] / beta_l2[0] < h_ratio ** 0.25
