"""β_h on the curved segment: every registered space on the arc of radius R, both couplings.

What curvature and the projection do to β_h, to the kernels and to the verdicts
(:mod:`infsup_contact.discretization.segment.arc`, :mod:`~infsup_contact.discretization.segment.projection`):
the membranes' β_h table over radii × couplings × mesh pairs, R = ∞ being the paper's segment,
and the stability verdict of each space over each series of pairs (matching N:N, N:N+1, and
N:≈√2 N), per radius and coupling.
"""
from __future__ import annotations

import math

import pandas as pd

from ...criteria.stability import stability_verdict
from ...discretization.segment.arc import COUPLINGS
from ...models import MODELS
from ...solvers.request import MeshOptions, resolve_gamma
from .batch_rows import beta_batch_rows

PAPER = "paper"
"""The ``coupling`` of the rows computed by the flat segment's own code."""
SERIES_KEYS = ("curvature", "coupling", "series", "case", "k", "family", "norm", "multiplier_mesh")


def arc_rows(radii, series: dict, k: int, cases=None, couplings=COUPLINGS, family: str = "structured",
             norms=("H", "L2"), paper: bool = False, element: str | None = None) -> pd.DataFrame:
    """β_h rows of the membranes on the arc for every radius × coupling × pair of ``series``.

    Parameters
    ----------
    radii : sequence of float
        R > 1, or inf (the paper's flat segment, built by the same code).
    series : dict
        Series id → list of (N1, N2) pairs (e.g. ``{"matching": [(8, 8), (16, 16)]}``).
    k : int
    cases : list of str or None
        Registered segment spaces (None: every one defined for k).
    couplings : sequence of str
        ``exact`` and/or ``projection``.
    paper : bool
        Also the rows of the paper's flat segment by its own code (no Γ option), coupling
        :data:`PAPER`, curvature 0: what R = ∞ must reproduce.
    element : str or None
        None: the 2D membranes, Γ the arc; an element of the 3D membranes (``hex``, ``tet``): Γ the
        part of the cylinder (:mod:`infsup_contact.discretization.face.shapes.cylinder`), the flat face the reference.

    Returns
    -------
    pandas.DataFrame
        ``beta``'s columns (timings dropped) plus ``curvature`` 1/R (0: flat; finite in a table,
        where R = ∞ is not), ``coupling`` and ``series``.
    """
    pairs = sorted({tuple(p) for ps in series.values() for p in ps})
    by_pair = {p: [s for s, ps in series.items() if p in {tuple(q) for q in ps}] for p in pairs}
    model, gamma = ("membranes", "arc") if element is None else ("membranes3d", "cylinder")
    mesh = MeshOptions(element=element)
    runs = [(curvature(r), c, resolve_gamma(MODELS[model], family, element=element, gamma=gamma, radius=float(r), coupling=c))
            for r in radii for c in couplings]
    if paper:
        runs.append((0.0, PAPER, None))
    frames = []
    for kappa, coupling, curved in runs:
        frame = beta_batch_rows(model, family, k, pairs, cases, norms=norms, series=by_pair, mesh=mesh, gamma=curved)
        frame = frame.drop(columns=[c for c in frame.columns if c.startswith("t_")])  # timings: benchmark tree
        frame.insert(0, "coupling", coupling)
        frame.insert(0, "curvature", kappa)
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def arc_verdicts(frame: pd.DataFrame, tol: float, floor: float, confidence: float) -> pd.DataFrame:
    """The stability verdict (:func:`~infsup_contact.criteria.stability.stability_verdict`) of every
    space over every series, per radius, coupling and norm, with its kernel dimensions."""
    out = []
    for key, rows in frame.groupby(list(SERIES_KEYS), sort=False):
        rows = rows.sort_values("N2")
        verdict = stability_verdict(rows, tol, floor, confidence)
        out.append(dict(zip(SERIES_KEYS, key), verdict=verdict["verdict"], min_beta=float(rows.beta.min()),
                        kernel_dims="/".join(str(int(d)) for d in rows.kernel_dim),
                        structural_kernel_dims="/".join(str(int(d)) for d in rows.structural_kernel_dim)))
    return pd.DataFrame(out)


def curvature(radius) -> float:
    """1/R (0 for R = ∞): how the tables name a radius."""
    return 0.0 if math.isinf(float(radius)) else 1.0 / float(radius)


def radius_of(kappa: float) -> float:
    """R = 1/κ (∞ for κ = 0)."""
    return math.inf if kappa == 0 else 1.0 / kappa
