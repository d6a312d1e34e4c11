"""The multiplier space M_h on G_h: what every space must have, what it may have, and the defaults.

Every consumer (the coupling B_i, the Gram matrices, β_h, the contact solver, the patch tests,
the exporters) reads a space through the attributes below and nothing else, so a new space —
on the segment or on the face, built in or a user's — is a class with these attributes and a
registry entry (:mod:`..spaces.registry`). Inherit :class:`SpaceDefaults` to get the optional
ones with their stated defaults; nothing probes a space with ``hasattr``.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class MultiplierSpace(Protocol):
    """A finite-dimensional space M_h of multipliers on a partition G_h of Γ.

    Required
    --------
    breakpoints : partition
        G_h, the partition the space is built on, in its interface's own form (the segment's
        sorted breakpoints, a face's ``TensorPartition`` or ``Triangulation``); the interface
        (``gamma.cells``, ``gamma.common_refinement``, ``gamma.coupling_quadrature``) reads it.
    dim : int
        dim M_h, the number of basis functions μ_j.
    degree : int
        Local polynomial degree s of the basis (per variable on rectangles, total on
        triangles): it sets the Gauss order of the coupling ∫_Γ μ_j φ_d.
    continuous : bool
        Whether every μ_j is continuous on Γ (r = 1 in the paper's M^r_s); the face's Gram of a
        non-tensor space then takes its nodal values on the continuous piece space as its
        projection.
    evaluate(x) -> ndarray, shape (len(x), dim)
        The values μ_j(x_i) at points of Γ (shape (n,) on the segment, (n, 2) on the face).

    Optional (defaults in :class:`SpaceDefaults`)
    ---------------------------------------------
    pieces : partition or None
        The partition on whose cells every μ_j is one polynomial; default ``breakpoints``.
        Finer for a space built from sub-cells (4C's piecewise-linear QUAD9); None where the
        pieces are not cells of a partition of this interface (pwlin on QUAD8: triangular
        sub-cells of rectangles), which the exact tensor Gram refuses.
    local_values(x) -> (values, dofs) or None
        The nonzero pattern of :meth:`evaluate`: per point the values of the few basis
        functions alive there and their global indices (−1: none), bit for bit the same
        numbers. Default None: the coupling evaluates the dense matrix instead.
    factors : tuple or None
        ``(M^x, M^y)`` for a tensor product M^x ⊗ M^y of two segment spaces (its Gram matrices
        are Kronecker products of the factors'); default None, not a tensor product.
    lives_on_triangles : bool
        Whether the cells of ``breakpoints`` are triangles (the Kuhn or a general triangulation
        of the face), whose symmetries the kernel bounds use; default False.
    name : str
        What an error message calls the space; default the class name.

    Optional, read by the Gram matrices of a face space that is not a tensor product (its
    basis projected onto discontinuous tensor pieces, :mod:`..face.norms.cellwise`)
    -----------------------------------------------------------------------------------
    piece_degree : int
        Degree per variable on a cell of ``pieces``; default ``degree``.
    smooth_tail : bool
        Whether every μ_j is continuous and vanishes on ∂Γ, so that its sine coefficients decay
        like 1/(m² n²) (the extrapolation's exponent 4); default False (exponent 2: slower,
        never wrong).
    """

    breakpoints: object
    dim: int
    degree: int
    continuous: bool

    def evaluate(self, x: np.ndarray) -> np.ndarray: ...

    @property
    def pieces(self): ...

    def local_values(self, x: np.ndarray): ...

    @property
    def factors(self) -> tuple | None: ...

    @property
    def lives_on_triangles(self) -> bool: ...

    @property
    def name(self) -> str: ...


class SpaceDefaults:
    """The optional attributes of :class:`MultiplierSpace` with their defaults (a mixin: a space
    overrides what it has)."""

    factors = None
    lives_on_triangles = False
    smooth_tail = False

    @property
    def name(self) -> str:
        """The class name (a message's ``got``)."""
        return type(self).__name__

    @property
    def piece_degree(self) -> int:
        """The degree: one polynomial of degree ``degree`` per piece."""
        return self.degree

    @property
    def pieces(self):
        """G_h itself: every basis function is one polynomial per cell."""
        return self.breakpoints

    def local_values(self, x: np.ndarray):
        """None: no sparse pattern, the coupling evaluates the dense basis."""
        return None
