"""A tensor grid of rectangles of the face (0, 1)²: the trace of a structured hexahedral mesh (and,
each rectangle cut by its diagonal, of a structured tetrahedral one), and the common refinement
of two such traces; the partition :class:`~.square.Square` works on."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...gamma.constants import axis_samples


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

    def interior_points(self, per: int) -> np.ndarray:
        """per² points strictly inside every rectangle, (n, 2): different offsets in x and y, so
        that none lies on a diagonal (the interior edges of the triangle faces)."""
        X, Y = np.meshgrid(axis_samples(self.xs, per, 0.31), axis_samples(self.ys, per, 0.67), indexing="ij")
        return np.column_stack([X.ravel(), Y.ravel()])


def merge_breakpoints(x: np.ndarray, tol: float) -> np.ndarray:
    """Sorted unique values of ``x``, values closer than ``tol`` merged into the first."""
    x = np.unique(np.asarray(x, dtype=float))
    return x[np.concatenate([[True], np.diff(x) > tol])]


def coarsening_cells(a: np.ndarray, b: np.ndarray, tol: float = 1e-12) -> int:
    """Cells of the common coarsening of two 1D partitions (their shared breakpoints)."""
    return int(np.sum(np.min(np.abs(a[:, None] - b[None, :]), axis=1) < tol)) - 1
