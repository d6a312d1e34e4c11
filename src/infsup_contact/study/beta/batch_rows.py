"""β_h of a batch of mesh pairs for any model: the one study path of the β_h tables.

The membranes' batches (``workflow/scripts/beta_job.py``: every pair of one (family, k) ×
seed × case × multiplier mesh × c pair × norm, rows tagged with their series) and the elastic
ones (:mod:`infsup_contact.study.beta.elastic`, ``workflow/scripts/model_job.py``) both
call :func:`beta_batch_rows`; the model is named (``models.make_model``) or passed, never
imported here. The pairs of a batch share one side cache, so a side common to several pairs
((16, 16), (17, 16), (24, 16): Ω2's) is factorized once.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from ...models import make_model
from ...models.contract import Model
from ...solvers.request import NO_OPTIONS, MeshOptions
from ...solvers.side_cache import SideCache
from ...solvers.infsup import NORMS, beta_rows_all


def as_model(model, **params) -> Model:
    """A model from its registered name (with its parameters, e.g. ``nu``) or as given."""
    if isinstance(model, str):
        return make_model(model, **params)
    if params:
        raise ValueError(f"model parameters {sorted(params)} need a model name, not a model")
    return model


def beta_batch_rows(model, family: str, k: int, pairs, cases=None, multiplier_meshes=("omega2",),
                    c_pairs=((1.0, 1.0),), norms=NORMS, *, seeds=None, series=None, model_params=None,
                    side_cache: SideCache | None = None, mesh: MeshOptions = NO_OPTIONS,
                    gamma=None) -> pd.DataFrame:
    """β_h rows of ``model`` on every (N1, N2) of ``pairs``, one frame.

    Parameters
    ----------
    model
        A registered model name (built with ``model_params``) or a model.
    cases, multiplier_meshes, c_pairs, norms
        As in :func:`~infsup_contact.solvers.infsup.beta_rows_all` (``cases=None``: every
        registered space defined for k).
    seeds
        Perturbed meshes: the seeds, each a mesh of every pair (the ``seed`` of ``mesh``); the
        rows get a ``seed`` column (empty for a seed ``None``: a deterministic family in a
        table that has seeds). ``None``: one mesh per pair and no ``seed`` column.
    series
        (N1, N2) → the series ids it belongs to: the pair's rows are written once per series,
        with a ``series`` column. ``None``: once, no ``series`` column.
    side_cache
        Side operators already built (default: a cache for this batch).
    mesh
        Mesh parameters of every pair (e.g. ``MeshOptions(alpha=0.2)`` of the perturbed family).
    gamma
        The Γ of every pair (:func:`~infsup_contact.solvers.request.resolve_gamma`: the arc, the
        cylinder); None: the model's flat Γ.

    Rows in the order pair, seed, series, then :func:`beta_rows_all`'s (multiplier mesh,
    case, c pair, norm).
    """
    model = as_model(model, **(model_params or {}))
    variants = {None: mesh} if seeds is None else {
        s: mesh if s is None else replace(mesh, seed=int(s)) for s in seeds}
    sides = SideCache() if side_cache is None else side_cache
    for options in variants.values():
        sides.expect(model, family, k, pairs, options, gamma)
    frames = []
    for n1, n2 in pairs:
        for seed, options in variants.items():
            rows = pd.DataFrame(beta_rows_all(family, k, n1, n2, cases, tuple(multiplier_meshes),
                                              [tuple(c) for c in c_pairs], norms, model=model,
                                              side_cache=sides, mesh=options, gamma=gamma))
            if seeds is not None:
                rows["seed"] = np.nan if seed is None else seed
            for name in ([None] if series is None else series[(n1, n2)]):
                frames.append(rows if name is None else rows.assign(series=name))
    return pd.concat(frames, ignore_index=True)
