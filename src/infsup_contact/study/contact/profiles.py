"""Contact solutions sampled for plotting: profiles along Γ and displacements at vertices.

Two tidy tables per solve (the data of figure 5):

* **Γ profiles** (long format) ``case, k, N, x, quantity, value`` with ``quantity`` one
  of ``gap`` (u_{2,h} − u_{1,h}), ``lambda`` (λ_h), ``u1``, ``u2``, sampled at
  ``per_interval`` points in every interval of the multiplier partition G_h.  The first
  and last point of an interval sit a relative 1e-9 inside it, so a discontinuous λ_h
  (cases T4, R5.4) shows both one-sided values at every breakpoint and a line plot draws
  its jumps as (near-)vertical segments.
* **field values** ``case, k, N, side, x, y, u``: u_{i,h} at the vertices of the mesh of
  Ω_i (x, y global, so Ω2 has 1 ≤ y ≤ 2).

Pure functions over a solved problem; no I/O.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ...contact.contact import ContactSolution, gamma_values, lambda_values, solve_contact
from ...solvers.request import NO_OPTIONS, MeshOptions
from .scenes import membranes

GAMMA_COLUMNS = ["case", "k", "N", "x", "quantity", "value"]
FIELD_COLUMNS = ["case", "k", "N", "side", "x", "y", "u"]
QUANTITIES = ("gap", "lambda", "u1", "u2")

#: relative inset of the first/last sample of an interval (one-sided values at breakpoints)
_INSET = 1e-9


def gamma_sample_points(breakpoints, per_interval: int = 9) -> np.ndarray:
    """``per_interval`` points in each interval of ``breakpoints``, ends inset by 1e-9·h.

    Returns a non-decreasing array of length ``per_interval × (len(breakpoints) − 1)``.
    """
    if per_interval < 2:
        raise ValueError("per_interval must be >= 2")
    x = np.asarray(breakpoints, dtype=float)
    a, b = x[:-1, None], x[1:, None]
    t = np.linspace(_INSET, 1.0 - _INSET, per_interval)[None, :]
    return (a + (b - a) * t).ravel()


def gamma_profile_frame(sol: ContactSolution, case: str, k: int, n: int,
                        per_interval: int = 9) -> pd.DataFrame:
    """The Γ profiles of one solution, long format (:data:`GAMMA_COLUMNS`)."""
    x = gamma_sample_points(sol.space.breakpoints, per_interval)
    u1, u2 = gamma_values(sol, x)
    values = {"gap": u2 - u1, "lambda": lambda_values(sol, x), "u1": u1, "u2": u2}
    frames = [pd.DataFrame({"case": case, "k": k, "N": n, "x": x, "quantity": q, "value": values[q]})
              for q in QUANTITIES]
    return pd.concat(frames, ignore_index=True)[GAMMA_COLUMNS]


def field_frame(sol: ContactSolution, case: str, k: int, n: int) -> pd.DataFrame:
    """u_{1,h}, u_{2,h} at the mesh vertices (:data:`FIELD_COLUMNS`)."""
    import ngsolve

    rows = []
    for side, (gf, op) in enumerate(zip(sol.u, sol.sides), start=1):
        fes = op.trace.fes
        mesh = fes.mesh
        vec = gf.vec.FV().NumPy()
        for v in mesh.vertices:
            dof = fes.GetDofNrs(ngsolve.NodeId(ngsolve.VERTEX, v.nr))[0]
            px, py = v.point
            rows.append((case, k, n, side, px, py, float(vec[dof])))
    return pd.DataFrame(rows, columns=FIELD_COLUMNS)


def contact_profiles(cases, k: int, n: int, scene=None, family: str = "structured",
                     per_interval: int = 9, mesh: MeshOptions = NO_OPTIONS):
    """Solve (4.1) for each case on one N×N mesh pair; return (Γ profiles, field values).

    Parameters
    ----------
    cases : iterable of str
        Case ids (T3 R5.2 T4 R5.4 T5), each valid for degree ``k``.
    k : int
        Displacement degree.
    n : int
        Segments on Γ of both meshes (matching pair N1 = N2 = n).
    scene : scene object, optional
        A :mod:`infsup_contact.study.contact.scenes` scene; default the paper's Fig. 4 loads,
        :func:`infsup_contact.study.contact.scenes.membranes` with c1 = c2 = 1.
    family : str
        Mesh family (default structured).
    per_interval : int
        Samples per interval of G_h for the Γ profiles.
    mesh : MeshOptions
        The mesh parameters (default: the builder's).

    Returns
    -------
    gamma : DataFrame with :data:`GAMMA_COLUMNS`
    field : DataFrame with :data:`FIELD_COLUMNS`
    """
    scene = scene if scene is not None else membranes()
    gammas, fields = [], []
    for case in cases:
        sol = solve_contact(scene, case, k, family, n, n, time_floor=False, mesh=mesh)
        gammas.append(gamma_profile_frame(sol, case, k, n, per_interval))
        fields.append(field_frame(sol, case, k, n))
    return pd.concat(gammas, ignore_index=True), pd.concat(fields, ignore_index=True)


__all__ = ["GAMMA_COLUMNS", "FIELD_COLUMNS", "QUANTITIES", "gamma_sample_points",
           "gamma_profile_frame", "field_frame", "contact_profiles"]
