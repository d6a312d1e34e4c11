"""The face studies' tables of the model table's ``membranes3d`` study (rules/models.smk with
plans/membranes3d.py): one pure function per study, each reading its own sub-section
(``membranes3d.patch``, ``membranes3d.alpha``, ``membranes3d.edge_dropping``) and the face's shared keys (model, cases, norms), returning a DataFrame.
:data:`FACE_STUDIES` maps the sub-section's key to its function, so the job script names none."""
from __future__ import annotations

import pandas as pd


def patch_frame(fc: dict) -> pd.DataFrame:
    """The 3D contact patch test (:func:`.face_patch.face_patch_table`): every case of
    ``membranes3d.cases`` the element's face builds, each k and non-matching pair of ``membranes3d.patch``."""
    from ..patch.face import face_patch_table

    sc = fc["patch"]
    return pd.DataFrame(face_patch_table(fc["cases"], sc["k"], [tuple(p) for p in sc["pairs"]], sc["elements"],
                                         fc["model"]))


def alpha_frame(fc: dict) -> pd.DataFrame:
    """The α sweep of the transformed dual bases (:func:`.face_alpha.sweep`) in ``membranes3d.norms``."""
    from .alpha import sweep

    sc = fc["alpha"]
    return pd.DataFrame(sweep(tuple(sc["N"]), tuple(sc["alphas"]), tuple(sc["elements"]), norms=tuple(fc["norms"]),
                              model=fc["model"]))


def edge_frame(fc: dict) -> pd.DataFrame:
    """Edge dropping (:func:`.edge_table.edge_table`) for the edge cases among ``membranes3d.cases``,
    its columns plus the claims' fit window ``fit_theta_max``."""
    from .edge_table import COLUMNS, edge_table

    sc = fc["edge_dropping"]
    frame = pd.DataFrame(edge_table(tuple(sc["k"]), tuple(sc["N"]), tuple(sc["theta"]), cases=fc["cases"],
                                    n2_factor=sc["n2_factor"]))
    return frame[[c for c in COLUMNS if c in frame.columns]].assign(fit_theta_max=sc["fit_theta_max"])


FACE_STUDIES = {"patch": patch_frame, "alpha": alpha_frame, "edge_dropping": edge_frame}
"""``face.<key>`` → its table function (the rule's ``{study}`` wildcard, the output's name)."""
