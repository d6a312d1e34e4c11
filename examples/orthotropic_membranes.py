"""A model the suite does not ship: orthotropic membranes, −div(K ∇u_i) = f_i with K = diag(1, 4).

A new model is this file plus one entry of the config's model table (docs/models.md)::

    studies:
      orthotropic: {study: beta, model: examples/orthotropic_membranes.py:MODEL, k: [1, 2],
                    N: [8, 12, 16], cases: [T3, R5.2, T4, R5.4, T5], norms: [H, L2]}

K is symmetric positive definite, so a(·,·) is equivalent to the membranes' energy and the
paper's verdicts are predicted to carry over; b(v, μ) only sees the traces, so the kernel of
B A⁻¹ Bᵀ is the membranes' one on every mesh pair.
"""
import numpy as np
import ngsolve
import scipy.sparse as sp

from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.models.contract import Model, factorized_side

STIFFNESS_Y = 4.0
"""K = diag(1, STIFFNESS_Y): stiffer across Γ than along it."""


def side_operator(mesh, k: int):
    """K_i of continuous P_k (u_i = 0 on ∂Ω_i∖Γ), factorized with Γ's dofs last."""
    fes = ngsolve.H1(mesh, order=k, dirichlet="dir")
    u, v = fes.TnT()
    form = ngsolve.BilinearForm(fes)
    form += (ngsolve.grad(u)[0] * ngsolve.grad(v)[0] + STIFFNESS_Y * ngsolve.grad(u)[1] * ngsolve.grad(v)[1]) * ngsolve.dx
    form.Assemble()
    data, cols, rows = (np.array(a, copy=True) for a in form.mat.CSR())
    stiffness = sp.csr_matrix((data, cols, rows), shape=(fes.ndof, fes.ndof))
    trace = SEGMENT.trace(fes)
    is_gamma = np.zeros(fes.ndof, dtype=bool)
    is_gamma[trace.gamma_dofs] = True
    free = np.concatenate([np.flatnonzero(np.array(fes.FreeDofs(), dtype=bool) & ~is_gamma), trace.gamma_dofs])
    return factorized_side(trace, free, stiffness[free][:, free].tocsc())


MODEL = Model("orthotropic", side_operator, "orthotropic membranes, K = diag(1, 4)")
