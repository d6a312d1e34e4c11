"""The model seam: what a physical model must give the Γ-reduced engine.

β_h (:mod:`infsup_contact.solvers.infsup`), the contact solver
(:mod:`infsup_contact.solvers.contact`), the ledger and the paper take a :class:`Model` and
never ask which one it is. A model is one function, ``side_operator(mesh, k)``, applied to
each mesh of a pair; the :class:`~infsup_contact.models.schur.SideOperator` it returns carries

* ``trace`` — the Γ trace of the side's displacement space: its partition of Γ
  (``trace.breakpoints``), its Γ dofs (``trace.gamma_dofs``, the components b(v, μ) sees:
  for a scalar membrane v itself, for an elastic body v·n) and the NGSolve space, from which
  :func:`~infsup_contact.discretization.coupling.coupling_matrix` builds B_i;
* ``steklov_times(M)`` — X_i M with X_i = (A_i⁻¹)_ΓΓ at unit material scale: the interface
  operator Σ_i B_i X_i B_iᵀ / c_i is assembled from it for every multiplier space and norm;
* ``solve``, ``free``, ``stiffness`` — the factorization and the free dofs (Γ last) with
  which the contact solver recovers u_h = A_i⁻¹ (F_i ∓ B_iᵀ λ_h).

The material enters only as the scale c_i of each side (A_i = c_i K_i), so one side
operator per (mesh, k) serves every material pair; data that changes K_i itself (an
elastic body's ν) belongs to the model instance.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Model:
    """A physical model as the engine sees it.

    Attributes
    ----------
    name : str
        Identifier used on the command line and in tables.
    side_operator : callable
        ``side_operator(mesh, k) -> SideOperator``: one body, factorized once, Γ dofs last,
        unit material scale.
    description : str
        One line for ``--help`` and the paper.
    """

    name: str
    side_operator: Callable
    description: str = ""
