"""Γ as an object: the contact interface every consumer talks to.

:class:`Interface` owns everything that depends on the shape of Γ: its geometry and
dimension, the partitions G_h (the trace of Ω1, of Ω2, their common refinement and the
multiplier partition chosen from them), the trace dofs of a side, quadrature on a partition,
the values of a side's trace basis at points of Γ, the Gram matrices of its norms (L² and the
exact H^{-1/2}_00) and the dimension counts the kernel proof, the registry and the sizing model
use. Multiplier spaces are built on it: ``registry.case_space(case, k, partition, gamma)`` builds
a registered space on a partition of ``gamma`` (the registry imports this module, not the reverse).

Coupling, β_h, contact and the scenes ask the interface and never take a partition apart (it is
opaque: obtained from the interface, handed back to it); a side's trace carries its interface
(``trace.gamma``, :mod:`.gamma.trace`).

Implementations: the paper's segment (:class:`~.segment.interface.Segment`, partitions = sorted
breakpoints, what users' ``build(k, x)`` receive); the face (0, 1)² × {1} with tensor partitions
(:class:`~.face.shapes.square.Square`; QUAD8 traces: :class:`~.face.shapes.serendipity.SerendipitySquare`) and
with general triangulations (:class:`~.face.shapes.triangulated_square.TriangulatedSquare`, clipped).
"""
from __future__ import annotations

import abc
import contextlib

import numpy as np

from ...errors import InputError
from .multiplier_meshes import MULTIPLIER_MESHES, check_choice, intervals_per_direction  # noqa: F401 (G_h's choices)
from .trace import GammaTrace


class Interface(abc.ABC):
    """The contact interface Γ and what is discretized on it.

    A *partition* is whatever the implementation uses to describe a partition of Γ into
    cells (for a :class:`Segment`, sorted breakpoints); consumers get partitions from the
    interface (:meth:`partition_of`, :meth:`multiplier_partition`, :meth:`common_refinement`,
    ``trace.partition``, ``space.breakpoints``) and pass them back — to the interface, or with it
    to ``registry.case_space(case, k, partition, gamma)`` — never inspecting them.
    """

    cell: str | None = None
    """A face's cell shape (``quad``, ``trig``) where its spaces depend on it, else None."""

    # --- geometry -------------------------------------------------------------------------
    @property
    @abc.abstractmethod
    def dim(self) -> int:
        """Topological dimension of Γ (1 for a segment, 2 for a face)."""

    @abc.abstractmethod
    def embed(self, x: np.ndarray) -> tuple:
        """Coordinates in the bodies' space of points of Γ.

        Parameters
        ----------
        x : ndarray, shape (n,) or (n, dim)
            Points of Γ in its own parameters (what quadrature and sampling return).

        Returns
        -------
        tuple of ndarray
            One coordinate array per ambient direction, each of shape (n,), ready for
            ``mesh(*coords)`` point evaluation.
        """

    # --- partitions G_h -------------------------------------------------------------------
    @abc.abstractmethod
    def partition_of(self, mesh):
        """The trace partition of Γ induced by a body's mesh.

        Parameters
        ----------
        mesh : ngsolve.Mesh
            Mesh of Ω1 or Ω2 whose boundary region Γ is named as the interface expects.

        Returns
        -------
        partition
            The cells of the mesh's boundary elements on Γ.
        """

    @abc.abstractmethod
    def common_refinement(self, *partitions, tol: float = 1e-12):
        """The coarsest partition refining every one of ``partitions``.

        Parameters
        ----------
        *partitions : partition
            One or more partitions of Γ.
        tol : float
            Vertices closer than ``tol`` are one vertex (0: merge only equal ones).

        Returns
        -------
        partition
            Every cell is contained in one cell of each input partition.
        """

    @abc.abstractmethod
    def multiplier_partition(self, trace1, trace2, choice: str = "omega2", tol: float = 1e-12):
        """G_h chosen from the two trace partitions.

        Parameters
        ----------
        trace1, trace2 : partition
            Trace partitions of Ω1 and Ω2.
        choice : {"omega2", "omega1", "union"}
            Ω2's trace (the paper's default), Ω1's, or their common refinement.
        tol : float
            As in :meth:`common_refinement`.

        Returns
        -------
        partition

        Raises
        ------
        InputError
            For a choice not in :data:`MULTIPLIER_MESHES`.
        """

    @abc.abstractmethod
    def cells(self, partition) -> int:
        """Number of cells (intervals, faces) of ``partition``.

        Returns
        -------
        int
        """

    @abc.abstractmethod
    def partition_key(self, partition) -> bytes:
        """A hashable key equal for equal partitions (what caches and dedupes use).

        Parameters
        ----------
        partition : partition

        Returns
        -------
        bytes
        """

    @abc.abstractmethod
    def sample(self, partition, per_cell: int, upper: float | None = None) -> np.ndarray:
        """Sample points of Γ: ``per_cell`` + 1 equispaced points per cell, vertices included,
        duplicates removed.

        Parameters
        ----------
        partition : partition
        per_cell : int: subdivisions of each cell
        upper : float, optional
            Points are clipped into Γ; ``upper`` lowers the upper clip (a point exactly on the
            far end of Γ belongs to no cell of a half-open search).

        Returns
        -------
        ndarray: points in Γ's parameters, sorted
        """

    @abc.abstractmethod
    def at_boundary(self, partition, x: np.ndarray) -> np.ndarray:
        """Whether each point lies in a cell of ``partition`` touching ∂Γ (where a multiplier
        space's end conditions act; the patch test reports those cells apart).

        Parameters
        ----------
        partition : partition
        x : ndarray: points of Γ

        Returns
        -------
        ndarray of bool, shape (len(x),)
        """

    # --- trace dofs of a side ---------------------------------------------------------------
    @abc.abstractmethod
    def trace(self, fes) -> GammaTrace:
        """The trace on Γ of a side's displacement space.

        Parameters
        ----------
        fes : ngsolve.H1
            A scalar displacement space (one component) on a body's mesh.

        Returns
        -------
        GammaTrace
            Its free Γ dofs, boundary elements, trace partition and this interface.
        """

    @abc.abstractmethod
    def trace_basis(self, trace: GammaTrace, x: np.ndarray) -> np.ndarray:
        """Values of the Γ-dof basis functions of ``trace`` at points of Γ.

        Parameters
        ----------
        trace : GammaTrace
        x : ndarray
            Points of Γ (interior of the trace's cells), as :meth:`quadrature` gives them.

        Returns
        -------
        ndarray, shape (len(x), len(trace.gamma_dofs)): read-only (values may be cached on the trace)
        """

    def sparse_trace_basis(self, trace: GammaTrace, x: np.ndarray):
        """:meth:`trace_basis` as CSR without the dense values; None (default): convert the dense."""
        return None

    # --- quadrature and norms ---------------------------------------------------------------
    @abc.abstractmethod
    def quadrature(self, partition, degree: int) -> tuple:
        """A rule exact for polynomials of ``degree`` on every cell of ``partition``.

        Parameters
        ----------
        partition : partition
            Usually a common refinement, on whose cells every integrand is polynomial.
        degree : int
            Total degree integrated exactly per cell.

        Returns
        -------
        x, w : ndarray: points (Γ's parameters) and weights
        """

    @abc.abstractmethod
    def gram(self, space, norm: str, h_route: str = "logkernel", **kwargs) -> tuple:
        """Gram matrix of a multiplier space in a norm of Γ.

        Parameters
        ----------
        space : MultiplierSpace
            A space built on a partition of this interface (``registry.case_space``).
        norm : {"L2", "H"}
            L²(Γ), or the exact dual norm of H^{1/2}_00(Γ).
        h_route : str
            How the H norm is computed (implementation-defined routes; the default is exact).

        Returns
        -------
        G : ndarray, shape (dim M, dim M), symmetric positive definite
        info : dict: ``n_max`` and ``nmax_rel_error`` of a truncated route (0 for exact ones)
        """

    def gram_session(self):
        """A context in which :meth:`gram` may share the spaces' work on one G_h (default: none)."""
        return contextlib.nullcontext()

    # --- spaces and dimension counts --------------------------------------------------------
    @abc.abstractmethod
    def trace_dimension(self, k: int, cells: int) -> int:
        """dim W_h: traces on Γ of continuous P_k vanishing on ∂Γ, on ``cells`` uniform cells.

        Parameters
        ----------
        k : int
        cells : int

        Returns
        -------
        int
        """

    @abc.abstractmethod
    def trace_sum_dimension(self, k: int, trace1, trace2) -> int:
        """dim(W1 + W2) of the traces of two sides of degree k.

        Parameters
        ----------
        k : int
        trace1, trace2 : partition
            The two trace partitions.

        Returns
        -------
        int
        """

    @abc.abstractmethod
    def trace_nodes(self, k: int, cells: int) -> int:
        """Γ nodes of a side's P_k space on ``cells`` cells, ends included (sizing model).

        Parameters
        ----------
        k, cells : int

        Returns
        -------
        int
        """

    @abc.abstractmethod
    def multiplier_cells(self, n1: int, n2: int, choice: str = "omega2") -> int:
        """Cells of G_h for uniform traces of ``n1``, ``n2`` cells, ``choice`` omega2, omega1 or union.

        Returns
        -------
        int
        """

    # --- derived, shared by every implementation ----------------------------------------------
    def proven_kernel(self, space, k: int, traces, dim_w: int) -> int:
        """The part of dim ker Bᵀ on ``space`` that a count proves (the kernel rule never loses it
        to round-off): max(dim M − dim(W1 + W2), 0), ``dim_w`` = :meth:`trace_sum_dimension`.
        An interface may add local counts (:class:`~.face.shapes.triangulated_square.TriangulatedSquare`:
        the corners of Γ).

        Parameters
        ----------
        space : multiplier space on G_h
        k : int
        traces : sequence of GammaTrace
            The two sides' traces.
        dim_w : int

        Returns
        -------
        int
        """
        return max(space.dim - dim_w, 0)

    def builds(self, spec) -> bool:
        """Whether this interface has a space of the registry entry ``spec``; default: every one."""
        return True

    @abc.abstractmethod
    def uniform_partition(self, n: int):
        """The trace partition of uniform bodies with ``n`` cells per direction, without a mesh: what
        a request checks its spaces on before any body exists (``--case all`` on a 3D model, ``verdict``).

        Returns
        -------
        What :meth:`partition_of` returns for such a body's mesh.
        """

    def check_builds(self, spec) -> None:
        """:class:`InputError` naming ``case`` unless :meth:`builds` (a shape may say why in its words)."""
        if not self.builds(spec):
            raise InputError("case", f"a space this Γ builds ({spec.id} is not one)", got=spec.id)

    contact = True  # whether contact scenes (the patch test among them) run on this Γ's bodies

    def allows(self, k: int) -> bool:
        """Whether this Γ's bodies exist for displacement degree k (default: every k)."""
        return True

    def space(self, spec, k: int, partition):
        """The multiplier space of a registry entry on a partition of this interface.

        The default (the segment's): ``spec.build(k, partition)`` on the sorted breakpoints. A
        face builds its tensor products from the same 1D ``build`` (:class:`~.face.shapes.square.Square`).

        Parameters
        ----------
        spec : SpaceSpec
            A registry entry (:mod:`.spaces.registry`).
        k : int
            Displacement degree.
        partition : G_h

        Returns
        -------
        MultiplierSpace
            On ``partition`` (:mod:`.protocol`).

        Raises
        ------
        InputError
            For a partition without a cell, naming the case and k.
        """
        x = np.asarray(partition, dtype=float)
        n = self.cells(x) if x.ndim == 1 else 0
        if n < 1:
            raise InputError("multiplier mesh", f"a partition of Γ with at least one interval (case {spec.id}, "
                             f"k = {k}, N = {max(n, 0)})")
        return spec.build(k, x)

    def multiplier_partition_of(self, mesh1, mesh2, choice: str = "omega2", tol: float = 1e-12):
        """G_h of a mesh pair: :meth:`multiplier_partition` of their trace partitions."""
        return self.multiplier_partition(self.partition_of(mesh1), self.partition_of(mesh2), choice, tol)

    def coupling_quadrature(self, trace: GammaTrace, space, degree: int) -> tuple:
        """Quadrature exact for ``degree`` on the common refinement of a trace and G_h."""
        return self.quadrature(self.common_refinement(trace.partition, space.breakpoints), degree)

    def coupling_points(self, trace: GammaTrace, space, degree: int) -> tuple:
        """(x_μ, x_trace, w): B_i = Σ_q w_q μ(x_μ,q) φ(x_trace,q). The same points (:meth:`coupling_quadrature`)
        unless the sides are coupled by projection (:mod:`..segment.projection`)."""
        x, w = self.coupling_quadrature(trace, space, degree)
        return x, x, w

    def paired(self, sides: list) -> list:
        """The sides of a pair as the coupling sees them (a projection ties each to the other): as built."""
        return sides

