"""P_s multiplier spaces on a general triangulation G_h of the face.

The spaces of :mod:`.face.spaces.triangles` (the paper's M^1_{0,s}, M^1_s, M^0_s, eqs. (5.3), (5.5),
and the dual bases TRI3 / TRI6) on any :class:`~.face.partitions.triangulation.Triangulation`, not only on the
structured Kuhn triangles: the same barycentric Lagrange basis
φ_α = Π_v Π_{a<α_v} (s λ_v − a)/(a + 1) per triangle (:func:`~.face.spaces.triangles.lagrange_barycentric`),
glued by node coordinates for the continuous spaces (:func:`~.face.partitions.triangulation.lattice`), nodes
on ∂Γ removed for ``vanish``; the dual basis ψ = Â N per triangle with the boundary modification
of :class:`~.face.spaces.triangles.TriangleSpace` (its ``_dual_matrix``: dead local nodes' dual
functions shared among the nearest live ones). The reference dual coefficients are symmetric
under permutations of the vertices (TRI3: 3λ_v − 1; TRI6 transformed), so the vertex order of a
general triangle does not matter.

Dimensions: continuous, nodes of the lattice (minus those on ∂Γ); discontinuous,
nt (s + 1)(s + 2)/2. On the structured Kuhn triangles they are those of
:class:`~.face.spaces.triangles.TriangleSpace` and so are the functions (a test compares them).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ....errors import InputError
from ...gamma.protocol import SpaceDefaults
from .triangles import DUAL_ELEMENTS, TriangleSpace, lagrange_barycentric, local_lattice
from ..partitions.triangulation import Triangulation, lattice, locate, on_boundary


@dataclass(frozen=True, eq=False)
class MeshTriangleSpace(SpaceDefaults):
    """P_s (continuous or not, optionally vanishing on ∂Γ, optionally its dual basis) on the
    triangles of a :class:`~.face.partitions.triangulation.Triangulation` ``breakpoints`` (G_h).

    Attributes
    ----------
    breakpoints : Triangulation
    s : int
    continuous, vanish, dual : bool
        As in :class:`~.face.spaces.triangles.TriangleSpace`.
    alpha : float or None
        As in :class:`~.face.spaces.triangles.TriangleSpace`: the α of a transformed dual basis (TRI6),
        None for 4C's 1/5.
    """

    breakpoints: Triangulation
    s: int
    continuous: bool
    vanish: bool = False
    dual: bool = False
    alpha: float | None = None

    def __post_init__(self):
        if not isinstance(self.breakpoints, Triangulation):
            raise InputError("multiplier mesh", "a triangulation of Γ", got=type(self.breakpoints).__name__)
        TriangleSpace.__post_init__(self)  # the same checks of s, vanish and dual

    @property
    def degree(self) -> int:
        """Total degree s (a coupling with a P_k trace: degree k + s on the common refinement)."""
        return int(self.s)

    @property
    def n_local(self) -> int:
        return (self.s + 1) * (self.s + 2) // 2

    @property
    def shape(self) -> tuple:
        """Nominal cells per direction (the H series' starting n_max, :mod:`.face.norms.unstructured`)."""
        n = self.breakpoints.nominal_n
        return n, n

    @cached_property
    def _lattice(self) -> tuple:
        """(node coordinates (dim, 2), global index (nt, nloc), −1 for removed nodes)."""
        tri = self.breakpoints
        if not self.continuous:
            nt, nloc = tri.cells, self.n_local
            alpha = local_lattice(self.s).astype(float) / max(self.s, 1)
            if self.s == 0:
                alpha = np.full((1, 3), 1.0 / 3.0)
            nodes = np.einsum("la,tac->tlc", alpha, tri.corners).reshape(-1, 2)
            return nodes, np.arange(nt * nloc).reshape(nt, nloc)
        nodes, glob = lattice(tri, self.s)
        if not self.vanish:
            return nodes, glob
        live = ~on_boundary(nodes)
        number = np.where(live, np.cumsum(live) - 1, -1)
        return nodes[live], number[glob]

    @property
    def _dofs(self) -> np.ndarray:
        return self._lattice[1]

    @property
    def dim(self) -> int:
        return len(self._lattice[0])

    def nodes(self) -> np.ndarray:
        """Coordinates (dim, 2) of the Lagrange nodes (centroids for s = 0)."""
        return self._lattice[0]

    lives_on_triangles = True

    def triangles(self) -> np.ndarray:
        """The triangles (nt, 3, 2) of G_h."""
        return self.breakpoints.corners

    live_mask = TriangleSpace.live_mask
    _dual_matrix = TriangleSpace._dual_matrix

    def local_matrices(self) -> np.ndarray:
        """Â per triangle (nt, nloc, nloc): ψ = Â N (the identity without ``dual``)."""
        eye = np.eye(self.n_local)
        if not self.dual:
            return np.broadcast_to(eye, (self.breakpoints.cells,) + eye.shape)
        pattern = self.live_mask(self._dofs)
        mats = {int(p): self._dual_matrix(int(p)) for p in np.unique(pattern)}
        return np.array([mats[int(p)] for p in pattern])

    def scatter(self) -> sp.csr_matrix:
        """P (dim, nt · nloc): the global function i is Σ of the local functions P[i, :]."""
        glob = self._dofs.ravel()
        keep = glob >= 0
        return sp.csr_matrix((np.ones(keep.sum()), (glob[keep], np.flatnonzero(keep))),
                             shape=(self.dim, glob.size))

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """All basis functions at points (n, 2), shape (n, dim)."""
        tri, lam = locate(self.breakpoints, x)
        return self.evaluate_located(tri, lam)

    def evaluate_located(self, tri: np.ndarray, lam: np.ndarray) -> np.ndarray:
        """Basis values at points given by their triangle and barycentric coordinates."""
        vals = lagrange_barycentric(lam, self.s)
        if self.dual:
            A = self.local_matrices()[tri]
            vals = np.einsum("nl,nml->nm", vals, A)
        glob = self._dofs[tri]
        out = np.zeros((len(vals), self.dim))
        rows = np.repeat(np.arange(len(vals)), self.n_local)
        keep = glob.ravel() >= 0
        np.add.at(out, (rows[keep], glob.ravel()[keep]), vals.ravel()[keep])
        return out


def mesh_space(partition: Triangulation, s: int, continuous: bool, vanish: bool, dual: bool = False):
    """:class:`MeshTriangleSpace`, refusing a dual basis of a degree without a reference element."""
    if dual and s not in DUAL_ELEMENTS:
        raise InputError("dual", f"a dual basis of degree s in {sorted(DUAL_ELEMENTS)} on triangles", got=s)
    return MeshTriangleSpace(partition, int(s), bool(continuous), bool(vanish), bool(dual))
