"""What exported matrices really look like, found before any number is computed.

Each finding is one line naming the file: a :class:`~.readers.SystemFileError` where the
number would be wrong (refused), or a note (printed on stderr, kept in the row) where the
system is repaired in a way that does not change β_h:

=====================================  =========================================================
finding                                action
=====================================  =========================================================
NaN or inf in a matrix                 refused (count, first position)
shapes that do not fit (A n×n, B m×n,  refused, naming both files and their shapes
G m×m)
declared constrained dofs              removed from A and B; refused if B has entries on them
                                       (b(v, μ) on a fixed dof has no meaning: export B
                                       without them)
huge diagonal penalties ("tgv",        ``tgv: eliminate`` (default): the dofs are removed —
|a_ii| ≥ 1e15 × median |a_jj|)         the penalty's own limit, v = 0 there — and B's entries
                                       on them dropped, with a note; ``tgv: refuse``: refused
undeclared identity rows (a dof with   removed with a note when B does not touch them (they
no coupling in A)                      cannot change B A⁻¹ Bᵀ); refused when B does and the
                                       diagonal is exactly 1 (a constrained dof left as an
                                       identity row); kept with a note otherwise (element
                                       bubbles, e.g. MINI, are coupled to nothing in A)
A not symmetric                        refused: the largest |a_ij − a_ji| and where
A not positive definite                refused; a floating body (zero pivots) gets the number
                                       of zero pivots and ‖A x‖ of a null vector x
zero rows in G, G not SPD              refused
a finer level with fewer dofs          refused (files swapped?)
=====================================  =========================================================
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..models import pardiso
from .readers import SystemFileError

TGV_RATIO = 1e15
"""A diagonal entry this many times the median |diagonal| is a Dirichlet penalty."""
SYMMETRY_RTOL = 1e-10
"""A is symmetric when max |a_ij − a_ji| ≤ SYMMETRY_RTOL · max |a_ij|."""
PIVOT_RTOL = 1e-12
"""A pivot below PIVOT_RTOL · max pivot is zero (a singular A: a floating body)."""
PARDISO_CHECK_MIN = 2000
"""Rows from which :func:`check_positive_definite` asks PARDISO's inertia first."""


@dataclass
class CheckedLevel:
    """The matrices of one level after the checks, and what was found."""

    A: sp.csc_matrix
    B: sp.csr_matrix
    G: object
    notes: list = field(default_factory=list)
    removed: int = 0


def check_finite(mat, path) -> None:
    data = mat.data if sp.issparse(mat) else np.asarray(mat)
    bad = ~np.isfinite(data)
    if bad.any():
        if sp.issparse(mat):
            coo = sp.coo_matrix(mat)
            i = int(np.flatnonzero(~np.isfinite(coo.data))[0])
            pos = (int(coo.row[i]), int(coo.col[i]))
        else:
            pos = tuple(int(v) for v in np.argwhere(bad)[0])
        raise SystemFileError(path, f"{int(bad.sum())} NaN/inf entries (first at row {pos[0]}, column {pos[1]}, 0-based)")


def check_shapes(level, A, B, G) -> None:
    if A.shape[0] != A.shape[1]:
        raise SystemFileError(level.A, f"A is {A.shape[0]} x {A.shape[1]}, not square")
    if G.shape[0] != G.shape[1]:
        raise SystemFileError(level.G, f"G is {G.shape[0]} x {G.shape[1]}, not square")
    if B.shape != (G.shape[0], A.shape[0]):
        raise SystemFileError(level.B, f"B is {B.shape[0]} x {B.shape[1]}, but A ({level.A.name}) is "
                              f"{A.shape[0]} x {A.shape[0]} and G ({level.G.name}) is {G.shape[0]} x {G.shape[0]}: "
                              f"expected {G.shape[0]} x {A.shape[0]} (m x n)")


def _remove(A, B, dofs):
    keep = np.setdiff1d(np.arange(A.shape[0]), dofs)
    return A[keep][:, keep], B[:, keep]


def _b_entries_on(B, dofs) -> int:
    """Non-zero entries of B in the columns ``dofs`` (sparse: no dense m × len(dofs) block)."""
    if not len(dofs):
        return 0
    block = sp.csc_matrix(B)[:, dofs]
    block.eliminate_zeros()
    return int(block.nnz)


def check_level(level, A, B, G, constrained=np.zeros(0, int), tgv: str = "eliminate") -> CheckedLevel:
    """Run every check on one level (module docstring); the matrices as read."""
    for mat, path in ((A, level.A), (B, level.B), (G, level.G)):
        check_finite(mat, path)
    check_shapes(level, A, B, G)
    A, B = sp.csr_matrix(A), sp.csr_matrix(B)
    A.eliminate_zeros()
    B.eliminate_zeros()
    notes, removed = [], 0
    if len(constrained):
        on = _b_entries_on(B, constrained)
        if on:
            raise SystemFileError(level.B, f"B has {on} entries on the {len(constrained)} constrained dofs of "
                                  f"levels[{level.index}] (b(v, mu) on a fixed dof has no meaning): export B "
                                  "without those columns, or do not declare them constrained")
        A, B = _remove(A, B, constrained)
        removed += len(constrained)
        notes.append(f"{level.A.name}: {len(constrained)} declared constrained dofs removed")
    diag = np.abs(A.diagonal())
    if np.any(diag > 0):
        med = float(np.median(diag[diag > 0]))
        tgv_dofs = np.flatnonzero(diag >= TGV_RATIO * med)
        if len(tgv_dofs):
            where = f"{len(tgv_dofs)} Dirichlet penalty rows (diagonal up to {diag.max():.3g} vs median {med:.3g})"
            if tgv == "refuse":
                raise SystemFileError(level.A, f"{where}; tgv: refuse (set tgv: eliminate, or export without them)")
            on = _b_entries_on(B, tgv_dofs)
            A, B = _remove(A, B, tgv_dofs)
            removed += len(tgv_dofs)
            notes.append(f"{level.A.name}: {where} eliminated (v = 0 there, the penalty's limit)"
                         + (f"; B's {on} entries on them dropped" if on else ""))
    off = A - sp.diags(A.diagonal())
    off.eliminate_zeros()
    lonely = np.flatnonzero((np.diff(off.tocsr().indptr) == 0) & (np.diff(off.tocsc().indptr) == 0))
    if len(lonely) and A.shape[0] > 1:
        touched = np.diff(sp.csc_matrix(B)[:, lonely].indptr) > 0
        unit = lonely[touched & (A.diagonal()[lonely] == 1.0)]
        if len(unit):
            raise SystemFileError(level.A, f"{len(unit)} identity rows (diagonal exactly 1, coupled to nothing in A: "
                                  f"constrained dofs left in A?) on which B ({level.B.name}) has entries: "
                                  "B A^-1 B^T would count them; declare them under 'constrained' and export B "
                                  "without those columns")
        if touched.any():
            notes.append(f"{level.A.name}: {int(touched.sum())} dofs coupled to nothing in A but touched by B "
                         "(element bubbles?) kept")
        free = lonely[~touched]
        if len(free):
            A, B = _remove(A, B, free)
            removed += len(free)
            notes.append(f"{level.A.name}: {len(free)} identity rows (uncoupled dofs B does not touch) removed")
    check_symmetric(A, level.A, "A")
    G = check_gram(G, level.G)
    check_positive_definite(A, level.A)
    return CheckedLevel(sp.csc_matrix(A), sp.csr_matrix(B), G, notes, removed)


def check_symmetric(M, path, what: str) -> None:
    M = sp.csr_matrix(M)
    D = abs(M - M.T).tocoo()
    big = float(abs(M).max()) if M.nnz else 0.0
    if D.nnz and D.data.max() > SYMMETRY_RTOL * big:
        i = int(np.argmax(D.data))
        raise SystemFileError(path, f"{what} is not symmetric: |a_ij - a_ji| = {D.data[i]:.3g} at ({D.row[i]}, "
                              f"{D.col[i]}) vs max |a_ij| = {big:.3g} (Dirichlet rows replaced without their columns?)")


def check_gram(G, path):
    """G: no zero rows, symmetric, positive definite; returned sparse if it was, else dense."""
    Gs = sp.csr_matrix(G)
    Gs.eliminate_zeros()
    zero = np.flatnonzero(np.diff(Gs.indptr) == 0)
    if len(zero):
        raise SystemFileError(path, f"G has {len(zero)} zero rows (first: row {zero[0]}, 0-based): a multiplier "
                              "with norm 0 (a dof outside the multiplier space?)")
    check_symmetric(Gs, path, "G")
    check_positive_definite(Gs, path, what="G")
    return Gs if sp.issparse(G) else np.asarray(G, float)


def check_positive_definite(A, path, what: str = "A"):
    """Refuse a singular or indefinite symmetric matrix. LDLᵀ without pivoting (SuperLU, symmetric
    mode): for a symmetric matrix the pivots' signs are its inertia (Sylvester), so all pivots
    > PIVOT_RTOL · max is positive definite. Returns the factorization (None where PARDISO
    certified it: from :data:`PARDISO_CHECK_MIN` rows, its Bunch–Kaufman LDLᵀ with n positive
    pivots, none negative and none perturbed below 1e-8 ‖A‖ is accepted at once; anything else
    goes to SuperLU, whose diagnosis names the failure. On a 3D export, membranes3d k = 2, N = 20,
    121,680 rows, SuperLU's LDLᵀ took 113 s)."""
    A = sp.csc_matrix(A)
    n = A.shape[0]
    if n >= PARDISO_CHECK_MIN and pardiso.available():
        try:  # a clean inertia certifies it at once; any doubt goes to the diagnosis below
            if pardiso.inertia(A) == (n, 0, 0):
                return None
        except pardiso.PardisoError:
            pass
    try:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
        piv = lu.U.diagonal()
        top = float(np.max(np.abs(piv)))
        zero = int(np.sum(np.abs(piv) <= PIVOT_RTOL * top))
    except RuntimeError:  # exactly singular: SuperLU stops at the first zero pivot
        lu, piv, top, zero = None, np.ones(n), float(abs(A).max()), -1
    neg = int(np.sum(piv < -PIVOT_RTOL * top))
    if zero:
        shift = 1e-10 * top
        x = np.random.default_rng(0).standard_normal(n)
        shifted = spla.splu(A + shift * sp.identity(n, format="csc"), permc_spec="MMD_AT_PLUS_A",
                            diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
        if zero < 0:  # count the pivots of A + δI at the level of δ: the null space's dimension
            zero = int(np.sum(np.abs(shifted.U.diagonal()) <= 1e4 * shift))
        for _ in range(3):  # inverse iteration: the null vector
            x = shifted.solve(x)
            x /= np.linalg.norm(x)
        size = float(np.linalg.norm(A @ x)) / max(float(abs(A).max()), 1e-300)
        raise SystemFileError(path, f"{what} is singular: {zero} zero pivots of {n} (a floating body: rigid "
                              f"motions not fixed?); a null vector x has |{what} x| / (max|a_ij| |x|) = {size:.1e}; "
                              "fix the rigid motions (Dirichlet conditions or springs) before export")
    if neg:
        raise SystemFileError(path, f"{what} is not positive definite: {neg} negative pivots of {n} "
                              "(an indefinite block: the whole saddle-point matrix exported as A?)")
    return lu


def check_sequence(manifest, shapes) -> None:
    """Levels coarse to fine: a finer level must not have fewer dofs or multipliers."""
    for i in range(1, len(shapes)):
        (n0, m0), (n1, m1) = shapes[i - 1], shapes[i]
        if n1 < n0 or m1 < m0:
            lv = manifest.levels[i]
            raise SystemFileError(lv.A, f"levels[{i}] (h = {lv.h:g}) has n = {n1}, m = {m1} but the coarser "
                                  f"levels[{i - 1}] has n = {n0}, m = {m0}: mismatched levels (files swapped?)")
