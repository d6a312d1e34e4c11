"""The membranes model of the paper's Section 3: −c_i Δu_i = f_i, u_i = 0 on ∂Ω_i∖Γ.

Its side operator is the Laplace stiffness K_i of continuous P_k (eq. (5.1)) with its Γ
Schur complement (:mod:`infsup_contact.models.schur`); A_i = c_i K_i, so the material
scale of side i is c_i.
"""
from __future__ import annotations

import numpy as np
import ngsolve
import scipy.sparse as sp

from ..discretization.coupling import gamma_trace
from .contract import Model
from .schur import SideOperator, factorized_side


def displacement_space(mesh, k: int):
    """V_{h,i}: continuous P_k, u_i = 0 on ∂Ω_i∖Γ (eq. (5.1))."""
    return ngsolve.H1(mesh, order=k, dirichlet="dir")


def laplace_stiffness(fes) -> sp.csr_matrix:
    """∫ ∇u·∇v assembled by NGSolve on all dofs (c = 1)."""
    u, v = fes.TnT()
    a = ngsolve.BilinearForm(fes)
    a += ngsolve.grad(u) * ngsolve.grad(v) * ngsolve.dx
    a.Assemble()
    mat = a.mat
    # CSR() returns views into NGSolve's memory, freed with the form: copy them
    data, cols, rows = (np.array(arr, copy=True) for arr in mat.CSR())
    return sp.csr_matrix((data, cols, rows), shape=(mat.height, mat.width))


def side_operator(mesh, k: int, route: str = "auto") -> SideOperator:
    """Factorize K_i once and extract its Γ Schur complement (c = 1); ``route`` as in
    :func:`gamma_factorization`."""
    fes = displacement_space(mesh, k)
    trace = gamma_trace(fes)
    free_mask = np.array(fes.FreeDofs(), dtype=bool)
    is_gamma = np.zeros(fes.ndof, dtype=bool)
    is_gamma[trace.gamma_dofs] = True
    free = np.concatenate([np.flatnonzero(free_mask & ~is_gamma), trace.gamma_dofs])
    return factorized_side(trace, free, laplace_stiffness(fes)[free][:, free].tocsc(), route)


MEMBRANES = Model("membranes", side_operator,
                  "two membranes, −c_i Δu_i = f_i, scalar P_k (the paper's Section 3)")
"""The paper's model problem through the model seam (:mod:`infsup_contact.models.contract`)."""
