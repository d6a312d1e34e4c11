"""Γ as an object: the contact interface every consumer talks to.

:class:`Interface` owns everything that depends on the shape of Γ: its geometry and
dimension, the partitions G_h (the trace of Ω1, of Ω2, their common refinement and the
multiplier partition chosen from them), the trace dofs of a side, quadrature on a partition,
the values of a side's trace basis at points of Γ, the Gram matrices of its norms (L² and the
exact H^{-1/2}_00) and the dimension counts the kernel proof, the registry and the sizing model
use. Multiplier spaces are built on it: ``registry.case_space(case, k, partition, gamma)``
builds a registered space on a partition of ``gamma`` (the registry imports this module, never
the other way round).

Coupling (:mod:`.coupling`), β_h (:mod:`infsup_contact.solvers.infsup`), contact
(:mod:`infsup_contact.solvers.contact`) and the scenes ask the interface; they never take a
partition apart. A partition is opaque to them: they obtain it from the interface and hand it
back to it. A side's trace carries its interface (``trace.gamma``), so a consumer holding the
sides of a mesh pair finds Γ there.

:class:`Segment` — Γ = (0, 1) × {1}, the paper's — is the one implementation; its partition
is the sorted array of breakpoints (abscissae x of the vertices on Γ), the representation
:class:`~.multipliers.MultiplierSpace` and users' spaces (``build(k, x)``) are built on.
A 2D contact face is a second subclass implementing the abstract methods below.
"""
from __future__ import annotations

import abc
import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from .quadrature import gauss_legendre

MULTIPLIER_MESHES = ("omega2", "omega1", "union")
"""The choices of G_h: the trace partition of Ω2 (the paper's default), of Ω1, or their union."""


@dataclass(frozen=True)
class GammaTrace:
    """The Γ trace of a displacement space V_{h,i} = H1(mesh_i, order=k, dirichlet="dir").

    Attributes
    ----------
    fes : ngsolve.H1
        The displacement space.
    gamma_dofs : ndarray of int
        Free NGSolve dofs that live on Γ (endpoint vertices are Dirichlet), sorted.
    elements : list of (x_first, x_second, dofs, element)
        Γ boundary elements: x of the element's first and second vertex and its dofs.
    breakpoints : ndarray
        The trace partition (for a :class:`Segment`: sorted x of its vertices); consumers
        read it as :attr:`partition`.
    gamma : Interface
        The interface this trace lives on.
    basis_cache : dict
        Values of the Γ-dof basis at point sets already asked for (:meth:`Interface.trace_basis`).
    """

    fes: object
    gamma_dofs: np.ndarray
    elements: list
    breakpoints: np.ndarray
    gamma: "Interface" = field(default=None, repr=False, compare=False)
    basis_cache: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def partition(self):
        """The trace partition of this side on Γ (opaque: hand it back to :attr:`gamma`)."""
        return self.breakpoints


class Interface(abc.ABC):
    """The contact interface Γ and what is discretized on it.

    A *partition* is whatever the implementation uses to describe a partition of Γ into
    cells (for a :class:`Segment`, sorted breakpoints); consumers get partitions from the
    interface (:meth:`partition_of`, :meth:`multiplier_partition`, :meth:`common_refinement`,
    ``trace.partition``, ``space.breakpoints``) and pass them back — to the interface, or with it
    to ``registry.case_space(case, k, partition, gamma)`` — never inspecting them.
    """

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

        Parameters
        ----------
        partition : partition

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
        per_cell : int
            Subdivisions of each cell.
        upper : float, optional
            Points are clipped into Γ; ``upper`` lowers the upper clip (a point exactly on the
            far end of Γ belongs to no cell of a half-open search).

        Returns
        -------
        ndarray
            Points in Γ's parameters, sorted.
        """

    @abc.abstractmethod
    def at_boundary(self, partition, x: np.ndarray) -> np.ndarray:
        """Whether each point lies in a cell of ``partition`` touching ∂Γ (where a multiplier
        space's end conditions act; the patch test reports those cells apart).

        Parameters
        ----------
        partition : partition
        x : ndarray
            Points of Γ.

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
        ndarray, shape (len(x), len(trace.gamma_dofs))
            Read-only (values may be cached on the trace).
        """

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
        x, w : ndarray
            Points (Γ's parameters) and weights.
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
        G : ndarray, shape (dim M, dim M)
            Symmetric positive definite.
        info : dict
            ``n_max`` and ``nmax_rel_error`` of a truncated route (0 for exact ones).
        """

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
        """Cells of G_h when the traces of Ω1 and Ω2 are uniform with ``n1`` and ``n2`` cells
        (the registry's emptiness checks and the sizing model).

        Parameters
        ----------
        n1, n2 : int
        choice : {"omega2", "omega1", "union"}

        Returns
        -------
        int
        """

    # --- derived, shared by every implementation ----------------------------------------------
    def multiplier_partition_of(self, mesh1, mesh2, choice: str = "omega2", tol: float = 1e-12):
        """G_h of a mesh pair: :meth:`multiplier_partition` of their trace partitions."""
        return self.multiplier_partition(self.partition_of(mesh1), self.partition_of(mesh2), choice, tol)

    def coupling_quadrature(self, trace: GammaTrace, space, degree: int) -> tuple:
        """Quadrature exact for ``degree`` on the common refinement of a trace and G_h."""
        return self.quadrature(self.common_refinement(trace.partition, space.breakpoints), degree)


def check_choice(choice: str) -> None:
    """:class:`InputError` unless ``choice`` names a G_h (:data:`MULTIPLIER_MESHES`)."""
    if choice not in MULTIPLIER_MESHES:
        raise InputError("multiplier_mesh", ", ".join(MULTIPLIER_MESHES), got=choice)


_BASIS_CACHE_SIZE = 4


@dataclass(frozen=True)
class Segment(Interface):
    """Γ = (a, b) × {y}, the paper's (0, 1) × {1}: partitions are sorted breakpoint arrays.

    Attributes
    ----------
    boundary : str
        Name of Γ's boundary region in the meshes (``meshes.GAMMA``).
    y : float
        Height of Γ.
    """

    boundary: str = "gamma"
    y: float = 1.0

    @property
    def dim(self) -> int:
        return 1

    def embed(self, x):
        x = np.asarray(x, dtype=float)
        return x, np.full_like(x, self.y)

    # --- partitions
    def partition_of(self, mesh) -> np.ndarray:
        """Sorted x-coordinates of the mesh vertices on Γ (the trace partition)."""
        import ngsolve

        xs = set()
        for el in mesh.Elements(ngsolve.BND):
            if el.mat == self.boundary:
                for v in el.vertices:
                    xs.add(mesh[v].point[0])
        return np.array(sorted(xs))

    def common_refinement(self, *partitions, tol: float = 1e-12) -> np.ndarray:
        """Sorted union of the breakpoints, merging points closer than ``tol``."""
        x = np.unique(np.concatenate(partitions))
        return x[np.concatenate([[True], np.diff(x) > tol])]

    def multiplier_partition(self, trace1, trace2, choice: str = "omega2", tol: float = 1e-12) -> np.ndarray:
        check_choice(choice)
        if choice == "union":
            return self.common_refinement(trace1, trace2, tol=tol)
        return np.asarray(trace2 if choice == "omega2" else trace1)

    def cells(self, partition) -> int:
        return len(partition) - 1

    def partition_key(self, partition) -> bytes:
        return np.asarray(partition).tobytes()

    def sample(self, partition, per_cell: int, upper: float | None = None) -> np.ndarray:
        g = np.asarray(partition)
        t = np.linspace(0.0, 1.0, per_cell + 1)
        return np.unique(np.clip((g[:-1, None] + np.outer(np.diff(g), t)).ravel(), 0.0,
                                 1.0 if upper is None else upper))

    def at_boundary(self, partition, x: np.ndarray) -> np.ndarray:
        """Whether each point of ``x`` lies in the first or last interval of ``partition``."""
        g = np.asarray(partition)
        e = np.clip(np.searchsorted(g, x, side="right") - 1, 0, len(g) - 2)
        return (e == 0) | (e == len(g) - 2)

    # --- trace dofs
    def trace(self, fes) -> GammaTrace:
        """Collect the Γ boundary elements, their vertex abscissae and dofs."""
        import ngsolve

        mesh, free = fes.mesh, fes.FreeDofs()
        elements, dofs = [], set()
        for el in mesh.Elements(ngsolve.BND):
            if el.mat != self.boundary:
                continue
            x0, x1 = (mesh[v].point[0] for v in el.vertices)
            dn = np.array(fes.GetDofNrs(el))
            elements.append((x0, x1, dn, el))
            dofs.update(int(d) for d in dn if d >= 0 and free[int(d)])
        elements.sort(key=lambda e: min(e[0], e[1]))
        bps = np.array(sorted({min(e[0], e[1]) for e in elements} | {max(e[0], e[1]) for e in elements}))
        return GammaTrace(fes, np.array(sorted(dofs), dtype=int), elements, bps, self)

    def trace_values(self, trace: GammaTrace, x: np.ndarray):
        """Values of the Γ-dof basis functions at points x (interior of trace elements).

        Returns
        -------
        rows, cols, vals : arrays for a COO matrix of shape (len(x), len(gamma_dofs)).
        """
        position = -np.ones(trace.fes.ndof, dtype=int)
        position[trace.gamma_dofs] = np.arange(len(trace.gamma_dofs))
        e = np.clip(np.searchsorted(trace.breakpoints, x, side="right") - 1, 0, len(trace.elements) - 1)
        rows, cols, vals, fes = [], [], [], {}
        for i, (xi, ei) in enumerate(zip(x, e)):
            x0, x1, dn, el = trace.elements[ei]
            if ei not in fes:  # GetFE once per element, not once per point
                fes[ei] = trace.fes.GetFE(el)
            fe = fes[ei]
            # the reference coordinate runs from the second vertex (0) to the first (1)
            shape = np.asarray(fe.CalcShape((xi - x1) / (x0 - x1), 0.0, 0.0))
            pos = position[dn]
            keep = pos >= 0
            rows.append(np.full(keep.sum(), i))
            cols.append(pos[keep])
            vals.append(shape[keep])
        return np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)

    def trace_basis(self, trace: GammaTrace, x: np.ndarray) -> np.ndarray:
        """Dense values of the Γ-dof basis at the points x, shape (len(x), number of Γ dofs).

        Every multiplier space of one degree on one partition G_h asks for the same quadrature
        points (T3, R5.2 and the dual bases; the three multiplier meshes of a matching pair), and
        NGSolve evaluates one point at a time: the values are kept on the trace (a few point sets,
        read-only) and computed once.
        """
        key = np.ascontiguousarray(x, dtype=float).tobytes()
        phi = trace.basis_cache.get(key)
        if phi is None:
            rows, cols, vals = self.trace_values(trace, x)
            phi = np.zeros((len(x), len(trace.gamma_dofs)))
            np.add.at(phi, (rows, cols), vals)
            phi.flags.writeable = False
            if len(trace.basis_cache) >= _BASIS_CACHE_SIZE:
                trace.basis_cache.clear()
            trace.basis_cache[key] = phi
        return phi

    # --- quadrature and norms
    def quadrature(self, partition, degree: int) -> tuple:
        """Gauss–Legendre points and weights exact for polynomials of ``degree`` per interval."""
        breakpoints = np.asarray(partition)
        t, w = gauss_legendre(degree // 2 + 1)
        a, b = breakpoints[:-1, None], breakpoints[1:, None]
        x = 0.5 * (a + b) + 0.5 * (b - a) * t[None, :]
        return x.ravel(), (0.5 * (b - a) * w[None, :]).ravel()

    def gram(self, space, norm: str, h_route: str = "logkernel", **kwargs) -> tuple:
        """:func:`~.norms.gram`: L² exactly, H by the log kernel (or the sine series)."""
        from .norms import gram

        return gram(space, norm, h_route=h_route, **kwargs)

    # --- spaces and counts
    def trace_dimension(self, k: int, cells: int) -> int:
        return cells * k - 1

    def common_coarsening(self, trace1, trace2, tol: float = 1e-12) -> np.ndarray:
        """Breakpoints shared by two partitions of Γ."""
        return np.array([x for x in trace1 if np.min(np.abs(trace2 - x)) < tol])

    def trace_sum_dimension(self, k: int, trace1, trace2) -> int:
        """dim(W1 + W2) = dim W1 + dim W2 − dim(W1 ∩ W2); W1 ∩ W2 lives on the common coarsening."""
        n1, n2, nc = len(trace1) - 1, len(trace2) - 1, len(self.common_coarsening(trace1, trace2)) - 1
        return (n1 * k - 1) + (n2 * k - 1) - (nc * k - 1)

    def trace_nodes(self, k: int, cells: int) -> int:
        return cells * k + 1

    def multiplier_cells(self, n1: int, n2: int, choice: str = "omega2") -> int:
        """N2 (``omega2``), N1 (``omega1``), or N1 + N2 − gcd(N1, N2) for their ``union``
        (i/N1 = j/N2 exactly at the multiples of 1/gcd)."""
        return {"omega2": n2, "omega1": n1}.get(choice, n1 + n2 - math.gcd(n1, n2))


SEGMENT = Segment()
"""The paper's Γ = (0, 1) × {1}."""
