"""Multiplier spaces on a tensor grid of rectangles of the face (0, 1)².

:class:`CellwiseFaceSpace` puts one reference quadrilateral (QUAD4, QUAD8 or QUAD9 of
:mod:`.face.spaces.reference_elements`) on every rectangle of a :class:`~.face.partitions.tensor_grid.TensorPartition` and numbers
the nodes globally: a node shared by neighbouring rectangles is one dof. The bases:

* ``standard`` — the continuous nodal basis N;
* ``transformed`` — the continuous Ñ = T(α) N of Popp et al. (:func:`.face.spaces.dual_bases.transformation`;
  on a shared edge T only involves that edge's nodes, so Ñ stays continuous);
* ``dual`` / ``transformed_dual`` — per rectangle ψ = A N (ψ̃ = Ã Ñ): the same global dof as
  the node's standard function, discontinuous across rectangles, and globally
  ∫ ψ_i N_j = δ_ij ∫ N_j (∫ ψ̃_i Ñ_j = δ_ij ∫ Ñ_j): the affine map of a rectangle scales
  D and M alike, so A is the reference one;
* ``pwlin`` — 4C's piecewise (bi)linear functions on the split of :func:`.face.spaces.reference_elements.pwlin_subelements`.

``vanish_on_boundary`` drops the dofs of the nodes on ∂(0, 1)². For the dual bases this
loses Σ ψ = 1 unless ``keep_constants`` (the default) applies a boundary modification in
the spirit of Wohlmuth's (SIAM J. Numer. Anal. 38 (2000), the dual basis next to the boundary
of the slave side): in every rectangle, the local dual function of a dropped node b is added
to the live local node(s) nearest to b in the reference cell (shared equally on a tie; this
nearest-node rule is our choice for QUAD8/9, where other distributions are possible). Each live ψ̂_j = ψ_j + Σ_b c_jb ψ_b
with Σ_j c_jb = 1, so Σ_j ψ̂_j = Σ_all ψ = 1, and ∫ ψ̂_i N_j = δ_ij ∫ N_j still holds for live
j (ψ_b ⟂ N_j for b ≠ j). On QUAD4 this is, rectangle by rectangle, the tensor product of the
1D ``DUAL`` basis of :mod:`.segment.dual` (ψ^x ⊗ (ψ^y_a + ψ^y_b) = ψ^x ⊗ 1 next to the boundary).
"""
from __future__ import annotations

import numpy as np

from ....errors import InputError
from ...gamma.protocol import SpaceDefaults
from .dual_bases import POPP_ALPHA, dual_coefficients, transformation
from .reference_elements import pwlin_shapes, reference_element

BASES = ("standard", "transformed", "dual", "transformed_dual", "pwlin")
QUAD_ELEMENTS = ("QUAD4", "QUAD8", "QUAD9")


def _reference_coefficients(name: str, basis: str, alpha) -> np.ndarray:
    """C with local functions = C · (N, or the pwlin shapes), on the reference cell."""
    if basis in ("standard", "pwlin"):
        return np.eye(reference_element(name).n_nodes)
    a = POPP_ALPHA if alpha is None else alpha
    if basis == "transformed":
        return transformation(name, a)
    return dual_coefficients(name, transformed=basis == "transformed_dual", alpha=a)


def _nearest_live(nodes: np.ndarray, live: np.ndarray, dead: np.ndarray) -> np.ndarray:
    """R[j, b] = share of dead node b given to live node j (the nearest live nodes, equally)."""
    R = np.zeros((len(nodes), len(nodes)))
    for b in dead:
        dist = np.linalg.norm(nodes[live] - nodes[b], axis=1)
        near = live[dist <= dist.min() + 1e-12]
        R[near, b] = 1.0 / len(near)
    return R


class CellwiseFaceSpace(SpaceDefaults):
    """A multiplier space on the rectangles of ``partition`` (see the module docstring).

    Parameters
    ----------
    partition : TensorPartition
        Breakpoints ``xs``, ``ys`` from 0 to 1.
    element : {"QUAD4", "QUAD8", "QUAD9"}
    basis : {"standard", "transformed", "dual", "transformed_dual", "pwlin"}
    alpha : float, optional
        α of the transformed bases (default 1/5, 4C's); ignored by the others.
    vanish_on_boundary : bool
        Drop the dofs on ∂(0, 1)².
    keep_constants : bool
        For the dual bases with ``vanish_on_boundary``: the modification keeping Σ ψ = 1.

    Attributes
    ----------
    dim : int
    degree : int
        Largest degree per variable of the element (1 for QUAD4, 2 for QUAD8/9).
    breakpoints : TensorPartition
    dofs : ndarray of int, shape (cells, n_nodes)
        Global dof per local node, −1 where dropped; cell c = i·(len(ys) − 1) + j.
    coefficients : ndarray, shape (cells, n_nodes, n_nodes)
        Local functions per cell in terms of the reference shapes (N, or the pwlin shapes).
    """

    def __init__(self, partition, element: str, basis: str = "standard", alpha=None,
                 vanish_on_boundary: bool = False, keep_constants: bool = True):
        if element not in QUAD_ELEMENTS:
            raise InputError("element", f"one of {', '.join(QUAD_ELEMENTS)} (the cells are rectangles)",
                             got=element)
        if basis not in BASES:
            raise InputError("basis", f"one of {', '.join(BASES)}", got=basis)
        self.breakpoints, self.element, self.basis = partition, element, basis
        self.xs, self.ys = np.asarray(partition.xs, float), np.asarray(partition.ys, float)
        el = reference_element(element)
        self.degree = el.degree
        nx, ny = len(self.xs) - 1, len(self.ys) - 1
        # nodes on the lattice of half-cells: I = 2 i + ξ + 1, J = 2 j + η + 1
        I = 2 * np.arange(nx)[:, None, None] + (el.nodes[:, 0] + 1)[None, None, :]
        J = 2 * np.arange(ny)[None, :, None] + (el.nodes[:, 1] + 1)[None, None, :]
        I, J = np.broadcast_to(I, (nx, ny, el.n_nodes)), np.broadcast_to(J, (nx, ny, el.n_nodes))
        key = (I * (2 * ny + 1) + J).reshape(nx * ny, el.n_nodes).astype(int)
        on_bd = (I == 0) | (I == 2 * nx) | (J == 0) | (J == 2 * ny)
        on_bd = on_bd.reshape(key.shape)
        live = ~on_bd if vanish_on_boundary else np.ones_like(on_bd)
        ids, inv = np.unique(key[live], return_inverse=True)
        self.dofs = -np.ones(key.shape, dtype=int)
        self.dofs[live] = inv
        self.dim = len(ids)
        self._lattice = np.column_stack([ids // (2 * ny + 1), ids % (2 * ny + 1)])
        C = _reference_coefficients(element, basis, alpha)
        self.coefficients = np.broadcast_to(C, (nx * ny,) + C.shape).copy()
        self.modified = bool(vanish_on_boundary and keep_constants and "dual" in basis)
        for c in range(nx * ny):
            lv, dead = np.flatnonzero(live[c]), np.flatnonzero(~live[c])
            if self.modified and len(lv) and len(dead):
                self.coefficients[c] = (np.eye(el.n_nodes) + _nearest_live(el.nodes, lv, dead)) @ C
            self.coefficients[c, dead] = 0.0

    def nodes(self) -> np.ndarray:
        """Coordinates of the global dofs' nodes, shape (dim, 2)."""
        def coord(b, K):
            i = np.minimum(K // 2, len(b) - 2)
            return b[i] + 0.5 * (K - 2 * i) * (b[i + 1] - b[i])
        return np.column_stack([coord(self.xs, self._lattice[:, 0]), coord(self.ys, self._lattice[:, 1])])

    def evaluate(self, points) -> np.ndarray:
        """All basis functions at ``points`` (n, 2) in [0, 1]², shape (n, dim).

        A point on a cell boundary is taken by the cell on its upper / right side (the last
        cell at 1), as the 1D spaces do.
        """
        vals, dofs = self.local_values(points)
        out = np.zeros((len(vals), self.dim))
        rows = np.repeat(np.arange(len(vals)), vals.shape[1])
        cols = dofs.ravel()
        keep = cols >= 0
        np.add.at(out, (rows[keep], cols[keep]), vals.ravel()[keep])
        return out

    def local_values(self, points) -> tuple:
        """The nonzero pattern of :meth:`evaluate`: (values, dofs), each (n, n_nodes), the local
        functions of the cell holding each point and their global dofs (−1: dropped); what
        :meth:`evaluate` scatters, so the two agree bit for bit (every point lies in one cell)."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        i = np.clip(np.searchsorted(self.xs, p[:, 0], side="right") - 1, 0, len(self.xs) - 2)
        j = np.clip(np.searchsorted(self.ys, p[:, 1], side="right") - 1, 0, len(self.ys) - 2)
        ref = np.column_stack([2 * (p[:, 0] - self.xs[i]) / (self.xs[i + 1] - self.xs[i]) - 1,
                               2 * (p[:, 1] - self.ys[j]) / (self.ys[j + 1] - self.ys[j]) - 1])
        raw = (pwlin_shapes(self.element, ref) if self.basis == "pwlin"
               else reference_element(self.element).shapes(ref))
        cell = i * (len(self.ys) - 1) + j
        return np.einsum("pab,pb->pa", self.coefficients[cell], raw), self.dofs[cell]

    def quadrature(self, total_degree: int) -> tuple[np.ndarray, np.ndarray]:
        """A Gauss rule on every rectangle (exact per cell for ``total_degree``; not across
        the pieces of ``pwlin``): points (q, 2), weights (q,)."""
        t, w = reference_element("QUAD4").quadrature(total_degree)
        a, b = self.xs[:-1], self.xs[1:]
        c, d = self.ys[:-1], self.ys[1:]
        X = (0.5 * (a + b))[:, None, None] + (0.5 * (b - a))[:, None, None] * t[None, None, :, 0]
        Y = (0.5 * (c + d))[None, :, None] + (0.5 * (d - c))[None, :, None] * t[None, None, :, 1]
        W = (0.25 * np.outer(b - a, d - c))[:, :, None] * w[None, None, :]
        X, Y = np.broadcast_to(X, W.shape), np.broadcast_to(Y, W.shape)
        return np.column_stack([X.ravel(), Y.ravel()]), W.ravel()

    @property
    def pieces(self):
        """The tensor partition on whose rectangles every basis function is one polynomial of
        degree ≤ :attr:`piece_degree` per variable: the cells, or for ``pwlin`` on QUAD4/QUAD9
        the cells halved in both directions (the four QUAD4 pieces); None for ``pwlin`` on
        QUAD8 (triangular pieces: no exact tensor route, :mod:`.face.norms.cellwise` refuses it)."""
        from ..partitions.tensor_grid import TensorPartition

        if self.basis != "pwlin":
            return self.breakpoints
        if self.element == "QUAD8":
            return None
        half = [np.sort(np.concatenate([g, 0.5 * (g[:-1] + g[1:])])) for g in (self.xs, self.ys)]
        return TensorPartition(*half)

    @property
    def name(self) -> str:
        """The reference element (QUAD4, QUAD8, QUAD9)."""
        return self.element

    @property
    def piece_degree(self) -> int:
        """Degree per variable on a piece of :attr:`pieces` (1 for ``pwlin``)."""
        return 1 if self.basis == "pwlin" else self.degree

    @property
    def continuous(self) -> bool:
        """Whether every basis function is continuous on Γ (the nodal bases: standard,
        transformed, pwlin; the dual ones jump across the rectangles)."""
        return self.basis in ("standard", "transformed", "pwlin")

    @property
    def series_key(self):
        """What the partial sums of this space's H series depend on: its piece space P (the pieces,
        the degree and continuity on them, :func:`~..norms.cellwise.piece_space`), not its basis.
        Spaces with one key share those sums (:func:`~..norms.cellwise.shared_piece_sums`), so a β_h
        request runs them one after the other in one worker (:mod:`~infsup_contact.solvers.side_by_side`);
        None without tensor pieces."""
        p = self.pieces
        return None if p is None else (np.asarray(p.xs, float).tobytes(), np.asarray(p.ys, float).tobytes(),
                                       self.piece_degree, bool(self.continuous))

    @property
    def smooth_tail(self) -> bool:
        """Whether every basis function is continuous and vanishes on ∂Γ (sine coefficients
        ~ 1/(m² n²) in the tail, :func:`.face.norms.tensor.gram_h_face` exponent 4; else 2)."""
        return bool(self.continuous and np.all(self.dofs[self._boundary_nodes()] < 0))

    def _boundary_nodes(self) -> np.ndarray:
        """Mask (cells, n_nodes) of the local nodes on ∂(0, 1)²."""
        el = reference_element(self.element)
        nx, ny = len(self.xs) - 1, len(self.ys) - 1
        I = 2 * np.arange(nx)[:, None, None] + (el.nodes[:, 0] + 1)[None, None, :]
        J = 2 * np.arange(ny)[None, :, None] + (el.nodes[:, 1] + 1)[None, None, :]
        I, J = np.broadcast_to(I, (nx, ny, el.n_nodes)), np.broadcast_to(J, (nx, ny, el.n_nodes))
        return ((I == 0) | (I == 2 * nx) | (J == 0) | (J == 2 * ny)).reshape(nx * ny, el.n_nodes)


class DiscontinuousP1Space(CellwiseFaceSpace):
    """Discontinuous P1 on the rectangles of ``partition``: 1, ξ, η on every cell (ξ, η the cell's
    reference coordinates in [−1, 1]², so the functions are affine in x and y), three dofs per
    cell, written as combinations of the QUAD4 shapes (1 = Σ N_a, ξ = Σ ξ_a N_a, η = Σ η_a N_a) so
    that evaluation, the pieces and the Grams are :class:`CellwiseFaceSpace`'s."""

    def __init__(self, partition):
        super().__init__(partition, "QUAD4", "standard")
        nodes = reference_element("QUAD4").nodes
        C = np.zeros((4, 4))
        C[0], C[1], C[2] = 1.0, nodes[:, 0], nodes[:, 1]
        cells = (len(self.xs) - 1) * (len(self.ys) - 1)
        self.coefficients = np.broadcast_to(C, (cells, 4, 4)).copy()
        self.dofs = np.column_stack([3 * np.arange(cells)[:, None] + np.arange(3), -np.ones(cells, int)])
        self.dim = 3 * cells
        self.basis = "p1"

    def nodes(self) -> np.ndarray:
        """The centre of each dof's cell, shape (dim, 2)."""
        cx, cy = 0.5 * (self.xs[:-1] + self.xs[1:]), 0.5 * (self.ys[:-1] + self.ys[1:])
        X, Y = np.meshgrid(cx, cy, indexing="ij")
        return np.repeat(np.column_stack([X.ravel(), Y.ravel()]), 3, axis=0)

    @property
    def name(self) -> str:
        return "P1-discontinuous"

    @property
    def continuous(self) -> bool:
        return False


def cellwise_builder(element: str, basis: str, vanish_on_boundary: bool = True, alpha=None,
                     refuse_with: str = ""):
    """``build(k, partition)`` of a registry entry (:attr:`.spaces.spec.SpaceSpec.face_build`):
    :class:`CellwiseFaceSpace` on the tensor partition G_h (k does not enter: the element
    fixes the multiplier degree). ``refuse_with`` is appended to the refusal of a dual basis
    with a weight ≤ 0 (the registered id of the remedy)."""
    def build(k, partition):
        try:
            return CellwiseFaceSpace(partition, element, basis, alpha, vanish_on_boundary)
        except InputError as err:
            if refuse_with and err.key == "element":
                reason = err.allowed.rsplit("; use ", 1)[0]       # the weights, without the generic remedy
                raise InputError("case", f"{reason}; {refuse_with}", got=err.got) from None
            raise
    return build
