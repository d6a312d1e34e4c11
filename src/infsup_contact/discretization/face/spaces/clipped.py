"""A face multiplier space cut off at x = L: Γ = (0, L) × (0, 1), the part of Ω1's face that a
smaller Ω2 covers ("edge dropping").

The multipliers are defined on Ω1's face (0, 1)² (multiplier mesh ``omega1``: a tensor space
M^x ⊗ M^y of :mod:`.face.spaces.tensor`) and restricted to Γ. Only x is cut: with the breakpoints
x_0 < … < x_N of M^x and x_{e*} < L ≤ x_{e*+1}, the cells beyond e* are removed, cell e* is
clipped to [x_{e*}, L] (its covered fraction θ = (L − x_{e*}) / (x_{e*+1} − x_{e*})), and the
basis functions whose support misses [0, L] are *dropped* (none when θ > 0 and L is not a
breakpoint: then only the supports of the last column are cut). Those kept on the clipped
cell keep their values, restricted: ψ_a(θ t) = Σ_b ψ_a(θ τ_b) L_b(t) on the clipped
reference cell (exact for the degree-s polynomials, τ_b the Lagrange nodes).

The restricted 1D space is stored pulled back to (0, 1), s = x / L, as a
:class:`~.segment.multipliers.SegmentSpace` (:func:`~.segment.multipliers.local_basis_space`), so the segment's
machinery (sine coefficients, L² Gram) applies unchanged; the rectangle enters the norms only
through the factor L of dx and the anisotropic weights of :func:`~.face.norms.tensor.partial_gram`
(``aspect`` = L): ‖μ‖²_{H^{-1/2}_00(Γ)} = L Σ μ̃_mn² / (π√((m/L)² + n²)).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ....errors import InputError
from ..norms.tensor import gram_h_face
from .tensor import FaceSpace
from ...segment.multipliers import local_basis_space, local_shapes, reference_nodes
from ...segment.norms import gram_l2
from ..partitions.tensor_grid import TensorPartition

CLIP_TOL = 1e-12
"""Cells starting within this of the cut L count as beyond it (:func:`clip_1d`, unit face)."""
SLIVER_MIN = 1e-9
"""The narrowest cut column the geometry resolves, in units of the face: 1000 × :data:`CLIP_TOL`
(a narrower one is dropped whole, as if θ = 0: at θ = 1e-12, N = 4 the study computed the
θ = 0 space, β_H 0.55 instead of ~θ), and L = (N − 1 + θ)/N carries θ to ~1e-7 relative."""


def min_covered_fraction(n: int) -> float:
    """The smallest covered fraction θ of the last of ``n`` columns that the geometry resolves:
    a cut column θ/n wide, at least :data:`SLIVER_MIN`."""
    return SLIVER_MIN * n


def clip_1d(space, L: float, scale=None, tol: float = CLIP_TOL):
    """The 1D space restricted to [0, L] and pulled back to (0, 1); see the module docstring.

    Parameters
    ----------
    space : SegmentSpace
        A 1D space on a partition of (0, 1).
    L : float
        The cut, 0 < L ≤ 1.
    scale : array_like, shape (space.dim,), optional
        Factors d_j multiplying the basis functions (d_j ψ_j; a diagonal change of basis).

    Returns
    -------
    clipped : SegmentSpace
        On the breakpoints (x_0, …, x_{e*}, L) / L.
    kept : ndarray of int
        The dofs of ``space`` kept, in the order of ``clipped``'s dofs.
    """
    if not 0.0 < L <= 1.0:
        raise InputError("L", "a cut 0 < L <= 1", got=L)
    x, s = np.asarray(space.breakpoints, float), space.degree
    n_keep = int(np.searchsorted(x, L - tol, side="right"))  # cells starting left of L
    C = (np.broadcast_to(np.eye(s + 1), (len(x) - 1, s + 1, s + 1)) if space.local_coefficients is None
         else space.local_coefficients)[:n_keep].copy()
    theta = (L - x[n_keep - 1]) / (x[n_keep] - x[n_keep - 1])
    if theta < 1.0 - tol:  # values of the shapes at the clipped cell's Lagrange nodes
        C[-1] = C[-1] @ local_shapes(s, theta * reference_nodes(s)).T
    dofs = np.array(space.dofs[:n_keep])
    if scale is not None:
        d = np.asarray(scale, float)
        C = C * np.where(dofs >= 0, d[np.maximum(dofs, 0)], 1.0)[:, :, None]
    kept = np.unique(dofs[dofs >= 0])
    renum = -np.ones(space.dim, dtype=int)
    renum[kept] = np.arange(len(kept))
    bp = np.append(x[:n_keep], L) / L
    clipped = local_basis_space(bp, s, np.where(dofs >= 0, renum[np.maximum(dofs, 0)], -1), C,
                                continuous=space.continuous, vanish_at_ends=False)
    return clipped, kept


@dataclass(frozen=True)
class ClippedFace:
    """M^x ⊗ M^y restricted to Γ = (0, L) × (0, 1) (module docstring).

    Attributes
    ----------
    space : FaceSpace
        The restricted space pulled back to the unit square (partition (x_0 … L)/L × ys).
    L : float
        Width of Γ.
    kept : ndarray of int
        The kept basis functions, as indices a·dim M^y + b of the unrestricted face space.
    """

    space: FaceSpace
    L: float
    kept: np.ndarray

    @classmethod
    def of(cls, face_space, L: float, scale_x=None, cut: bool = True) -> "ClippedFace":
        """Restrict a :class:`~.face.spaces.tensor.FaceSpace` on (0, 1)² to (0, L) × (0, 1);
        ``scale_x`` scales the x factor's basis functions (:func:`clip_1d`). ``cut=False``:
        ``face_space`` is already a space of Γ pulled back to (0, 1)² (nothing is cut)."""
        sx, sy = face_space.factors
        cx, kx = clip_1d(sx, L if cut else 1.0, scale_x)
        if not cut:
            cx = local_basis_space(cx.breakpoints, cx.degree, cx.dofs, cx.local_coefficients,
                                   continuous=sx.continuous, vanish_at_ends=False)
        part = TensorPartition(np.asarray(cx.breakpoints), np.asarray(face_space.breakpoints.ys, float))
        kept = (kx[:, None] * sy.dim + np.arange(sy.dim)[None, :]).ravel()
        return cls(FaceSpace(cx, sy, part), float(L), kept)

    @property
    def dim(self) -> int:
        return self.space.dim

    def evaluate_x(self, x: np.ndarray) -> np.ndarray:
        """Values of the x factor at physical points x ∈ [0, L], shape (n, dim M^x)."""
        return self.space.sx.evaluate(np.asarray(x, float) / self.L)

    def gram(self, norm: str, **kwargs) -> tuple[np.ndarray, dict]:
        """Gram matrix on Γ: L² exactly (L · G̃_x ⊗ G̃_y), H^{-1/2}_00(Γ) by the anisotropic
        double sine series (:func:`~.face.norms.tensor.gram_h_face` with ``aspect`` = L)."""
        sx, sy = self.space.factors
        if norm == "L2":
            return self.L * np.kron(gram_l2(sx), gram_l2(sy)), {"n_max": 0, "nmax_rel_error": 0.0}
        if norm == "H":
            return gram_h_face(self.space, aspect=self.L, **kwargs)
        raise InputError("norm", "H, L2", got=norm)
