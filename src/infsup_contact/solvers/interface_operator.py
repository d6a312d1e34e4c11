"""The interface operator B A⁻¹ Bᵀ = Σ_i B_i X_i B_iᵀ / c_i on a multiplier space (paper, Section 4).

Because b(v, μ) touches only Γ dofs, the operator behind (4.5) is a sum over the sides of
B_i (A_i⁻¹)_ΓΓ B_iᵀ, with X_i = (A_i⁻¹)_ΓΓ the Steklov inverse of a side operator
(:class:`~infsup_contact.models.contract.SideOperator`, its Schur complement from
:mod:`infsup_contact.la.schur`). A model assembles its stiffness at unit material scale
(A_i = c_i K_i), so the terms B_i X_i B_iᵀ serve every (c1, c2).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..la.parity_sandwich import ParityOperator, combine, parity_sandwich
from ..la.threaded import concurrent_map, symmetric_part


SPARSE_PRODUCT_MIN_DIM = 300
"""dim M above which :func:`interface_terms` multiplies by B as a sparse matrix on both sides
(B has (k + 1)^d (s + 1)^d-sized blocks: at dim M ≈ 4,000 on a face the dense products are 1e11
flops) with the explicit X = S⁻¹ of the side (:meth:`~infsup_contact.la.schur.SteklovProduct.steklov_sandwich`,
potri once per side); below it the dense products with the solves. At k = 2, N = 16 on the face
(dim M ≈ 1,000, n_Γ = 961) the solves cost 0.2 CPU-s a space, the sparse products 0.03-0.08 (the
potri once, 0.1); below 300 (every segment space of the default DAG, up to N = 64 at k = 4, and the
face's at N = 6) both are milliseconds and the rows keep their bits."""


def interface_terms(couplings, sides, split=None) -> list:
    """The terms B_i X_i B_iᵀ of the interface operator at unit material scale, one per side.

    Above :data:`SPARSE_PRODUCT_MIN_DIM` by a side's ``steklov_sandwich`` where it has one (the
    same matrix to round-off: X from potri instead of the triangular solves), else
    ``B (X Bᵀ)`` by its ``steklov_times``. ``split``: the space's reflections
    (:class:`~infsup_contact.la.reflection.ReflectionSplit`, its route's); where every side
    knows X in its parity blocks (``steklov_parts``) the terms are computed in the split's
    components only (:func:`~infsup_contact.la.parity_sandwich.parity_sandwich`:
    :class:`~infsup_contact.la.parity_sandwich.ParityOperator` terms, their dropped part bounded),
    else, or where a bound is too large, whole."""
    blocked = _parity_terms(couplings, sides, split)
    if blocked is not None:
        return blocked
    out = []
    for B, side in zip(couplings, sides):
        large = B.shape[0] > SPARSE_PRODUCT_MIN_DIM
        if large and hasattr(side, "steklov_sandwich"):
            out.append(side.steklov_sandwich(sp.csr_matrix(B)))
            continue
        Bl = sp.csr_matrix(B) if large else B
        Bd = B.toarray() if sp.issparse(B) else B  # steklov_times solves with a dense right-hand side
        out.append(np.asarray(Bl @ side.steklov_times(Bd.T)))
    return out


def _parity_terms(couplings, sides, split) -> list | None:
    """The terms in the components of ``split`` (:func:`interface_terms`), or None."""
    if split is None or couplings[0].shape[0] <= SPARSE_PRODUCT_MIN_DIM:
        return None
    parts = [getattr(side, "steklov_parts", None) for side in sides]
    if any(p is None for p in parts):
        return None
    # the sides' terms side by side (sparse products and the sandwiches' row blocks, GIL-free;
    # each term the same operations as alone, on one thread: the same bits)
    out = concurrent_map(lambda Bp: parity_sandwich(Bp[0], Bp[1], split.bases), list(zip(couplings, parts)))
    return None if any(term is None for term in out) else out


def combine_terms(terms, c) -> np.ndarray:
    """Σ_i T_i / c_i, symmetrized: the interface operator for the material scales c (the
    symmetrisation over the threads, :func:`~infsup_contact.la.threaded.symmetric_part`);
    terms in parity blocks stay in them (:func:`~infsup_contact.la.parity_sandwich.combine`)."""
    if isinstance(terms[0], ParityOperator):
        return combine(terms, c)
    out = 0.0
    for T, ci in zip(terms, c):
        out = out + T / ci
    return symmetric_part(out)


def interface_operator(couplings, sides, c=(1.0, 1.0)) -> np.ndarray:
    """Σ_i B_i X_i B_iᵀ / c_i = B A⁻¹ Bᵀ on the multiplier space (dense, symmetric PSD).

    Its terms do not depend on c: a sweep over (c1, c2) computes them once
    (:func:`interface_terms`) and combines them per pair (:func:`combine_terms`)."""
    return combine_terms(interface_terms(couplings, sides), c)
