"""The coupling matrices B_i of b(v, μ) = ∫_Γ (v2 − v1) μ (paper, eqs. (3.5), (3.11)).

B_i[j, d] = ∫_Γ μ_j φ_d for the multiplier basis μ_j and the Γ dofs φ_d of V_{h,i}; then
b(v, μ) = μᵀ (B_2 v_2 − B_1 v_1). Both factors are polynomial on every interval of the
union of all breakpoints (the two trace partitions and G_h), so Gauss–Legendre with
⌈(k + s + 1)/2⌉ points per union interval is exact.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import ngsolve

from .meshes import GAMMA
from .multipliers import MultiplierSpace
from .quadrature import gauss_legendre


@dataclass(frozen=True)
class GammaTrace:
    """The Γ trace of a displacement space V_{h,i} = H1(mesh_i, order=k, dirichlet="dir").

    Attributes
    ----------
    fes : ngsolve.H1
        The displacement space.
    gamma_dofs : ndarray of int
        Free NGSolve dofs that live on Γ (endpoint vertices are Dirichlet), sorted.
    elements : list of (x_first, x_second, dofs)
        Γ boundary elements: x of the element's first and second vertex and its dofs.
    breakpoints : ndarray
        Sorted x of the trace partition.
    basis_cache : dict
        Values of the Γ-dof basis at quadrature points already asked for (:func:`trace_basis_at`).
    """

    fes: ngsolve.H1
    gamma_dofs: np.ndarray
    elements: list
    breakpoints: np.ndarray
    basis_cache: dict = field(default_factory=dict, repr=False, compare=False)


def gamma_trace(fes) -> GammaTrace:
    """Collect the Γ boundary elements, their vertex abscissae and dofs."""
    mesh, free = fes.mesh, fes.FreeDofs()
    elements, dofs = [], set()
    for el in mesh.Elements(ngsolve.BND):
        if el.mat != GAMMA:
            continue
        x0, x1 = (mesh[v].point[0] for v in el.vertices)
        dn = np.array(fes.GetDofNrs(el))
        elements.append((x0, x1, dn, el))
        dofs.update(int(d) for d in dn if d >= 0 and free[int(d)])
    elements.sort(key=lambda e: min(e[0], e[1]))
    bps = np.array(sorted({min(e[0], e[1]) for e in elements} | {max(e[0], e[1]) for e in elements}))
    return GammaTrace(fes, np.array(sorted(dofs), dtype=int), elements, bps)


def union_breakpoints(*partitions, tol: float = 1e-12) -> np.ndarray:
    """Sorted union of several partitions of Γ, merging points closer than ``tol``."""
    x = np.unique(np.concatenate(partitions))
    return x[np.concatenate([[True], np.diff(x) > tol])]


def quadrature_on(breakpoints: np.ndarray, degree: int):
    """Gauss–Legendre points and weights exact for polynomials of ``degree`` per interval."""
    t, w = gauss_legendre(degree // 2 + 1)
    a, b = breakpoints[:-1, None], breakpoints[1:, None]
    x = 0.5 * (a + b) + 0.5 * (b - a) * t[None, :]
    return x.ravel(), (0.5 * (b - a) * w[None, :]).ravel()


def trace_values(trace: GammaTrace, x: np.ndarray):
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


def coupling_matrix(trace: GammaTrace, space: MultiplierSpace, k: int, extra_degree: int = 0) -> np.ndarray:
    """B_i[j, d] = ∫_Γ μ_j φ_d, dense, shape (dim M, number of Γ dofs); exact.

    ``extra_degree`` > 0 uses a rule exact for that much higher degree: the same matrix up
    to round-off, which is how the kernel decision measures the round-off of the entries."""
    x, w = quadrature_on(union_breakpoints(trace.breakpoints, space.breakpoints), k + space.degree + extra_degree)
    mu = space.evaluate(x)  # (n_q, dim M)
    return (mu * w[:, None]).T @ trace_basis_at(trace, x)


def trace_l2_norms(trace: GammaTrace, k: int) -> np.ndarray:
    """‖φ_d‖_{L²(Γ)} of the Γ-dof basis functions (exact Gauss rule for the degree-2k squares):
    the row scaling of the kernel decision (:func:`infsup_contact.solvers.kernel.scaled_couplings`)."""
    x, w = quadrature_on(trace.breakpoints, 2 * k)
    return np.sqrt(w @ trace_basis_at(trace, x) ** 2)


_BASIS_CACHE_SIZE = 4


def trace_basis_at(trace: GammaTrace, x: np.ndarray) -> np.ndarray:
    """Dense values of the Γ-dof basis at the points x, shape (len(x), number of Γ dofs).

    Every multiplier space of one degree on one partition G_h asks for the same quadrature
    points (T3, R5.2 and the dual bases; the three multiplier meshes of a matching pair), and
    NGSolve evaluates one point at a time: the values are kept on the trace (a few point sets,
    read-only) and computed once.
    """
    key = np.ascontiguousarray(x, dtype=float).tobytes()
    phi = trace.basis_cache.get(key)
    if phi is None:
        rows, cols, vals = trace_values(trace, x)
        phi = np.zeros((len(x), len(trace.gamma_dofs)))
        np.add.at(phi, (rows, cols), vals)
        phi.flags.writeable = False
        if len(trace.basis_cache) >= _BASIS_CACHE_SIZE:
            trace.basis_cache.clear()
        trace.basis_cache[key] = phi
    return phi
