"""Whether 1 ∈ M_h, computed on the space a solver uses (its own G_h and construction).

What a patch test of a uniform pressure asks of M_h (study/patch/: segment.py, face.py).
``SpaceSpec.contains_constants(k)`` answers it for the segment's space on a uniform partition
(and for a face-only space on its n × n grid); on a face the construction can differ from the
1D one in a way the segment cannot show: the TRI3 dual with Wohlmuth's boundary modification
on the six-tetrahedra faces has two corner triangles whose three vertices all lie on ∂Γ, so
no basis function lives there and the constants are lost although the segment's DUAL keeps
them. This check asks the space itself.
"""
from __future__ import annotations

import numpy as np

SAMPLES_PER_DIRECTION = 5
"""Points per direction and cell of the least-squares fit (more than any degree's needs)."""
RESIDUAL_TOL = 1e-10
"""Largest |fit − 1| for which the constant counts as in the span."""


def axis_samples(breakpoints, per: int, offset: float) -> np.ndarray:
    """``per`` points strictly inside every interval of a 1D partition, at (a + offset/per … ) of
    each, in order."""
    g = np.asarray(breakpoints, dtype=float)
    t = (np.arange(per) + offset) / per
    return (g[:-1, None] + np.outer(np.diff(g), t)).ravel()


def interior_samples(partition, per: int = SAMPLES_PER_DIRECTION) -> np.ndarray:
    """Points strictly inside every cell of a segment partition (1D array of breakpoints) or of a
    face partition (its ``interior_points``: off the cells' edges and diagonals)."""
    if np.ndim(partition) == 1:
        return axis_samples(partition, per, 0.31)
    return partition.interior_points(per)


def spans_constants(space) -> bool:
    """Whether the least-squares fit of the constant 1 by ``space``'s basis leaves no residual
    (≤ :data:`RESIDUAL_TOL`) at points inside every cell of the partition it is polynomial on."""
    partition = space.breakpoints if space.pieces is None else space.pieces
    x = interior_samples(partition)
    phi = space.evaluate(x)
    coef = np.linalg.lstsq(phi, np.ones(len(x)), rcond=None)[0]
    return bool(np.max(np.abs(phi @ coef - 1.0)) <= RESIDUAL_TOL)
