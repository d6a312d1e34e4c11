"""Lagrange-multiplier spaces on a 1D partition G_h of Γ = (0, 1).

The spaces are the paper's (5.3) and (5.5):

* ``M^r_s``   — piecewise P_s on G_h, continuous (r = 1) or not (r = 0);
* ``M^r_{0,s}`` — the same, vanishing at the endpoints x = 0 and x = 1.

The named cases of Section 5 (and every other space) live in the registry,
:mod:`infsup_contact.discretization.spaces.registry`.

A space is plain data: the breakpoints, the local degree and the local-to-global dof
map. Local shape functions are Lagrange polynomials on equispaced nodes of the
reference interval t ∈ [0, 1] (for s = 0 the constant 1), so a dof is a nodal value and
the cone "λ_h ≥ 0 at the nodes" is "dof ≥ 0".

A space may instead carry its own local basis, per interval a combination of those
Lagrange shapes (``local_coefficients``: ψ_{e,a} = Σ_b C[e, a, b] L_b): the dual mortar
bases (:mod:`infsup_contact.discretization.segment.dual`) and users' spaces
(:func:`local_basis_space`) are built that way, and every consumer (evaluation, Gram
matrices, coupling) applies C where it would use the shapes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ..gamma.protocol import SpaceDefaults

@dataclass(frozen=True)
class SegmentSpace(SpaceDefaults):
    """A 1D piecewise-polynomial space on the partition ``breakpoints`` of Γ.

    Attributes
    ----------
    breakpoints : ndarray, shape (N + 1,)
        Nodes 0 = x_0 < ... < x_N = 1 of G_h.
    degree : int
        Local polynomial degree s.
    continuous : bool
        r = 1 (continuous) or r = 0 (discontinuous).
    vanish_at_ends : bool
        Whether μ(0) = μ(1) = 0 is imposed (the spaces (5.5)).
    dofs : ndarray of int, shape (N, s + 1)
        Global dof of each local shape function, −1 where a shape function is dropped
        (the endpoint condition).
    dim : int
        Dimension of the space.
    local_coefficients : ndarray, shape (N, s + 1, s + 1), optional
        Local basis per interval in terms of the Lagrange shapes, ψ_{e,a} = Σ_b C[e, a, b] L_b;
        None for the Lagrange basis itself (a dof is then a nodal value).
    """

    breakpoints: np.ndarray
    degree: int
    continuous: bool
    vanish_at_ends: bool
    dofs: np.ndarray
    dim: int
    local_coefficients: np.ndarray | None = None

    def to_local_basis(self, local: np.ndarray, elements=None) -> np.ndarray:
        """Values given per Lagrange shape, ``local[e, b, ...]``, turned into values per local
        basis function: Σ_b C[e, a, b] local[e, b, ...] (identity for a Lagrange basis).
        ``elements`` selects the rows of C when ``local`` is given for some intervals only."""
        if self.local_coefficients is None:
            return local
        C = self.local_coefficients if elements is None else self.local_coefficients[elements]
        return np.einsum("eab,eb...->ea...", C, local)

    @property
    def n_intervals(self) -> int:
        return len(self.breakpoints) - 1

    def nodes(self) -> np.ndarray:
        """Coordinates of the global dofs (the Lagrange nodes), shape (dim,)."""
        x = np.empty(self.dim)
        t = reference_nodes(self.degree)
        a, b = self.breakpoints[:-1], self.breakpoints[1:]
        pts = a[:, None] + (b - a)[:, None] * t[None, :]
        mask = self.dofs >= 0
        x[self.dofs[mask]] = pts[mask]
        return x

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """Dense matrix of all basis functions at points ``x``, shape (len(x), dim).

        A point on a breakpoint is assigned to the interval on its right (the last
        breakpoint to the last interval); discontinuous spaces are thus right-continuous.
        """
        x = np.asarray(x, dtype=float)
        vals, cols = self._local(x)
        out = np.zeros((len(x), self.dim))
        rows = np.repeat(np.arange(len(x)), self.degree + 1)
        cols = cols.ravel()
        keep = cols >= 0
        np.add.at(out, (rows[keep], cols[keep]), vals.ravel()[keep])
        return out

    def local_values(self, x: np.ndarray):
        """The nonzero pattern of :meth:`evaluate`: (values, dofs), each (len(x), s + 1), with
        ``evaluate(x)[i, dofs[i, a]] == values[i, a]`` for ``dofs[i, a] >= 0`` (−1: a dropped
        shape) and zero elsewhere — the same numbers from the same operations, bit for bit. None
        when an interval maps two local functions to one dof (:meth:`evaluate` then adds them)."""
        if not self._distinct_local_dofs:
            return None
        return self._local(np.asarray(x, dtype=float))

    @property
    def _distinct_local_dofs(self) -> bool:
        d = np.sort(self.dofs, axis=1)
        return not np.any((d[:, 1:] == d[:, :-1]) & (d[:, 1:] >= 0))

    def _local(self, x: np.ndarray) -> tuple:
        """(values of the s + 1 local basis functions, their global dofs) at the points x: a point
        on a breakpoint is taken by the interval on its right (the last breakpoint by the last)."""
        e = np.clip(np.searchsorted(self.breakpoints, x, side="right") - 1, 0, self.n_intervals - 1)
        a, b = self.breakpoints[e], self.breakpoints[e + 1]
        vals = local_shapes(self.degree, (x - a) / (b - a))
        if self.local_coefficients is not None:
            vals = np.einsum("iab,ib->ia", self.local_coefficients[e], vals)
        return vals, self.dofs[e]


def reference_nodes(s: int) -> np.ndarray:
    """Equispaced Lagrange nodes on [0, 1]; the midpoint for s = 0."""
    return np.array([0.5]) if s == 0 else np.linspace(0.0, 1.0, s + 1)


def local_shapes(s: int, t: np.ndarray) -> np.ndarray:
    """Lagrange shape functions of degree s at reference points t, shape (len(t), s + 1)."""
    t = np.asarray(t, dtype=float)
    nodes = reference_nodes(s)
    out = np.ones((len(t), s + 1))
    for a in range(s + 1):
        for b in range(s + 1):
            if a != b:
                out[:, a] *= (t - nodes[b]) / (nodes[a] - nodes[b])
    return out


def local_monomial_coefficients(s: int) -> np.ndarray:
    """Coefficients C with shape_a(t) = Σ_p C[a, p] t^p, shape (s + 1, s + 1)."""
    nodes = reference_nodes(s)
    vander = np.vander(nodes, s + 1, increasing=True)  # V[i, p] = nodes_i^p
    return np.linalg.inv(vander).T


def make_space(breakpoints, degree: int, continuous: bool, vanish_at_ends: bool) -> SegmentSpace:
    """Build the general space ``M^r_s`` or ``M^r_{0,s}`` on the partition ``breakpoints``.

    Raises
    ------
    InputError
        For a negative degree, a continuous space of degree 0, or a bad partition.
    """
    x = np.asarray(breakpoints, dtype=float)
    if x.ndim != 1 or len(x) < 2 or not np.all(np.diff(x) > 0):
        raise InputError("breakpoints", "a strictly increasing array with at least 2 entries")
    if degree < 0:
        raise InputError("degree", "an integer s >= 0")
    if continuous and degree == 0:
        raise InputError("degree", "s >= 1 for a continuous space (continuous P_0 is only the constants)")
    n, s = len(x) - 1, degree
    if continuous:
        dofs = np.arange(n)[:, None] * s + np.arange(s + 1)[None, :]
        if vanish_at_ends:
            dofs = dofs - 1
            dofs[-1, -1] = -1  # the last node, x = 1; x = 0 became −1 by the shift
    else:
        dofs = np.arange(n * (s + 1)).reshape(n, s + 1)
        if vanish_at_ends and s >= 1:
            # drop the shape functions that are nonzero at x = 0 and x = 1
            dofs[0, 0] = dofs[-1, -1] = -1
            live = np.unique(dofs[dofs >= 0])
            renum = -np.ones(n * (s + 1), dtype=int)
            renum[live] = np.arange(len(live))
            dofs = np.where(dofs >= 0, renum[np.maximum(dofs, 0)], -1)
        elif vanish_at_ends:
            raise InputError("vanish_at_ends", "False for discontinuous P_0 (no endpoint nodes)")
    dim = int(dofs.max()) + 1
    return SegmentSpace(x, s, continuous, vanish_at_ends, dofs, dim)


def local_basis_space(breakpoints, degree: int, dofs, coefficients=None, *, continuous: bool = False,
                      vanish_at_ends: bool = False) -> SegmentSpace:
    """A space given by its local basis and global numbering — the public way to define one.

    Parameters
    ----------
    breakpoints : array_like, shape (N + 1,)
        The partition G_h of Γ = (0, 1).
    degree : int
        Local polynomial degree s.
    dofs : array_like of int, shape (N, s + 1)
        Global number of each local basis function (−1: dropped, e.g. at Γ's ends); the
        numbers used must be 0 .. dim − 1. Sharing a number between neighbouring intervals
        glues the pieces into one basis function.
    coefficients : array_like, shape (s + 1, s + 1) or (N, s + 1, s + 1), optional
        Local basis in terms of the equispaced Lagrange shapes L_b of degree s:
        ψ_{e,a} = Σ_b C[e, a, b] L_b (one matrix for every interval, or one per interval).
        Default: the Lagrange shapes themselves.
    continuous, vanish_at_ends : bool
        Descriptive flags (what the space is), not constraints.

    Raises
    ------
    InputError
        Naming the argument that is malformed.
    """
    x = np.asarray(breakpoints, dtype=float)
    if x.ndim != 1 or len(x) < 2 or not np.all(np.diff(x) > 0):
        raise InputError("breakpoints", "a strictly increasing array with at least 2 entries")
    n, s = len(x) - 1, int(degree)
    dofs = np.asarray(dofs)
    if dofs.shape != (n, s + 1) or not np.issubdtype(dofs.dtype, np.integer):
        raise InputError("dofs", f"an integer array of shape (N, s + 1) = ({n}, {s + 1})", got=dofs.shape)
    used = np.unique(dofs[dofs >= 0])
    if not len(used) or not np.array_equal(used, np.arange(len(used))):
        raise InputError("dofs", "global numbers 0 .. dim − 1, each used (−1 for a dropped function)")
    C = None
    if coefficients is not None:
        C = np.asarray(coefficients, dtype=float)
        if C.shape == (s + 1, s + 1):
            C = np.broadcast_to(C, (n, s + 1, s + 1)).copy()
        if C.shape != (n, s + 1, s + 1) or not np.all(np.isfinite(C)):
            raise InputError("coefficients", "finite numbers of shape (s + 1, s + 1) or (N, s + 1, s + 1)",
                             got=C.shape)
    return SegmentSpace(x, s, bool(continuous), bool(vanish_at_ends), dofs.astype(int), len(used), C)

