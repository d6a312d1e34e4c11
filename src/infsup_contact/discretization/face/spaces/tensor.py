"""Multiplier spaces on the face Γ = (0, 1)²: tensor products of two 1D spaces.

On a tensor partition G_h = {[x_i, x_{i+1}] × [y_j, y_{j+1}]} (:class:`~.face.partitions.tensor_grid.TensorPartition`)
the face analogues of the paper's spaces (eqs. (5.3), (5.5)) are M_h = M^x ⊗ M^y with M^x, M^y
the segment's 1D space of the same case on the x and y breakpoints
(:meth:`~.face.shapes.square.Square.space` asks the registry's 1D ``build`` for each factor):

* T3   — Q_k continuous vanishing on ∂Γ, M^1_{0,k} ⊗ M^1_{0,k};
* R5.2 — Q_k continuous, M^1_k ⊗ M^1_k;
* T4   — discontinuous Q_{k−2}, M^0_{k−2} ⊗ M^0_{k−2} (k ≥ 2);
* R5.4 — discontinuous Q_{k−1}, M^0_{k−1} ⊗ M^0_{k−1};
* T5   — continuous Q_{k−1}, M^1_{k−1} ⊗ M^1_{k−1} (k ≥ 2);
* DUAL, DUAL-ALL — the tensor products of the 1D dual (biorthogonal) bases.

The basis is the tensor product basis μ_{(a, b)}(x, y) = μ^x_a(x) μ^y_b(y), numbered a·dim M^y + b,
so that every Gram matrix of a separable norm is a Kronecker product (:mod:`.face.norms.tensor`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...gamma.protocol import SpaceDefaults


@dataclass(frozen=True)
class FaceSpace(SpaceDefaults):
    """M^x ⊗ M^y on a tensor partition of the face.

    Attributes
    ----------
    sx, sy : SegmentSpace
        The 1D factors on ``breakpoints.xs`` and ``breakpoints.ys``.
    breakpoints : TensorPartition
        G_h (what :meth:`~.gamma.interface.Interface.coupling_quadrature` reads).
    """

    sx: object
    sy: object
    breakpoints: object

    @property
    def factors(self) -> tuple:
        """(M^x, M^y), for the Kronecker fast paths."""
        return self.sx, self.sy

    @property
    def dim(self) -> int:
        """dim M^x · dim M^y."""
        return self.sx.dim * self.sy.dim

    @property
    def continuous(self) -> bool:
        """Whether both factors are continuous (then so is every product μ^x_a μ^y_b)."""
        return bool(self.sx.continuous and self.sy.continuous)

    @property
    def smooth_tail(self) -> bool:
        """Whether every basis function is continuous and vanishes on ∂Γ, in the Lagrange basis of
        both factors (sine coefficients ~ 1/(m² n²): the series' tail exponent 4, else 2)."""
        return all(s.continuous and s.vanish_at_ends and s.local_coefficients is None for s in self.factors)

    @property
    def degree(self) -> int:
        """Polynomial degree per variable (Q_s: a coupling with Q_k traces has degree k + s per variable)."""
        return max(self.sx.degree, self.sy.degree)

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """All basis functions at points (n, 2): the row-wise Kronecker product of the 1D
        evaluations, shape (n, dim)."""
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        ex, ey = self.sx.evaluate(x[:, 0]), self.sy.evaluate(x[:, 1])
        return (ex[:, :, None] * ey[:, None, :]).reshape(len(x), self.dim)

    def local_values(self, x: np.ndarray):
        """The nonzero pattern of :meth:`evaluate` (the face-splitting product of the 1D
        patterns, :meth:`~.segment.multipliers.SegmentSpace.local_values`): (values, dofs), each
        (n, (s_x + 1)(s_y + 1)), dof −1 where a 1D factor dropped its shape. Every value is the
        same product μ^x_a(x) μ^y_b(y) :meth:`evaluate` forms, so the two agree bit for bit
        (up to the sign of zeros); None where a factor has no such pattern."""
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        lx, ly = self.sx.local_values(x[:, 0]), self.sy.local_values(x[:, 1])
        if lx is None or ly is None:
            return None
        (vx, cx), (vy, cy) = lx, ly
        vals = (vx[:, :, None] * vy[:, None, :]).reshape(len(x), -1)
        dofs = np.where((cx[:, :, None] >= 0) & (cy[:, None, :] >= 0),
                        cx[:, :, None] * self.sy.dim + cy[:, None, :], -1).reshape(len(x), -1)
        return vals, dofs

    def nodes(self) -> np.ndarray:
        """Coordinates (dim, 2) of the tensor Lagrange nodes (a·dim M^y + b order)."""
        X, Y = np.meshgrid(self.sx.nodes(), self.sy.nodes(), indexing="ij")
        return np.column_stack([X.ravel(), Y.ravel()])
