"""Test helper: the second, NGSolve-free route of the edge-dropping study — Laplace side
operators of boxes meshed by tensor grids, assembled from 1D matrices, and the couplings as
Kronecker products of 1D Gauss sums.

On a box meshed by the tensor grid xs × ys × zs, continuous Q_k is the tensor product of the
1D continuous P_k Lagrange spaces (:func:`~infsup_contact.discretization.segment.multipliers.make_space`),
and the Laplace stiffness is exactly

    K = K_x ⊗ M_y ⊗ M_z + M_x ⊗ K_y ⊗ M_z + M_x ⊗ M_y ⊗ K_z

with the 1D stiffness and mass matrices (Gauss–Legendre, exact). This is a second route to the
side operators of :mod:`infsup_contact.models.membranes3d` (hexahedra), independent of NGSolve,
and it takes any tensor grid: the study of partially covered faces
(:mod:`infsup_contact.study.face.edge_dropping`, whose production path uses NGSolve) has a body
(0, L) × (0, 1) × (1, 2); the tests check that both routes give the same β_h and condition numbers.

The side's contribution to the interface operator is B X Bᵀ with X = (K_ff⁻¹)_ΓΓ, the Γ block of
the inverse of K on the free dofs (= the inverse of K's Schur complement on the Γ dofs): the
face dofs are the nodes of the contact face z = z_Γ interior in x and y (every other face of
the box is Dirichlet).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from infsup_contact.discretization.segment.multipliers import local_monomial_coefficients, make_space
from infsup_contact.discretization.segment.norms import gram_l2
from infsup_contact.discretization.gamma.quadrature import gauss_legendre_01
from infsup_contact.errors import InputError


def lagrange_1d(xs: np.ndarray, k: int):
    """Continuous P_k Lagrange space on the 1D partition ``xs`` (all N k + 1 nodes)."""
    return make_space(np.asarray(xs, float), k, True, False)


def stiffness_1d(space) -> np.ndarray:
    """Exact ∫ φ_i' φ_j' of a Lagrange space (k Gauss points per interval)."""
    s = space.degree
    t, w = gauss_legendre_01(s + 1)
    C = local_monomial_coefficients(s)                     # shape_a(t) = Σ_p C[a, p] t^p
    dpow = np.array([[p * tt ** (p - 1) if p else 0.0 for p in range(s + 1)] for tt in t])
    d = dpow @ C.T                                         # (q, s+1): shape_a'(t)
    ref = (d * w[:, None]).T @ d
    K = np.zeros((space.dim, space.dim))
    for e, h in enumerate(np.diff(space.breakpoints)):
        idx = space.dofs[e]
        K[np.ix_(idx, idx)] += ref / h
    return K


def _free_pencils(spaces, dirichlet_z_end: int):
    """1D (K, M) restricted to the free nodes: interior in x and y; in z every node but the
    Dirichlet end (index ``dirichlet_z_end``: 0 or −1)."""
    out = []
    for d, s in enumerate(spaces):
        K, M = stiffness_1d(s), gram_l2(s)
        free = np.arange(1, s.dim - 1) if d < 2 else np.delete(np.arange(s.dim), dirichlet_z_end)
        out.append((K[np.ix_(free, free)], M[np.ix_(free, free)]))
    return out


def box_gamma_block(xs, ys, zs, k: int, gamma_top: bool, route: str = "eig") -> np.ndarray:
    """X = (K_ff⁻¹)_ΓΓ of the Q_k Laplacian on the box xs × ys × zs.

    Γ is the top face (z = zs[-1]) when ``gamma_top``, else the bottom face; the other five
    faces are Dirichlet. The Γ dofs are ordered (ix, iy), x-major, ix and iy the interior node
    indices of the x and y lattices (the order of :func:`face_dofs_1d` ⊗ itself).

    ``route``: "eig" — fast diagonalization (Lynch, Rice & Thomas 1964): with the 1D
    generalized eigenpairs K_d V_d = M_d V_d Λ_d, V_dᵀ M_d V_d = I of the free nodes,
    K_ff⁻¹ = (V_x ⊗ V_y ⊗ V_z) diag(1 / (λ_a + λ_b + λ_c)) (V_x ⊗ V_y ⊗ V_z)ᵀ, so
    X = (V_x ⊗ V_y) diag(w) (V_x ⊗ V_y)ᵀ with w_ab = Σ_c V_z[Γ, c]² / (λ_a + λ_b + λ_c);
    "lu" — sparse LU of the assembled 3D matrix, one solve per Γ dof (the check route).
    """
    spaces = [lagrange_1d(g, k) for g in (xs, ys, zs)]
    if route == "eig":
        import scipy.linalg as sla

        (vals, vecs) = zip(*(sla.eigh(K, M) for K, M in _free_pencils(spaces, 0 if gamma_top else -1)))
        face = -1 if gamma_top else 0
        lam = vals[0][:, None, None] + vals[1][None, :, None] + vals[2][None, None, :]
        w = (vecs[2][face] ** 2 / lam).sum(axis=2).ravel()
        V = np.kron(vecs[0], vecs[1])
        X = (V * w) @ V.T
        return 0.5 * (X + X.T)
    if route != "lu":
        raise InputError("route", "eig, lu", got=route)
    M = [sp.csr_matrix(gram_l2(s)) for s in spaces]
    K = [sp.csr_matrix(stiffness_1d(s)) for s in spaces]
    A = (sp.kron(sp.kron(K[0], M[1]), M[2]) + sp.kron(sp.kron(M[0], K[1]), M[2])
         + sp.kron(sp.kron(M[0], M[1]), K[2])).tocsr()
    nx, ny, nz = (s.dim for s in spaces)
    ix, iy, iz = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    ix, iy, iz = ix.ravel(), iy.ravel(), iz.ravel()
    face_z = nz - 1 if gamma_top else 0
    inner = (ix > 0) & (ix < nx - 1) & (iy > 0) & (iy < ny - 1)
    free = inner & ((iz == face_z) | ((iz > 0) & (iz < nz - 1)))
    gamma = inner & (iz == face_z)
    free_idx = np.flatnonzero(free)
    pos = -np.ones(len(ix), dtype=int)
    pos[free_idx] = np.arange(len(free_idx))
    g = pos[np.flatnonzero(gamma)]                 # already x-major (ix, iy) order
    lu = spla.splu(A[free_idx][:, free_idx].tocsc())
    E = np.zeros((len(free_idx), len(g)))
    E[g, np.arange(len(g))] = 1.0
    X = lu.solve(E)[g]
    return 0.5 * (X + X.T)


def face_dofs_1d(xs, k: int) -> np.ndarray:
    """Indices of the interior nodes of the 1D lattice (the Γ dofs per direction)."""
    return np.arange(1, lagrange_1d(xs, k).dim - 1)


def _merged(*grids, upper: float = 1.0) -> np.ndarray:
    g = np.unique(np.concatenate([np.asarray(v, float) for v in grids] + [[upper]]))
    g = g[g <= upper + 1e-14]
    return g[np.concatenate([[True], np.diff(g) > 1e-13])]


def couplings_1d(face, trace_space, axis: str, k: int) -> np.ndarray:
    """∫ μ_a φ_p of the clipped x factor over (0, L) (``axis`` "x") or of the y factor over
    (0, 1) (``axis`` "y") against every nodal function φ_p of a 1D Lagrange space, by
    Gauss–Legendre on the common refinement (exact: degree ≤ 2k per interval)."""
    if axis == "x":
        grid = _merged(np.asarray(face.space.sx.breakpoints) * face.L, trace_space.breakpoints, upper=face.L)
        mu = face.evaluate_x
    else:
        grid = _merged(face.space.sy.breakpoints, trace_space.breakpoints)
        mu = face.space.sy.evaluate
    t, w = gauss_legendre_01(k + 2)
    a, b = grid[:-1, None], grid[1:, None]
    pts, wts = (a + (b - a) * t).ravel(), ((b - a) * w).ravel()
    return (mu(pts) * wts[:, None]).T @ trace_space.evaluate(pts)


def tensor_interface_operator(face, k: int, grids: dict) -> np.ndarray:
    """S = Σ_i B_i X_i B_iᵀ (c1 = c2 = 1) with B_i = B_i^x ⊗ B_i^y and X_i of
    :func:`box_gamma_block`; ``grids`` {side: (xs, ys, zs)} as
    :func:`infsup_contact.study.face.edge_dropping.geometry` gives them."""
    S = np.zeros((face.dim, face.dim))
    for i, (xs, ys, zs) in grids.items():
        bx = couplings_1d(face, lagrange_1d(xs, k), "x", k)[:, face_dofs_1d(xs, k)]
        by = couplings_1d(face, lagrange_1d(ys, k), "y", k)[:, face_dofs_1d(ys, k)]
        B = np.kron(bx, by)
        S += B @ box_gamma_block(xs, ys, zs, k, gamma_top=i == 1) @ B.T
    return S
