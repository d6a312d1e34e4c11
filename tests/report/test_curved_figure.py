"""fig12_curved (report/figures/curved.py) from a small arc study's tables: the PDF and PNG are written."""
from __future__ import annotations

import numpy as np
import pandas as pd

from infsup_contact.plans import study_of
from infsup_contact.plans.arc import PATCH
from infsup_contact.report.figures.curved import plot_curved

ENTRY = {"study": "arc", "k": [1], "radii": [2], "couplings": ["exact"],
         "series": {"plus1": [[4, 5], [6, 7], [8, 9]]}, "cases": ["T3", "R5.2", "DUAL"],
         "patch": {"k": [1], "pairs": [[5, 4], [10, 8]], "c": [1, 3]}}


def test_the_curved_figure_is_drawn_from_the_study_tables(tmp_path):
    study = study_of({"studies": {"arc": ENTRY}}, "arc")
    jobs = study.jobs()
    beta = pd.concat([jobs[j].run() for j in jobs if j != PATCH], ignore_index=True)
    patch = jobs[PATCH].run()
    x = np.linspace(0.0, 1.0, 41)
    modes = pd.DataFrame(dict(case="DUAL-ALL", multiplier_mesh="omega2", c1=1.0, c2=1.0, norm="H", beta=1e-6, x=x,
                              mu=np.exp(-50 * x)))
    pdf, png = tmp_path / "f.pdf", tmp_path / "f.png"
    plot_curved(beta, patch, modes, pdf, png)
    assert pdf.stat().st_size > 1000 and png.stat().st_size > 1000
