"""The 3D face's Schur complement alone (``what`` = ``face_schur``), measured on a β setup
(:mod:`.beta_bench`): each body's S = K_ΓΓ − K_ΓI K_II⁻¹ K_IΓ by the routes of
:func:`~infsup_contact.la.schur.gamma_factorization`, ``ratio_to_ours`` against PARDISO's partial
factorization: the measurement behind the route ``"auto"`` takes on a face (CHOLMOD and MUMPS have
no wheel for this Python and numpy on PyPI; scikit-sparse and python-mumps 0.0.2 were tried, see
docs/models.md). ``max_abs_diff`` is the relative difference of S to the first route's.
"""
from __future__ import annotations

import numpy as np

from ..la import pardiso
from ..la.schur import gamma_factorization
from .harness import _log, _row, run_interleaved

SCHUR_ROUTES = ("pardiso", "nested", "solves")
SOLVES_MAX_GAMMA = 600
"""The solves route (n_Γ solves) is timed only up to this many Γ dofs: beyond it, minutes."""
INCLUDES = {
    "pardiso": "Schur complement per body: PARDISO partial factorization (METIS)",
    "nested": "Schur complement per body: SuperLU, Γ-last nested dissection, S from the factors",
    "solves": "Schur complement per body: SuperLU MMD_AT_PLUS_A + one solve per Γ dof",
}


def schur_routes(setup) -> dict:
    """{route: callable} giving both bodies' Schur complements by that route (the solves route
    only while n_Γ ≤ :data:`SOLVES_MAX_GAMMA`; PARDISO only where it loads)."""
    n_gamma = max(len(s.trace.gamma_dofs) for s in setup.sides)
    names = [r for r in SCHUR_ROUTES if (r != "solves" or n_gamma <= SOLVES_MAX_GAMMA)
             and (r != "pardiso" or pardiso.available())]
    return {r: (lambda r=r: [gamma_factorization(s.stiffness, len(s.trace.gamma_dofs), r,
                                                 gamma_dim=s.trace.gamma.dim).schur
                             for s in setup.sides]) for r in names}


def _schur_diff(got: list, ref: list) -> float:
    """max relative |S_route − S_ref| over both bodies."""
    return float(max(np.abs(a - b).max() / np.abs(b).max() for a, b in zip(got, ref)))


def schur_rows(setup, repeats: int, budget: float) -> list:
    """The ``face_schur`` rows of one setup: each Schur route timed interleaved, ratios to the
    first route (PARDISO where it loads)."""
    res = run_interleaved(schur_routes(setup), repeats, budget)
    ref, t_ref = next(iter(res.values()))
    rows = []
    for name, (got, times) in res.items():
        rows.append(_row("face_schur", name, setup.k, setup.n, times, float(np.median(t_ref)), np.nan,
                         other="ratio_to_limit", max_abs_diff=_schur_diff(got, ref), n_problems=len(setup.sides),
                         ndof=setup.ndof, dim_M_max=max(len(s.trace.gamma_dofs) for s in setup.sides),
                         includes=INCLUDES[name], **setup.mesh_options))
        _log(f"  schur {name:8s} {np.median(times):9.4f} s  rel diff {rows[-1]['max_abs_diff']:.2e}")
    return rows
