"""Stokes saddle-point systems assembled by scikit-fem: a producer this suite did not write.

Velocity in H¹₀((0,1)²)² with the H¹ seminorm (A = vector Laplacian, Dirichlet dofs removed
by scikit-fem's own ``get_dofs``/``complement_dofs``), pressure in L² (G = the pressure mass),
B = −div. The constant pressure is in the kernel of Bᵀ on every pair (an enclosed flow:
∫ div v = 0); the manifest declares it (``known_kernel: 1``), as a user of an enclosed
Stokes flow would.
"""
from __future__ import annotations

import numpy as np

PAIRS = {
    # pair: (velocity element, pressure element, mesh kind, textbook verdict (Boffi–Brezzi–Fortin))
    "P2-P1": ("ElementTriP2", "ElementTriP1", "tri", "stable"),     # Taylor–Hood
    "MINI": ("ElementTriMini", "ElementTriP1", "tri", "stable"),    # P1+bubble / P1
    "P2-P0": ("ElementTriP2", "ElementTriP0", "tri", "stable"),
    "P1-P1": ("ElementTriP1", "ElementTriP1", "tri", "unstable"),
    "Q1-P0": ("ElementQuad1", "ElementQuad0", "quad", "unstable"),  # checkerboard
}


def stokes_system(pair: str, n: int):
    """(A, B, G) of ``pair`` on the structured n × n mesh of the unit square."""
    import skfem
    from skfem.helpers import div, dot, grad, ddot

    ev, ep, kind, _ = PAIRS[pair]
    x = np.linspace(0.0, 1.0, n + 1)
    mesh = (skfem.MeshTri if kind == "tri" else skfem.MeshQuad).init_tensor(x, x)
    ub = skfem.Basis(mesh, skfem.ElementVector(getattr(skfem, ev)()), intorder=4)
    pb = skfem.Basis(mesh, getattr(skfem, ep)(), intorder=4)

    @skfem.BilinearForm
    def laplace(u, v, w):
        return ddot(grad(u), grad(v))

    @skfem.BilinearForm
    def divergence(u, q, w):
        return -div(u) * q

    @skfem.BilinearForm
    def mass(p, q, w):
        return p * q

    A = laplace.assemble(ub)
    B = divergence.assemble(ub, pb)
    G = mass.assemble(pb)
    interior = ub.complement_dofs(ub.get_dofs())
    return A[interior][:, interior].tocsr(), B[:, interior].tocsr(), G.tocsr()
