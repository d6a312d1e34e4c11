"""The paper's Γ = (0, 1) × {1}: :class:`Segment`, the one implementation of
:class:`~.gamma.interface.Interface`, whose partitions are sorted arrays of breakpoints."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..gamma.interface import Interface
from ..gamma.multiplier_meshes import check_choice, intervals_per_direction
from ..gamma.trace import GammaTrace
from ..gamma.quadrature import gauss_legendre


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

    def uniform_partition(self, n: int) -> np.ndarray:
        """The breakpoints of N uniform segments."""
        return np.linspace(0.0, 1.0, int(n) + 1)

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
        def dense(x):
            rows, cols, vals = self.trace_values(trace, x)
            phi = np.zeros((len(x), len(trace.gamma_dofs)))
            np.add.at(phi, (rows, cols), vals)
            return phi

        return trace.cached_basis(x, dense)

    # --- quadrature and norms
    def quadrature(self, partition, degree: int) -> tuple:
        """Gauss–Legendre points and weights exact for polynomials of ``degree`` per interval."""
        breakpoints = np.asarray(partition)
        t, w = gauss_legendre(degree // 2 + 1)
        a, b = breakpoints[:-1, None], breakpoints[1:, None]
        x = 0.5 * (a + b) + 0.5 * (b - a) * t[None, :]
        return x.ravel(), (0.5 * (b - a) * w[None, :]).ravel()

    def gram(self, space, norm: str, h_route: str = "logkernel", **kwargs) -> tuple:
        """:func:`~.segment.norms.gram`: L² exactly, H by the log kernel (or the sine series)."""
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
        """The intervals of G_h (:func:`~..gamma.interface.intervals_per_direction`)."""
        return intervals_per_direction(n1, n2, choice)


SEGMENT = Segment()
"""The paper's Γ = (0, 1) × {1}."""
