"""Multiplier spaces of P_s on the triangles of a tensor partition of the face.

The trace on Γ of the six-tetrahedra (Kuhn) split of a structured grid is P_k on the triangles
that the diagonal from (x_i, y_j) to (x_{i+1}, y_{j+1}) cuts every rectangle of the grid into
(:mod:`.face.partitions.quadrature`, ``Square(cell="trig")``). The analogues of the paper's spaces
(eqs. (5.3), (5.5)) on such a triangulated partition G_h are the Lagrange spaces

* M^1_{0,s}: continuous P_s vanishing on ∂Γ (T3 with s = k),
* M^1_s:     continuous P_s (R5.2 with s = k, T5 with s = k − 1),
* M^0_s:     discontinuous P_s (T4 with s = k − 2, R5.4 with s = k − 1),

instead of the tensor Q_s products of :mod:`.face.spaces.tensor`. Their dimensions on an
n_x × n_y grid are (n_x s ± 1)(n_y s ± 1) (continuous; − when vanishing on ∂Γ) and
2 n_x n_y (s + 1)(s + 2)/2 (discontinuous): for s ≥ 1 the P_s Lagrange lattices of the two
triangles of a rectangle are together its (s + 1)² tensor lattice, so the continuous nodes are
the tensor lattice of the refined 1D breakpoints, as for Q_s.

Basis: the Lagrange basis of every triangle in barycentric form (Nicolaides),
φ_α = Π_v Π_{a<α_v} (s λ_v − a)/(a + 1), |α| = s, glued at shared nodes for the continuous spaces.

``dual=True`` (continuous numbering, s = 1 or 2): the dual (biorthogonal) basis of the continuous
space, ψ = A N per triangle with the same global dof as the node's N, discontinuous across
triangles: TRI3's A = D M⁻¹ (Wohlmuth 2000; ψ_v = 3λ_v − 1) and TRI6's transformed
Ã T(α) (Popp et al., α = 1/5, :func:`.face.spaces.dual_bases.dual_coefficients`: ∫ N_vertex = 0 on TRI6).
With ``vanish`` the local dual function of a node on ∂Γ is added to the nearest live local
node(s) (:mod:`.face.spaces.cellwise`' boundary modification, keeping Σ ψ = 1 where a triangle has a
live node; a TRI3 corner triangle with its three vertices on ∂Γ has none).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ....errors import InputError
from ...gamma.protocol import SpaceDefaults


def local_lattice(s: int) -> np.ndarray:
    """Multi-indices (α_A, α_B, α_C) with sum s, shape (nloc, 3), nloc = (s + 1)(s + 2)/2."""
    return np.array([(s - b - c, b, c) for b in range(s + 1) for c in range(s + 1 - b)], dtype=int).reshape(-1, 3)


def lagrange_barycentric(lam: np.ndarray, s: int) -> np.ndarray:
    """Values (n, nloc) of the P_s Lagrange basis of a triangle at barycentric coordinates
    ``lam`` (n, 3), in :func:`local_lattice` order (s = 0: the constant 1)."""
    out = np.ones((len(lam), len(local_lattice(s))))
    for i, alpha in enumerate(local_lattice(s)):
        for v in range(3):
            for a in range(alpha[v]):
                out[:, i] *= (s * lam[:, v] - a) / (a + 1)
    return out


def _lattice_position(s: int, upper: bool) -> np.ndarray:
    """Tensor lattice coordinates (a, b) ∈ {0..s}² in a rectangle of the local nodes of its lower
    triangle (vertices A = (0,0), B = (1,0), C = (1,1)) or upper one (A, C, D = (0,1))."""
    al = local_lattice(s)
    if s == 0:
        return np.zeros((1, 2), dtype=int)
    if upper:  # multi-index (α_A, α_C, α_D): node (α_C, α_C + α_D)
        return np.column_stack([al[:, 1], al[:, 1] + al[:, 2]])
    return np.column_stack([al[:, 1] + al[:, 2], al[:, 2]])  # (α_A, α_B, α_C): (α_B + α_C, α_C)


DUAL_ELEMENTS = {1: ("TRI3", False), 2: ("TRI6", True)}
"""Degree s → (reference element, Popp-transformed) of the dual bases on triangles."""


def dual_local(s: int, alpha: float | None = None) -> np.ndarray:
    """A (nloc, nloc), local dual functions ψ = A N in :func:`local_lattice` order: the
    reference element's coefficients (:func:`.face.spaces.dual_bases.dual_coefficients`) permuted by matching
    its nodes (x, y) to the barycentric multi-indices s (1 − x − y, x, y). ``alpha``: the α of
    the transformed TRI6 basis (None: 4C's 1/5; ignored by TRI3)."""
    from .dual_bases import POPP_ALPHA, dual_coefficients
    from .reference_elements import reference_element

    name, transformed = DUAL_ELEMENTS[s]
    ref = reference_element(name).nodes
    bary = np.rint(s * np.column_stack([1.0 - ref.sum(axis=1), ref])).astype(int)
    perm = [int(np.flatnonzero((bary == a).all(axis=1))[0]) for a in local_lattice(s)]
    C = dual_coefficients(name, transformed=transformed, alpha=POPP_ALPHA if alpha is None else alpha)
    return C[np.ix_(perm, perm)]


@dataclass(frozen=True, eq=False)
class TriangleSpace(SpaceDefaults):
    """P_s (continuous or not, optionally vanishing on ∂Γ) on the triangulated tensor partition.

    Attributes
    ----------
    breakpoints : TensorPartition
        G_h; every rectangle is cut by its diagonal from (x_i, y_j) to (x_{i+1}, y_{j+1}).
    s : int
        Polynomial degree (total), s ≥ 0; s ≥ 1 for a continuous space.
    continuous : bool
    vanish : bool
        Continuous spaces only: the functions vanish on ∂Γ.
    """

    breakpoints: object
    s: int
    continuous: bool
    vanish: bool = False
    dual: bool = False
    alpha: float | None = None  # α of a transformed dual basis (TRI6), None: 4C's 1/5

    def __post_init__(self):
        if int(self.s) < 0 or (self.continuous and self.s == 0):
            raise InputError("degree", "s >= 0 (s >= 1 for a continuous space on triangles)", got=self.s)
        if self.vanish and not self.continuous:
            raise InputError("vanish", "False for a discontinuous space on triangles", got=self.vanish)
        if self.dual and (not self.continuous or self.s not in DUAL_ELEMENTS):
            raise InputError("dual", f"a continuous space of degree s in {sorted(DUAL_ELEMENTS)} "
                             f"for a dual basis on triangles", got=(self.s, self.continuous))

    @property
    def degree(self) -> int:
        """Total degree s: a coupling with a P_k trace is a polynomial of total degree k + s on
        every piece of :func:`~.face.partitions.quadrature.split_triangles`."""
        return int(self.s)

    @property
    def shape(self) -> tuple:
        return len(self.breakpoints.xs) - 1, len(self.breakpoints.ys) - 1

    @property
    def n_local(self) -> int:
        return (self.s + 1) * (self.s + 2) // 2

    @cached_property
    def _dofs(self) -> np.ndarray:
        """Global index (nx, ny, 2, nloc) of every local function (−1: removed on ∂Γ);
        triangle 0 is the lower one (below the diagonal), 1 the upper one."""
        nx, ny = self.shape
        s, nloc = self.s, self.n_local
        if not self.continuous:
            return np.arange(nx * ny * 2 * nloc).reshape(nx, ny, 2, nloc)
        i, j = np.arange(nx)[:, None, None, None], np.arange(ny)[None, :, None, None]
        pos = np.stack([_lattice_position(s, False), _lattice_position(s, True)])  # (2, nloc, 2)
        gx, gy = i * s + pos[None, None, :, :, 0], j * s + pos[None, None, :, :, 1]
        if not self.vanish:
            return gx * (ny * s + 1) + gy
        inner = (gx > 0) & (gx < nx * s) & (gy > 0) & (gy < ny * s)
        return np.where(inner, (gx - 1) * (ny * s - 1) + (gy - 1), -1)

    def live_mask(self, glob: np.ndarray) -> np.ndarray:
        """Bit mask of the live local nodes (global index ≥ 0) of rows of local dof indices."""
        return (np.asarray(glob) >= 0) @ (1 << np.arange(self.n_local))

    def _dual_matrix(self, live_mask: int) -> np.ndarray:
        """Â (nloc, nloc) of a triangle whose live local nodes are the bits of ``live_mask``:
        rows of the live nodes get the dead nodes' dual functions, shared equally among the
        nearest live ones (distance of the barycentric multi-indices); rows of dead nodes are unused."""
        A = dual_local(self.s, self.alpha)
        pos = local_lattice(self.s).astype(float)
        live = np.array([(live_mask >> i) & 1 for i in range(self.n_local)], dtype=bool)
        out = A.copy()
        if live.any():
            for b in np.flatnonzero(~live):
                dist = np.linalg.norm(pos[live] - pos[b], axis=1)
                near = np.flatnonzero(live)[dist <= dist.min() + 1e-12]
                out[near] += A[b] / len(near)
        return out

    @property
    def dim(self) -> int:
        nx, ny = self.shape
        if not self.continuous:
            return nx * ny * 2 * self.n_local
        d = -1 if self.vanish else 1
        return max(nx * self.s + d, 0) * max(ny * self.s + d, 0)

    def locate(self, x: np.ndarray) -> tuple:
        """(cell ix, cell iy, triangle 0/1, barycentric coordinates (n, 3)) of points (n, 2);
        a point on the diagonal goes to the lower triangle."""
        x = np.asarray(x, dtype=float).reshape(-1, 2)
        xs, ys = np.asarray(self.breakpoints.xs, float), np.asarray(self.breakpoints.ys, float)
        ix = np.clip(np.searchsorted(xs, x[:, 0], side="right") - 1, 0, len(xs) - 2)
        iy = np.clip(np.searchsorted(ys, x[:, 1], side="right") - 1, 0, len(ys) - 2)
        xi = (x[:, 0] - xs[ix]) / (xs[ix + 1] - xs[ix])
        eta = (x[:, 1] - ys[iy]) / (ys[iy + 1] - ys[iy])
        upper = eta > xi
        lam = np.where(upper[:, None], np.column_stack([1.0 - eta, xi, eta - xi]),
                       np.column_stack([1.0 - xi, xi - eta, eta]))
        return ix, iy, upper.astype(int), lam

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """All basis functions at points (n, 2), shape (n, dim)."""
        vals, glob = self.local_values(x)
        out = np.zeros((len(vals), self.dim))
        rows = np.repeat(np.arange(len(vals)), self.n_local)
        keep = glob.ravel() >= 0
        np.add.at(out, (rows[keep], glob.ravel()[keep]), vals.ravel()[keep])
        return out

    def local_values(self, x: np.ndarray) -> tuple:
        """The nonzero pattern of :meth:`evaluate`: (values, dofs), each (n, nloc), the local
        functions of the triangle holding each point and their global dofs (−1: removed on ∂Γ);
        what :meth:`evaluate` scatters, so the two agree bit for bit."""
        ix, iy, tri, lam = self.locate(x)
        vals = lagrange_barycentric(lam, self.s)
        glob = self._dofs[ix, iy, tri]  # (n, nloc)
        if self.dual:  # ψ = Â N per triangle, Â with the boundary modification of the pattern
            pattern = self.live_mask(glob)
            for p in np.unique(pattern):
                rows = pattern == p
                vals[rows] = vals[rows] @ self._dual_matrix(int(p)).T
        return vals, glob

    def nodes(self) -> np.ndarray:
        """Coordinates (dim, 2) of the Lagrange nodes (the centroid of the triangle for s = 0)."""
        nx, ny = self.shape
        xs, ys = np.asarray(self.breakpoints.xs, float), np.asarray(self.breakpoints.ys, float)
        s = self.s
        out = np.zeros((self.dim, 2))
        for t, upper in enumerate((False, True)):
            pos = _lattice_position(s, upper).astype(float) / max(s, 1)
            if s == 0:
                pos = np.array([[1.0, 2.0]]) / 3.0 if upper else np.array([[2.0, 1.0]]) / 3.0
            for i in range(nx):
                for j in range(ny):
                    g = self._dofs[i, j, t]
                    p = np.column_stack([xs[i] + pos[:, 0] * (xs[i + 1] - xs[i]),
                                         ys[j] + pos[:, 1] * (ys[j + 1] - ys[j])])
                    out[g[g >= 0]] = p[g >= 0]
        return out

    lives_on_triangles = True

    def triangles(self) -> np.ndarray:
        """The triangles (2 n_x n_y, 3, 2) of G_h, in (i, j, lower/upper) order."""
        xs, ys = np.asarray(self.breakpoints.xs, float), np.asarray(self.breakpoints.ys, float)
        out = []
        for i in range(len(xs) - 1):
            for j in range(len(ys) - 1):
                a, b = (xs[i], ys[j]), (xs[i + 1], ys[j])
                c, d = (xs[i + 1], ys[j + 1]), (xs[i], ys[j + 1])
                out += [[a, b, c], [a, c, d]]
        return np.array(out, dtype=float)
