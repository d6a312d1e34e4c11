"""β_h of the face spaces on the cylinder (:mod:`infsup_contact.discretization.face.shapes.cylinder`).

The 3D membranes on hexahedra, Γ the part of the cylinder of radius R (R = inf: the flat face, the
reference), coupled ``exact`` (both traces mapped to the cylinder) or by ``projection`` (the
mortar codes' normal projection of the master onto the slave's discrete surface), on matching and
non-matching pairs: one ``infsup-contact beta`` row per (R, coupling, pair, case, norm), with the
columns of ``beta`` plus ``model``, ``element``, ``gamma``, ``radius`` and ``coupling``. What it shows: how
far curvature and projection move β_h and whether they change a kernel.
"""
from __future__ import annotations

import math

RADII = (math.inf, 8.0, 2.0, 1.25)
"""From the flat face to a strongly curved one (Ω1's inner radius R − 1 = 0.25)."""
PAIRS = ((4, 4), (4, 5), (8, 8), (8, 9))
"""Matching and non-matching (N : N + 1) pairs."""
COUPLINGS = ("exact", "projection")


def cylinder_rows(radii=RADII, pairs=PAIRS, k: int = 1, cases=None, couplings=COUPLINGS,
                  norms=("H", "L2")) -> list[dict]:
    """β_h rows (module docstring) of ``cases`` (None: every face space of k on hexahedra) at each
    radius, coupling and pair (N1, N2), both norms; a bad argument raises
    :class:`~infsup_contact.errors.InputError` naming its key (the request's checks)."""
    from ...models import model_of_dim
    from ...solvers.infsup import beta_rows
    from ...solvers.request import MeshOptions, resolve_gamma
    from ...solvers.side_cache import SideCache

    membranes3d = model_of_dim(3)  # the registry's 3D membranes, asked for (not imported by module)
    rows = []
    for radius in radii:
        for coupling in couplings:
            mesh = MeshOptions(element="hex")
            gamma = resolve_gamma(membranes3d, element="hex", gamma="cylinder", radius=float(radius), coupling=coupling)
            cache = SideCache.for_sweep(membranes3d, "structured", k, pairs, mesh, gamma)  # Ω2 at N shared by N:N, N+1:N
            for n1, n2 in pairs:
                found = beta_rows("structured", k, n1, n2, cases, norms=tuple(norms), model=membranes3d,
                                  side_cache=cache, mesh=mesh, gamma=gamma)
                rows += [dict(r, model=membranes3d.name, element="hex", gamma="cylinder", radius=float(radius),
                              coupling=coupling) for r in found]
    return rows
