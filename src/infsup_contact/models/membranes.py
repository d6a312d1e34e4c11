"""The membranes model of the paper's Section 3: −c_i Δu_i = f_i, u_i = 0 on ∂Ω_i∖Γ.

Its side operator is the Laplace stiffness K_i of continuous P_k (eq. (5.1)) with its Γ
Schur complement (:mod:`infsup_contact.la.schur`); A_i = c_i K_i, so the material
scale of side i is c_i.
"""
from __future__ import annotations

import numpy as np
import ngsolve
import scipy.sparse as sp

from ..discretization.spaces.gammas import gamma_of
from ..errors import check_prestress
from ..la.threaded import threads
from .contract import OUTWARD_NORMAL_Y, PAPER_GAMMA, Body, MaterialParam, Model, OptionalChoice
from ..discretization.segment.arc import COUPLINGS, GAMMAS, RADIUS_ALLOWED
from .contract import SideOperator, factorized_side


def displacement_space(mesh, k: int, dirichlet: str = "dir"):
    """V_{h,i}: continuous P_k, u_i = 0 on ``dirichlet`` (default ∂Ω_i∖Γ, eq. (5.1))."""
    return ngsolve.H1(mesh, order=k, dirichlet=dirichlet)


CURVED_MARGIN = 4
"""Quadrature orders beyond the numerator's degree on a curved cell (:func:`curved_bonus_intorder`)."""


def curved_bonus_intorder(mesh, k: int) -> int:
    """The ``bonus_intorder`` of ∫ ∇u·∇v on ``mesh``: 0 on an undeformed mesh (the integrand is a
    polynomial, NGSolve's default order 2k − 2 on simplices, 2k on hexahedra, is exact); on a mesh
    curved by ``SetDeformation`` (the isoparametric arc and cylinder) NGSolve keeps that order, though the
    integrand is the rational (adj J ∇φ)·(adj J ∇ψ) / det J: its numerator has degree 4(k − 1) on
    triangles, 6(k − 1) on tetrahedra and 6k per direction on hexahedra, and the geometric series of
    1 / det J about a cell's mean converges like (h/R)^n, so :data:`CURVED_MARGIN` orders more bring K
    to round-off (measured, docs/models.md; ``tests/discretization/segment/test_arc_reference.py``). The default order
    put β_h of T3 on the arc R = 2, 16:17, k = 2 2.5e-3 (relative) off."""
    if mesh.deformation is None:
        return 0
    k = int(k)
    element = next(iter(mesh.Elements(ngsolve.VOL))).type
    numerator, default = {ngsolve.ET.TRIG: (4 * (k - 1), 2 * k - 2), ngsolve.ET.TET: (6 * (k - 1), 2 * k - 2),
                          ngsolve.ET.HEX: (6 * k, 2 * k)}.get(element, (6 * k, 2 * k))
    return max(numerator - default, 0) + CURVED_MARGIN


def assemble(form) -> None:
    """``form.Assemble()``, on NGSolve's task manager with the request's threads where it has two
    or more (:func:`~infsup_contact.la.threaded.threads`; one inside a concurrent task): its
    coloured assembly gave the same matrix bit for bit (Q_2, N = 48: 1.81 → 0.94 s on two threads)."""
    n = threads()
    if n < 2:
        form.Assemble()
        return
    ngsolve.SetNumThreads(n)
    with ngsolve.TaskManager():
        form.Assemble()


def laplace_stiffness(fes, free: np.ndarray | None = None) -> sp.spmatrix:
    """∫ ∇u·∇v assembled by NGSolve on all dofs (c = 1, CSR); on a curved mesh with the quadrature
    of :func:`curved_bonus_intorder`. ``free``: K restricted to those dofs, rows and columns in
    that order (CSC, as ``K[free][:, free].tocsc()`` of the whole one, bit for bit), read from
    NGSolve's arrays without a copy of the whole K (200 MB at k = 2, N = 32)."""
    u, v = fes.TnT()
    a = ngsolve.BilinearForm(fes)
    bonus = curved_bonus_intorder(fes.mesh, fes.globalorder)
    a += ngsolve.grad(u) * ngsolve.grad(v) * ngsolve.dx(bonus_intorder=bonus)
    assemble(a)
    mat = a.mat
    if free is not None:
        # views into NGSolve's memory, alive with the form ``a`` until this returns: the row and
        # column selections copy what they keep
        data, cols, rows = mat.CSR()
        return sp.csr_matrix((data, cols, rows), shape=(mat.height, mat.width))[free][:, free].tocsc()
    # CSR() returns views into NGSolve's memory, freed with the form: copy them
    data, cols, rows = (np.array(arr, copy=True) for arr in mat.CSR())
    return sp.csr_matrix((data, cols, rows), shape=(mat.height, mat.width))


def side_operator(mesh, k: int, route: str = "auto", dirichlet: str = "dir") -> SideOperator:
    """Factorize K_i once and extract its Γ Schur complement (c = 1); ``route`` as in
    :func:`gamma_factorization`, u_i = 0 on ``dirichlet``. ``mesh``: a body of the paper's, or a
    :class:`~.contract.Body` whose Γ is an :class:`~infsup_contact.discretization.segment.arc.Arc`
    (the mesh of its square, curved here at the body's degree k); a bare mesh: the paper's, whose Γ
    is the Γ table's :data:`~.contract.PAPER_GAMMA`."""
    if isinstance(mesh, Body):
        mesh, gamma = mesh.mesh, mesh.interface
        gamma.curve(mesh, k)
    else:
        gamma = gamma_of(PAPER_GAMMA)
    fes = displacement_space(mesh, k, dirichlet)
    trace = gamma.trace(fes)
    free_mask = np.array(fes.FreeDofs(), dtype=bool)
    is_gamma = np.zeros(fes.ndof, dtype=bool)
    is_gamma[trace.gamma_dofs] = True
    free = np.concatenate([np.flatnonzero(free_mask & ~is_gamma), trace.gamma_dofs])
    return factorized_side(trace, free, laplace_stiffness(fes)[free][:, free].tocsc(), route)


def load_vector(side: SideOperator, f) -> np.ndarray:
    """F_i = ∫ f v on the free dofs of side i, in the order of ``side.free``."""
    fes = side.trace.fes
    lf = ngsolve.LinearForm(fes)
    lf += f * fes.TestFunction() * ngsolve.dx(bonus_intorder=4)
    lf.Assemble()
    return lf.vec.FV().NumPy()[side.free].copy()


def load_vector_from_exact(side: SideOperator, grad_u, c: float, normal_y: float) -> np.ndarray:
    """F_i = (f_i, v) for f_i = −c_i Δu_i, evaluated as c_i(∇u_i, ∇v) − ∫_Γ c_i ∂u_i/∂n v.

    Green's formula makes this identical to ∫ f v for every v ∈ V_h (v = 0 on ∂Ω_i∖Γ). For
    the low-regularity manufactured solutions f has an integrable singularity at x = a
    that quadrature samples badly, while ∇u is bounded: this form keeps F exact to
    quadrature accuracy. ``normal_y`` is the outward normal's y component on Γ (+1 for
    Ω1, −1 for Ω2), given explicitly rather than taken from the mesh.
    """
    fes = side.trace.fes
    v = fes.TestFunction()
    lf = ngsolve.LinearForm(fes)
    lf += c * grad_u * ngsolve.grad(v) * ngsolve.dx(bonus_intorder=6)
    lf += -c * normal_y * grad_u[1] * v * ngsolve.ds("gamma", bonus_intorder=6)
    lf.Assemble()
    return lf.vec.FV().NumPy()[side.free].copy()


def scene_side(scene, mesh, k: int) -> SideOperator:
    """The side of a contact scene: u_i prescribed on the scene's ``supports`` (one NGSolve boundary
    regexp in a tuple, the patch test's far faces ``dir`` with the lateral sides natural) where it
    has them, else on ``dir`` (the β_h side)."""
    (dirichlet,) = getattr(scene, "supports", None) or ("dir",)
    return side_operator(mesh, k, dirichlet=dirichlet)


def far_face_load(side: SideOperator, scene, i: int):
    """(F_i, u_{D,i}): the lift u_{D,i} = ``scene.far_displacement_y[i]`` on the boundary ``dir``
    (0 on every free dof), F_i = −c_i (K u_{D,i}) on the free dofs (no body force)."""
    fes = side.trace.fes
    gf = ngsolve.GridFunction(fes)
    gf.Set(float(scene.far_displacement_y[i]), definedon=fes.mesh.Boundaries("dir"))
    lift = gf.vec.FV().NumPy().copy()
    lift[np.array(fes.FreeDofs(), dtype=bool)] = 0.0  # only the supports carry the lift
    c = (scene.c1, scene.c2)[i]
    return -c * (laplace_stiffness(fes) @ lift)[side.free], lift


def load(side: SideOperator, scene, i: int):
    """(F_i, lift): from the exact solution's gradient where the scene has one (no lift), from a
    prescribed far-face displacement where it has one (:func:`far_face_load`), else ∫ f_i v."""
    if getattr(scene, "has_exact", False):
        grad, c = (scene.grad_u1, scene.grad_u2)[i], (scene.c1, scene.c2)[i]
        return load_vector_from_exact(side, grad, c, OUTWARD_NORMAL_Y[i]), None
    if hasattr(scene, "far_displacement_y"):
        return far_face_load(side, scene, i)
    return load_vector(side, (scene.f1, scene.f2)[i]), None


def field(side: SideOperator, values: np.ndarray, lift=None):
    """u_{i,h} as a GridFunction of V_{h,i}: ``values`` on the free dofs, ``lift`` (or 0) elsewhere."""
    gf = ngsolve.GridFunction(side.trace.fes)
    if lift is not None:
        gf.vec.FV().NumPy()[:] = lift
    gf.vec.FV().NumPy()[side.free] = values
    return gf


def interpolate(side: SideOperator, components) -> np.ndarray:
    """Coefficients (all dofs) of the interpolant of the scalar field ``components[0]``."""
    gf = ngsolve.GridFunction(side.trace.fes)
    gf.Set(components[0])
    return gf.vec.FV().NumPy().copy()


MEMBRANES = Model("membranes", side_operator,
                  "two membranes, −c_i Δu_i = f_i, scalar P_k (the paper's Section 3)",
                  scene_side=scene_side, load=load, field=field, interpolate=interpolate,
                  params=tuple(MaterialParam(f"c{i + 1}", 1.0, lambda v, key: check_prestress(key, v),
                                             "1e-150 <= c <= 1e150", f"prestress c{i + 1} of Ω{i + 1}", side=i)
                               for i in range(2)),
                  curving=("segment", "arc"),
                  mesh_options=(("gamma", OptionalChoice(GAMMAS)),
                                ("radius", OptionalChoice(text=RADIUS_ALLOWED + ", with --gamma arc", above=1.0)),
                                ("coupling", OptionalChoice(COUPLINGS, filled_when=("gamma", "arc")))))
"""The paper's model problem through the model seam (:mod:`infsup_contact.models.contract`)."""
