"""Γ = (0, 1)² × {1}, the contact face of the 3D model problem (issue 28).

A partition of the face is, for now, a tensor grid of rectangles (:class:`TensorPartition`):
the trace of a structured hexahedral mesh, and the common refinement of two such traces.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class TensorPartition:
    """The rectangles [xs[i], xs[i+1]] × [ys[j], ys[j+1]] of the face (0, 1)².

    Attributes
    ----------
    xs, ys : ndarray
        Sorted breakpoints in x and in y, from 0 to 1.
    """

    xs: np.ndarray
    ys: np.ndarray

    @property
    def cells(self) -> int:
        """Number of rectangles."""
        return (len(self.xs) - 1) * (len(self.ys) - 1)
