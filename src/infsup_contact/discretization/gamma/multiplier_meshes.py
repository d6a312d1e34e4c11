"""The choices of G_h, the multiplier mesh, and how many cells it has before any Γ is built:
shared by every shape of the Γ table (:mod:`.interface`) and the registry's checks."""
from __future__ import annotations

import math

from ...errors import InputError

MULTIPLIER_MESHES = ("omega2", "omega1", "union")
"""The choices of G_h: the trace partition of Ω2 (the paper's default), of Ω1, or their union."""


def intervals_per_direction(n1: int, n2: int, choice: str = "omega2") -> int:
    """Intervals per direction of G_h for uniform traces of ``n1`` and ``n2`` cells per direction:
    N2 (``omega2``), N1 (``omega1``), or N1 + N2 − gcd(N1, N2) for their ``union`` (i/N1 = j/N2
    exactly at the multiples of 1/gcd). The same on every shape of the Γ table (the segment's
    cells; a face's per direction, :meth:`.interface.Interface.multiplier_cells` counts its cells): what a
    request's N means before any Γ is built."""
    return {"omega2": n2, "omega1": n1}.get(choice, n1 + n2 - math.gcd(n1, n2))


def check_choice(choice: str) -> None:
    """:class:`InputError` unless ``choice`` names a G_h (:data:`MULTIPLIER_MESHES`)."""
    if choice not in MULTIPLIER_MESHES:
        raise InputError("multiplier_mesh", ", ".join(MULTIPLIER_MESHES), got=choice)
