"""β_h (eq. (4.5)) of the plane-strain elastic pair, next to the membranes on the same meshes.

The elastic bodies are Ω1 = (0,1)², Ω2 = (0,1)×(1,2), clamped on ∂Ω_i∖Γ (the paper's
geometry, so the H^{-1/2}_00(Γ) norm applies as is); b(v, μ) sees the normal components
(:mod:`infsup_contact.models.elastic`). Every row also carries β_h of the membranes with
c_i = E_i on the same meshes and multipliers (``beta_membranes``) and the factor
``bound_factor`` = 1/sqrt(2μ̂ + λ̂) of the exact discrete bound

    β_h^elastic >= β_h^membranes / sqrt(2μ̂ + λ̂),     2μ̂ + λ̂ = (1 − ν)/((1 + ν)(1 − 2ν)):

for every scalar w of V_h (the membranes' space), v = (0, w) is an elastic displacement of
V_h with b(v, μ) = b(w, μ) and a(v, v) = Σ E_i (μ̂‖∂_x w_i‖² + (2μ̂ + λ̂)‖∂_y w_i‖²) ≤
(2μ̂ + λ̂) Σ E_i |w_i|_1², so the elastic sup over v is at least the membranes' one divided
by sqrt(2μ̂ + λ̂). As ν → 1/2 the factor is ~ sqrt(3(1 − 2ν)/2).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ...discretization.spaces import registry
from ...models import DEFAULT_MODEL, model_taking
from ...models.plane_strain import lame
from ...solvers.request import NO_OPTIONS, MeshOptions
from .batch_rows import beta_batch_rows

ELASTIC = model_taking("nu").name
"""The model this study compares with the membranes: the registered one whose bodies take a
Poisson ratio ν (:data:`~infsup_contact.models.MODELS`)."""
MEMBRANES = DEFAULT_MODEL

COLUMNS = ["model", "case", "k", "family", "N1", "N2", "multiplier_mesh", "E1", "E2", "nu", "norm", "beta",
           "kernel_dim", "structural_kernel_dim", "kernel_detected", "kernel_margin_decades", "kernel_decision",
           "smallest_nonzero", "beta_v1_zero", "dim_M", "dim_W", "ndof",
           "beta_membranes", "kernel_dim_membranes", "kernel_decision_membranes", "bound_factor"]


def bound_factor(nu: float) -> float:
    """1/sqrt(2μ̂ + λ̂) at E = 1 (module docstring)."""
    mu, lam = lame(nu)
    return 1.0 / np.sqrt(2.0 * mu + lam)


def membranes_rows(family: str, k: int, pairs, E=(1.0, 1.0), cases=None, norms=("H",),
                   mesh: MeshOptions = NO_OPTIONS) -> pd.DataFrame:
    """The membranes' β_h rows (c = E) on every pair, G_h = trace of Ω2: they do not depend on
    ν, so a ν sweep computes them once."""
    cases = registry.common_ids(k) if cases is None else list(cases)
    return beta_batch_rows(MEMBRANES, family, k, pairs, cases, ("omega2",), (tuple(E),), norms, mesh=mesh)


def elastic_beta_rows(family: str, k: int, pairs, nu: float = 0.3, E=(1.0, 1.0), cases=None,
                      norms=("H",), membranes: pd.DataFrame | None = None,
                      mesh: MeshOptions = NO_OPTIONS) -> pd.DataFrame:
    """β_h of the elastic pair (and of the membranes, c = E) for each (N1, N2) in ``pairs``,
    every case valid for k (default) and norm; G_h = trace of Ω2 (the paper's choice). Both
    come from the β_h batches' study path (:func:`~infsup_contact.study.beta.batch_rows.beta_batch_rows`).
    ``membranes``: the membranes' rows of :func:`membranes_rows` where already computed."""
    cases = registry.common_ids(k) if cases is None else list(cases)
    if membranes is None:
        membranes = membranes_rows(family, k, pairs, E, cases, norms, mesh)
    el = beta_batch_rows(ELASTIC, family, k, pairs, cases, ("omega2",), (tuple(E),), norms,
                         model_params={"nu": nu}, mesh=mesh)
    out = []
    for r, m in zip(el.to_dict("records"), membranes.to_dict("records"), strict=True):
        assert (r["N1"], r["N2"], r["case"], r["norm"]) == (m["N1"], m["N2"], m["case"], m["norm"])
        out.append(dict(r, model=ELASTIC, E1=E[0], E2=E[1], nu=nu, beta_membranes=m["beta"],
                        kernel_dim_membranes=m["kernel_dim"], kernel_decision_membranes=m["kernel_decision"],
                        bound_factor=bound_factor(nu)))
    return pd.DataFrame(out, columns=COLUMNS)


def nu_sweep_rows(k: int, ns, nus, family: str = "structured", cases=None) -> pd.DataFrame:
    """The ν → 1/2 sweep: matching meshes N1 = N2 = N for each N in ``ns``, each ν in ``nus``,
    H norm."""
    pairs = [(n, n) for n in ns]
    mem = membranes_rows(family, k, pairs, cases=cases)
    frames = [elastic_beta_rows(family, k, pairs, nu, cases=cases, membranes=mem) for nu in nus]
    return pd.concat(frames, ignore_index=True)
