"""Serendipity HEX20 bodies for the 3D membranes: −Δu_i on Ω_i with the 20-node hexahedron.

NGSolve has no serendipity hexahedra; scikit-fem's ``ElementHexS2`` is the 20-node serendipity Q2
element (nodal values at the 8 vertices and the 12 edge midpoints; per cell P2 plus the ten
monomials of degree ≤ 2 in each variable up to x²yz, xy²z, xyz² — no face or cell centres). Its
trace on a face is QUAD8, so Γ is :data:`~infsup_contact.discretization.face.shapes.serendipity.SERENDIPITY`.

Meshes: the structured N × N × N cells of each body (:func:`subdomain_mesh`, ``MeshHex.init_tensor``),
Ω1 = (0,1)³ and Ω2 = (0,1)²×(1,2) as in :mod:`.membranes3d`. The side operator (:func:`side_operator`):
the Laplace stiffness assembled by scikit-fem (3 Gauss points per direction: the products of the
gradients have degree ≤ 4 per variable, so the rule is exact), u_i = 0 on ∂Ω_i∖Γ, the free dofs
ordered interior then Γ, and the Γ Schur complement by the shared factorization
(:func:`~.contract.factorized_side`). Only k = 2 exists.

**Contact scenes** (the model contract's ``scene_side``, ``load``, ``field``; dispatched to from
:mod:`.membranes3d`): u_i prescribed on the far face only (z = 0 of Ω1, z = 2 of Ω2: the face patch
test, :mod:`infsup_contact.study.patch.face`) or on all of ∂Ω_i∖Γ (:func:`scene_side`), the
lift a constant on the far face (:func:`load`; the serendipity basis is nodal and sums to 1, so
nodal values equal to the constant are the constant), and u_h a :class:`Hex20Field`: all nodal
values and the scikit-fem basis, evaluated at points by ``Basis.probes`` (a point evaluation, as
NGSolve's GridFunction at mesh points). A scene's exact u is compared at points
(``exact_values``): there is no interpolant of NGSolve coefficient functions on these bodies.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..discretization.face.shapes.serendipity import SERENDIPITY, NodalDofs
from ..errors import InputError
from .contract import Body, SideOperator, extended, factorized_side, mirrored_side

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


def far_facets(body: Body) -> np.ndarray:
    """The boundary facets of the body's far face: the plane z = const farthest from Γ (z = 0 of
    Ω1, z = 2 of Ω2), found by the facets' midpoints."""
    mesh, z = body.mesh, body.interface.z
    far = max(mesh.p[2].min(), mesh.p[2].max(), key=lambda c: abs(c - z))
    return mesh.facets_satisfying(lambda p: np.abs(p[2] - far) < 1e-12, boundaries_only=True)


def displacement_space(body: Body, lateral: bool = True):
    """(scikit-fem ``CellBasis`` of ``ElementHexS2``, :class:`NodalDofs`): the dofs on the far face
    and, with ``lateral``, on the four lateral faces (so all of ∂Ω_i∖Γ: every boundary facet off the
    plane of Γ) are not free."""
    from skfem import Basis, ElementHexS2

    mesh = body.mesh
    basis = Basis(mesh, ElementHexS2(), intorder=GAUSS_ORDER)
    z = body.interface.z
    fixed = (mesh.facets_satisfying(lambda p: np.abs(p[2] - z) > 1e-12, boundaries_only=True) if lateral
             else far_facets(body))
    free = np.ones(basis.N, dtype=bool)
    free[basis.get_dofs(facets=fixed).all()] = False
    return basis, NodalDofs(np.asarray(basis.doflocs, float).T, free, np.asarray(mesh.p, float).T, basis)


def stiffness(basis):
    """K = ∫ ∇u·∇v of the basis (CSR, all dofs)."""
    from skfem import asm
    from skfem.models.poisson import laplace

    return asm(laplace, basis).tocsr()


@dataclass(frozen=True)
class Hex20Side(SideOperator):
    """A HEX20 :class:`SideOperator` plus what a contact scene needs: K_i on every dof
    (``stiffness_all``, the loads of a Dirichlet lift) and the far face's dofs (``far``, bool
    over all dofs)."""

    stiffness_all: sp.csr_matrix | None = None
    far: np.ndarray | None = None


def side_operator(body: Body, k: int, route: str = "auto", keep_factor: bool = False,
                  lateral: bool = True, mirror_of=None) -> Hex20Side:
    """The Laplace stiffness of HEX20 on ``body`` factorized once, Γ dofs last (c = 1), u = 0 on
    the far face and, with ``lateral`` (β_h), on the lateral faces; without, those are natural and
    the Γ dofs on ∂Γ free. The nodes are the dofs' signature (:mod:`.body_symmetry`): the body's
    reflections factorize it in parity parts, ``mirror_of`` (side 1 of a matching pair) lends its
    factorization through the mirror (:func:`~.contract.mirrored_side`), both checked on K."""
    check_k(k)
    basis, dofs = displacement_space(body, lateral)
    trace = body.interface.trace(dofs)
    is_gamma = np.zeros(dofs.ndof, dtype=bool)
    is_gamma[trace.gamma_dofs] = True
    free = np.concatenate([np.flatnonzero(dofs.free & ~is_gamma), trace.gamma_dofs])
    K = stiffness(basis)
    K_free = K[free][:, free].tocsc()
    signature = np.column_stack([np.asarray(basis.doflocs, float).T, np.ones(basis.N)])[free]
    base = (factorized_side(trace, free, K_free, route, keep_factor, signature) if mirror_of is None else
            mirrored_side(mirror_of, trace, free, K_free, signature, route, keep_factor))
    far = np.zeros(dofs.ndof, dtype=bool)
    far[basis.get_dofs(facets=far_facets(body)).all()] = True
    return extended(base, Hex20Side, stiffness_all=K, far=far)


def scene_side(body: Body, k: int, lateral: bool) -> Hex20Side:
    """The side of a contact scene: u prescribed on the far face (and the lateral faces with
    ``lateral``), factorized to solve (``keep_factor``)."""
    return side_operator(body, k, keep_factor=True, lateral=lateral)


def load(side: Hex20Side, far_value: float, c: float) -> tuple:
    """(F_i, u_{D,i}): the lift ``far_value`` on the far face's dofs (0 on the other fixed dofs),
    F_i = −c (K_i u_{D,i}) on the free dofs (no body force)."""
    lift = np.where(side.far, float(far_value), 0.0)
    lift[side.free] = 0.0  # only the supports carry the lift
    return -c * (side.stiffness_all @ lift)[side.free], lift


@dataclass(frozen=True)
class Hex20Field:
    """u_{i,h} on a HEX20 body: every nodal value and the scikit-fem basis.

    Attributes
    ----------
    values : ndarray
        Nodal values on all dofs (lift included).
    basis : skfem.CellBasis
        The ``ElementHexS2`` basis of the body.
    """

    values: np.ndarray
    basis: object

    def __call__(self, points) -> np.ndarray:
        """u_h at ``points`` (n, 3) of the body (point evaluation, ``Basis.probes``; its cell search
        is quadratic in the number of points and cells: for a few points)."""
        return self.basis.probes(np.asarray(points, float).reshape(-1, 3).T) @ self.values

    def samples(self, per_cell: int) -> tuple:
        """(points (n, 3), u_h there): ``per_cell`` + 1 points per direction in every cell, faces and
        edges included (the reference cube's tensor grid mapped to each hexahedron; shared points
        repeat), by ``Basis.interpolate`` at those reference points (no cell search)."""
        from skfem import Basis

        t = np.linspace(0.0, 1.0, per_cell + 1)
        ref = np.stack(np.meshgrid(t, t, t, indexing="ij")).reshape(3, -1)
        at = Basis(self.basis.mesh, self.basis.elem, quadrature=(ref, np.ones(ref.shape[1])))
        points = np.asarray(at.global_coordinates()).reshape(3, -1).T
        return points, np.asarray(at.interpolate(self.values)).ravel()


def field(side: Hex20Side, values: np.ndarray, lift=None) -> Hex20Field:
    """u_{i,h} from its free-dof values and the lift (or 0) elsewhere."""
    basis = side.trace.fes.basis
    out = np.zeros(basis.N) if lift is None else np.array(lift, dtype=float)
    out[side.free] = values
    return Hex20Field(out, basis)


def is_hex20_side(side) -> bool:
    """Whether ``side`` was built on a HEX20 body."""
    return isinstance(side, Hex20Side)
