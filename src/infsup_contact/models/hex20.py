"""Serendipity HEX20 bodies for the 3D membranes: −Δu_i on Ω_i with the 20-node hexahedron.

NGSolve has no serendipity hexahedra; scikit-fem's ``ElementHexS2`` is the 20-node serendipity Q2
element (nodal values at the 8 vertices and the 12 edge midpoints; per cell P2 plus the ten
monomials of degree ≤ 2 in each variable up to x²yz, xy²z, xyz² — no face or cell centres). Its
trace on a face is QUAD8, so Γ is :data:`~infsup_contact.discretization.face.serendipity.SERENDIPITY`.

Meshes: the structured N × N × N cells of each body (:func:`subdomain_mesh`, ``MeshHex.init_tensor``),
Ω1 = (0,1)³ and Ω2 = (0,1)²×(1,2) as in :mod:`.membranes3d`. The side operator (:func:`side_operator`):
the Laplace stiffness assembled by scikit-fem (3 Gauss points per direction: the products of the
gradients have degree ≤ 4 per variable, so the rule is exact), u_i = 0 on ∂Ω_i∖Γ, the free dofs
ordered interior then Γ, and the Γ Schur complement by the shared factorization
(:func:`~.contract.factorized_side`). Only k = 2 exists. β_h only: contact scenes need NGSolve fields.
"""
from __future__ import annotations

import numpy as np

from ..discretization.face.serendipity import SERENDIPITY, NodalDofs
from ..errors import InputError
from .contract import Body, SideOperator, factorized_side

GAUSS_ORDER = 4
"""scikit-fem's ``intorder`` of the stiffness: 3 Gauss points per direction, exact to degree 5 per variable."""


def subdomain_mesh(n: int, side: int) -> Body:
    """The structured mesh of Ω_side, n × n × n hexahedra (scikit-fem ``MeshHex``), with Γ :data:`SERENDIPITY`."""
    from skfem import MeshHex

    t = np.linspace(0.0, 1.0, int(n) + 1)
    return Body(MeshHex.init_tensor(t, t, t + (side - 1)), SERENDIPITY)


def is_hex20(body: Body) -> bool:
    """Whether ``body`` is a HEX20 body (its Γ is the QUAD8 face)."""
    return body.interface is SERENDIPITY


def check_k(k: int) -> None:
    """:class:`InputError` naming ``k`` unless k = 2 (the serendipity element is quadratic)."""
    if k != 2:
        raise InputError("k", "2 (the serendipity HEX20 element is quadratic)", got=k)


def displacement_space(body: Body):
    """(scikit-fem ``CellBasis`` of ``ElementHexS2``, :class:`NodalDofs`): the dofs vanishing on
    ∂Ω_i∖Γ (every boundary facet off the plane z = 1) are not free."""
    from skfem import Basis, ElementHexS2

    mesh = body.mesh
    basis = Basis(mesh, ElementHexS2(), intorder=GAUSS_ORDER)
    z = body.interface.z
    off_gamma = mesh.facets_satisfying(lambda p: np.abs(p[2] - z) > 1e-12, boundaries_only=True)
    free = np.ones(basis.N, dtype=bool)
    free[basis.get_dofs(facets=off_gamma).all()] = False
    return basis, NodalDofs(np.asarray(basis.doflocs, float).T, free, np.asarray(mesh.p, float).T, basis)


def stiffness(basis):
    """K = ∫ ∇u·∇v of the basis (CSR, all dofs)."""
    from skfem import asm
    from skfem.models.poisson import laplace

    return asm(laplace, basis).tocsr()


def side_operator(body: Body, k: int, route: str = "auto", keep_factor: bool = False) -> SideOperator:
    """The Laplace stiffness of HEX20 on ``body`` factorized once, Γ dofs last (c = 1), u = 0 on ∂Ω_i∖Γ."""
    check_k(k)
    basis, dofs = displacement_space(body)
    trace = body.interface.trace(dofs)
    is_gamma = np.zeros(dofs.ndof, dtype=bool)
    is_gamma[trace.gamma_dofs] = True
    free = np.concatenate([np.flatnonzero(dofs.free & ~is_gamma), trace.gamma_dofs])
    K = stiffness(basis)
    return factorized_side(trace, free, K[free][:, free].tocsc(), route, keep_factor)
