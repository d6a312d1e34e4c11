"""Laplace side operators of boxes meshed by tensor grids, assembled from 1D matrices.

On a box meshed by the tensor grid xs × ys × zs, continuous Q_k is the tensor product of the
1D continuous P_k Lagrange spaces (:func:`~infsup_contact.discretization.multipliers.make_space`),
and the Laplace stiffness is exactly

    K = K_x ⊗ M_y ⊗ M_z + M_x ⊗ K_y ⊗ M_z + M_x ⊗ M_y ⊗ K_z

with the 1D stiffness and mass matrices (Gauss–Legendre, exact). This is a second route to the
side operators of :mod:`infsup_contact.models.membranes3d` (hexahedra), independent of NGSolve,
and it takes any tensor grid: the study of partially covered faces
(:mod:`.edge_dropping`) needs a body (0, L) × (0, 1) × (1, 2).

The side's contribution to the interface operator is B X Bᵀ with X = (K_ff⁻¹)_ΓΓ, the Γ block of
the inverse of K on the free dofs (= the inverse of K's Schur complement on the Γ dofs): the
face dofs are the nodes of the contact face z = z_Γ interior in x and y (every other face of
the box is Dirichlet).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..discretization.multipliers import local_monomial_coefficients, make_space
from ..discretization.norms import gram_l2
from ..discretization.quadrature import gauss_legendre_01


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


def box_gamma_block(xs, ys, zs, k: int, gamma_top: bool) -> np.ndarray:
    """X = (K_ff⁻¹)_ΓΓ of the Q_k Laplacian on the box xs × ys × zs.

    Γ is the top face (z = zs[-1]) when ``gamma_top``, else the bottom face; the other five
    faces are Dirichlet. The Γ dofs are ordered (ix, iy), x-major, ix and iy the interior node
    indices of the x and y lattices (the order of :func:`face_dofs_1d` ⊗ itself).
    """
    spaces = [lagrange_1d(g, k) for g in (xs, ys, zs)]
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
