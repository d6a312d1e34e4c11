"""The tables of the 3D elastic bodies on the contact face (config ``studies.elastic3d``;
rules/models.smk with plans/elastic3d.py): β_h per Poisson ratio and the elastic face patch test.

Pure functions of the config section returning DataFrames; the job scripts only read and write.

* :func:`beta_frame`: β_h in the H^{-1/2}_00(Γ) norm (G_h = trace of Ω2) of ``elastic3d.model``
  (:mod:`infsup_contact.models.elastic3d`) for one element, every k, every case the element's
  face builds: at ν = ``elastic3d.nu`` on every matching N and non-matching pair, and at
  every ν of ``elastic3d.nu_sweep`` on its matching meshes (the ν → 1/2 sweep of
  :mod:`.claims.elastic3d`). Each (ν, pair) is computed once, through the one β batch path
  of every model (:func:`~.beta_batches.beta_batch_rows`, the model built with ``nu``).
* :func:`patch_frame`: the elastic face patch test (:mod:`.patch.elastic3d`) on the pairs of
  ``elastic3d.patch`` at ν = ``elastic3d.nu``, E1 = E2 = 1.
"""
from __future__ import annotations

import pandas as pd

NORMS = ("H",)
"""The norm of every β row here: the exact H^{-1/2}_00(Γ) (the claims are about β_H)."""


def nu_pairs(fe: dict) -> list:
    """(ν, [(N1, N2), …]) in computing order: the table's ν on every matching N and
    non-matching pair, then each other ν of the sweep on the sweep's meshes (each once)."""
    base = [(int(n), int(n)) for n in fe["N"]] + [tuple(int(x) for x in p) for p in fe["nonmatching"]]
    sweep = [(int(n), int(n)) for n in fe["nu_sweep"]["N"]]
    out = [(float(fe["nu"]), list(dict.fromkeys(base)))]
    out += [(float(nu), sweep) for nu in dict.fromkeys(fe["nu_sweep"]["nu"]) if float(nu) != float(fe["nu"])]
    return out


def face_cases(fe: dict, k: int, gamma) -> list:
    """The cases of ``elastic3d.cases`` defined for k and built by the face ``gamma``."""
    from ...discretization.spaces.registry import SPACES, ids_valid_for

    return [c for c in ids_valid_for(k, fe["cases"]) if gamma.builds(SPACES[c])]


def beta_frame(fe: dict, element: str) -> pd.DataFrame:
    """β_H rows of one element (module docstring), columns of the β table plus ``model``,
    ``element`` and ``nu`` (timings dropped: they belong to the benchmark tree)."""
    from ...solvers.request import MeshOptions
    from ..beta.batch_rows import beta_batch_rows
    from ..claims.membranes3d import element_interfaces

    gamma = element_interfaces(fe["model"], [element])[element]
    frames = []
    for k in fe["k"]:
        cases = face_cases(fe, int(k), gamma)
        if not cases:
            continue
        for nu, pairs in nu_pairs(fe):
            rows = beta_batch_rows(fe["model"], "structured", int(k), pairs, cases, ("omega2",), norms=NORMS,
                                   model_params={"nu": nu}, mesh=MeshOptions(element=element))
            frames.append(rows.assign(nu=nu))
    frame = pd.concat(frames, ignore_index=True)
    frame = frame.drop(columns=[c for c in frame.columns if c.startswith("t_")])
    frame.insert(0, "element", element)
    frame.insert(0, "model", fe["model"])
    return frame


def patch_frame(fe: dict) -> pd.DataFrame:
    """The elastic face patch test (:func:`~.elastic_face_patch.elastic_face_patch_rows`) for
    every element of ``elastic3d.patch``, the cases its face builds, every k and pair."""
    from ...models import make_model
    from ..patch.elastic3d import elastic_face_patch_rows
    from ..claims.membranes3d import element_interfaces

    pc = fe["patch"]
    model = make_model(fe["model"], nu=float(fe["nu"]))
    gammas = element_interfaces(model, pc["elements"])
    rows = []
    for element in pc["elements"]:
        for k in pc["k"]:
            cases = face_cases(fe, int(k), gammas[element])
            rows += elastic_face_patch_rows(cases, [int(k)], [tuple(p) for p in pc["pairs"]], nu=float(fe["nu"]),
                                            element=element, model=model)
    frame = pd.DataFrame(rows)
    return frame.drop(columns=[c for c in ("seconds",) if c in frame.columns])
