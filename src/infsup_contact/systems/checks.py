"""What exported matrices really look like, found before any number is computed.

Each finding is one line naming the file: a :class:`~.readers.SystemFileError` where the
number would be wrong (refused), or a note (printed on stderr, kept in the row) where the
system is repaired in a way that does not change β_h.

**Constrained rows: one rule for A, B and G.** A dof the producer fixed is removed where the
removal cannot change β_h, and refused, naming the file and the rows, where it could:

=====================================  =========================================================
constrained row                        action
=====================================  =========================================================
displacement dof declared              removed with B's entries over it (v = 0 there, so
(``constrained``), a penalty row of A  b(v, μ) never sees them: dropping them is exact, however
(|a_ii| >= 1e15 × median, "tgv"), or   the dof was marked); a note counts the dofs and the
a unit row of A (coupled to nothing,   entries. ``tgv: refuse`` refuses the penalty rows. A
a_ii exactly 1)                        unit row is told by A's *coupled* rows: a coarse mesh's
                                       Dirichlet rows are most of A (26 of 50, k = 1, N = 4)
a dof coupled to nothing in A, not     removed (it cannot change B A⁻¹ Bᵀ)
touched by B, diagonal not 1
a dof coupled to nothing in A, touched refused, naming the rows and ``constrained``: an
by B, diagonal not 1, B an interface   element bubble has no trace on Γ, so it is a fixed dof
(the manifest's ``gamma``, or B        left unmarked, and eliminating it unmarked could change
touching <= 1/2 of the dofs), A not    β_h (with diagonal 1 it is the unit row above)
diagonal; the same, B over the body    kept with a note (element bubbles, e.g. MINI, are
(Stokes), or with diagonal 1 where     coupled to nothing in A); with a unit diagonal on the
A's coupled rows have diagonal 1       coupled rows (Jacobi-scaled) a unit row is not told apart
multiplier row: B's row zero as given  removed with a note (the boundary condition on the
and G's row decoupled and singled out  multiplier space FE codes use to make μ vanish at Γ's
(a unit row in a G that couples other  ends: μ_i is G-orthogonal to the rest, so removing it
rows, or whose diagonal is not 1)      leaves the pencil of the constrained space)
multiplier row: a penalty row of G     removed with B's row (the penalty's limit: the pencil
(g_ii >= 1e15 × median)                tends to that of μ_i = 0, plus one spurious zero mode);
                                       ``tgv: refuse`` refuses it
multiplier row: B's row zero, G's row  refused, naming both files and the rows: an incomplete
coupled to others but its diagonal 1   constraint (the unit diagonal set, the row and column
(G's diagonal elsewhere not 1)         left), where removing the row changes β_h and keeping it
                                       counts a kernel the producer meant to remove
multiplier row: B's row zero, G's row  kept: a kernel of Bᵀ (UNSTABLE unless declared), with a
coupled to others (diagonal not 1), or note. No constraint pattern: removing it would change β_h
decoupled in a diagonal G with the     (a P1–P1 pressure at a corner whose velocities are all
same diagonal there                    fixed is such a mode, not a constraint)
multiplier row: B's and G's rows zero  removed with a note (a multiplier in neither)
B's row zero only after the dofs it    kept: a kernel of Bᵀ (the multiplier couples only to fixed
touched were removed                   dofs), with a note
=====================================  =========================================================

**Everything else:**

=====================================  =========================================================
finding                                action
=====================================  =========================================================
NaN or inf in a matrix                 refused (count, first position)
shapes that do not fit (A n×n, B m×n,  refused, naming both files and their shapes
G m×m)
A not symmetric                        refused: the largest |a_ij − a_ji| and where
A not positive definite                refused; a floating body (zero pivots) gets the number
                                       of zero pivots and ‖A x‖ of a null vector x
zero rows in G (B's row not zero),     refused
G not SPD
a finer level with fewer dofs          refused (files swapped?)
=====================================  =========================================================
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..la import pardiso
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
    removed_multipliers: int = 0
    kept_multipliers: np.ndarray | None = None  # the rows of B as read that B here holds, in order
    C: object = None  # the stabilisation, restricted to those rows (module .stabilised)


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


TINY_COUPLING = 1e-12
"""An off-diagonal |g_ij| <= TINY_COUPLING × sqrt(g_ii g_jj) is a producer zero: G's row is decoupled there."""
ROWS_SHOWN = 6
"""Rows named in a message (then "…")."""


def _rows(idx) -> str:
    idx = [int(i) for i in idx]
    return ", ".join(map(str, idx[:ROWS_SHOWN])) + (", ..." if len(idx) > ROWS_SHOWN else "") + " (0-based)"


def _b_entries_on(B, dofs) -> int:
    """Non-zero entries of B in the columns ``dofs`` (sparse: no dense m × len(dofs) block)."""
    if not len(dofs):
        return 0
    block = sp.csc_matrix(B)[:, dofs]
    block.eliminate_zeros()
    return int(block.nnz)


def _decoupled(M, rtol: float = 0.0) -> np.ndarray:
    """Rows (and columns) of a square sparse M with no off-diagonal |m_ij| above
    rtol · sqrt(|m_ii m_jj|) (scale-free: a penalty elsewhere does not hide a coupling)."""
    off = sp.coo_matrix(M - sp.diags(M.diagonal()))
    d = np.sqrt(np.abs(M.diagonal()))
    big = np.abs(off.data) > rtol * d[off.row] * d[off.col]
    rows, cols = off.row[big], off.col[big]
    out = np.ones(M.shape[0], bool)
    out[rows] = out[cols] = False
    return out


def _penalty_rows(diag) -> tuple:
    """(rows whose |diagonal| is >= TGV_RATIO × the median non-zero |diagonal|, that median)."""
    diag = np.abs(diag)
    if not np.any(diag > 0):
        return np.zeros(0, int), 0.0
    med = float(np.median(diag[diag > 0]))
    return np.flatnonzero(diag >= TGV_RATIO * med), med


def constrained_displacements(level, A, B, constrained, tgv: str, interface: bool | None = None) -> tuple:
    """(dofs of A to remove, notes): the displacement rows of the module's table. ``interface``:
    whether B is a contact coupling on Γ (the manifest's ``gamma``), None: decided from B
    (:func:`_interface`)."""
    n = A.shape[0]
    notes, remove = [], [np.asarray(constrained, int)]
    if len(constrained):
        notes.append(f"{level.A.name}: {len(constrained)} declared constrained dofs removed"
                     + _dropped(B, constrained))
    diag = A.diagonal()
    pen, med = _penalty_rows(diag)
    pen = np.setdiff1d(pen, constrained)
    if len(pen):
        where = f"{len(pen)} Dirichlet penalty rows (diagonal up to {np.abs(diag).max():.3g} vs median {med:.3g})"
        if tgv == "refuse":
            raise SystemFileError(level.A, f"{where}; tgv: refuse (set tgv: eliminate, or export without them)")
        notes.append(f"{level.A.name}: {where} eliminated (v = 0 there, the penalty's limit)" + _dropped(B, pen))
        remove.append(pen)
    alone = _decoupled(A) if n > 1 else np.zeros(n, bool)
    lonely = np.setdiff1d(np.flatnonzero(alone), np.concatenate(remove))
    if len(lonely):
        cols = abs(sp.csc_matrix(B)[:, lonely])  # a column of producer zeros (<= 1e-12 max|b|) touches nothing
        touched = cols.max(axis=0).toarray().ravel() > TINY_COUPLING * (abs(B).max() if B.nnz else 0.0)
        interface = _interface(B, alone) if interface is None else interface
        # a Jacobi-scaled A (the *coupled* rows' diagonal 1): a unit row is not told apart; counted on
        # the coupled rows only, as a coarse mesh's Dirichlet rows are most of A (26 of 50 at N = 4).
        # A diagonal A (no row coupled: a toy, a lumped operator) has no body to have fixed dofs of
        body = bool(np.any(~alone))
        scaled = body and np.mean(diag[~alone] == 1.0) > 0.5
        unit = lonely[(diag[lonely] == 1.0) & touched & body & (interface or not scaled)]
        if len(unit):
            notes.append(f"{level.A.name}: {len(unit)} unit rows (diagonal exactly 1, coupled to nothing in A: "
                         "constrained dofs, v = 0) eliminated" + _dropped(B, unit))
        free = lonely[~touched]
        if len(free):
            notes.append(f"{level.A.name}: {len(free)} identity rows (uncoupled dofs B does not touch) removed")
        kept = np.setdiff1d(lonely[touched], unit)
        if len(kept) and interface and body:  # an element bubble has no trace on Γ: not a free dof of a body
            raise SystemFileError(level.A, f"rows {_rows(kept)}: coupled to nothing in A, touched by B, diagonal "
                                  f"{diag[kept[0]]:.6g} (not 1): in a contact system (B on Γ) these are not "
                                  "element bubbles, whose trace on Γ is zero; if they are fixed (Dirichlet) dofs, "
                                  f"declare them in levels[{level.index}].constrained (or zero B's columns there)")
        if len(kept):
            notes.append(f"{level.A.name}: {len(kept)} dofs coupled to nothing in A but touched by B kept (element "
                         f"bubbles, as MINI's; fixed dofs? declare them in levels[{level.index}].constrained)")
        remove += [unit, free]
    return np.unique(np.concatenate(remove)).astype(int), notes


INTERFACE_TOUCHED = 0.5
"""B couples an interface (contact, mortar) when it touches at most this fraction of A's dofs,
the uncoupled dofs it does not touch (Dirichlet identity rows) not counted. A Stokes B touches
every velocity dof; a contact B on N = 4, k = 1 membranes 10 of 28."""


def _interface(B, alone) -> bool:
    """Whether B couples an interface (:data:`INTERFACE_TOUCHED`) rather than a whole body."""
    touched = np.diff(sp.csc_matrix(B).indptr) > 0
    counted = int(np.sum(touched | ~alone))
    return counted > 0 and touched.sum() <= INTERFACE_TOUCHED * counted


def _dropped(B, dofs) -> str:
    on = _b_entries_on(B, dofs)
    return f"; B's {on} entries on them dropped" if on else ""


def constrained_multipliers(level, B, G, tgv: str) -> tuple:
    """(multiplier rows to remove, notes): the multiplier rows of the module's table, B's rows
    judged as given. A refusal names both files and the rows."""
    Gs = sp.csr_matrix(G)
    Gs.eliminate_zeros()
    gdiag = Gs.diagonal()
    B = sp.csr_matrix(B, copy=True)
    B.eliminate_zeros()  # a stored 0.0 is a zero (DOLFINx keeps the pattern of the rows its bc zeroed)
    zero_b = np.diff(B.indptr) == 0
    notes, remove = [], [np.zeros(0, int)]
    pen, med = _penalty_rows(gdiag)
    if len(pen):
        where = f"{len(pen)} penalty rows of G (diagonal up to {np.abs(gdiag).max():.3g} vs median {med:.3g}), rows {_rows(pen)}"
        if tgv == "refuse":
            raise SystemFileError(level.G, f"{where}; tgv: refuse (set tgv: eliminate, or export without them)")
        on = int(np.diff(B.indptr)[pen].sum())
        notes.append(f"{level.G.name}: {where} eliminated (mu = 0 there, the penalty's limit)"
                     + (f"; B's {on} entries on them dropped" if on else ""))
        remove.append(pen)
    zero_g = np.diff(Gs.indptr) == 0
    both = np.setdiff1d(np.flatnonzero(zero_b & zero_g), pen)
    if len(both):
        notes.append(f"{level.B.name}, {level.G.name}: {len(both)} multipliers in neither B nor G (rows "
                     f"{_rows(both)}) removed")
        remove.append(both)
    rows = np.setdiff1d(np.flatnonzero(zero_b & ~zero_g), pen)
    if not len(rows):
        return np.unique(np.concatenate(remove)).astype(int), notes
    dec = _decoupled(Gs, TINY_COUPLING)
    others = np.setdiff1d(np.arange(len(gdiag)), rows)
    typical = float(np.median(gdiag[others])) if len(others) else np.nan
    g_couples = len(others) > 0 and not dec[others].all()
    if len(others):
        marked = rows[dec[rows] & (g_couples | (gdiag[rows] != typical))]
    else:  # B = 0: no other row to single one out from; only the constraint idiom, a unit row, is one
        marked = rows[dec[rows] & (gdiag[rows] == 1.0)]  # (FreeFEM's tutorial: B = 0, G a P0 mass: a kernel)
    half = rows[~dec[rows] & (gdiag[rows] == 1.0) & (typical != 1.0)]
    if len(half):  # a unit diagonal set, the row and column left: neither reading is safe
        raise SystemFileError(level.G, f"rows {_rows(half)}: B ({level.B.name}) is zero there and G's diagonal is 1 "
                              "(a unit row: constrained multipliers?) but G still couples them to other multipliers: "
                              "removing them would change beta_h, keeping them counts a kernel; zero G's rows and "
                              "columns there but the diagonal, or drop the rows from B and G")
    if len(marked):
        notes.append(f"{level.B.name}: {len(marked)} constrained multipliers (B's row zero, G's row decoupled: "
                     f"a boundary condition on the multiplier space), rows {_rows(marked)}, removed")
        remove.append(marked)
    kernel = np.setdiff1d(rows, marked)
    if len(kernel):
        notes.append(f"{level.B.name}: {len(kernel)} zero rows ({_rows(kernel)}) kept: a kernel of B^T ("
                     + ("G couples them to other multipliers, so they are not constrained ones"
                        if not dec[kernel].all() else "G does not single them out: give them unit rows in G if "
                        "they are constrained") + ")")
    return np.unique(np.concatenate(remove)).astype(int), notes


def check_level(level, A, B, G, constrained=np.zeros(0, int), tgv: str = "eliminate",
                interface: bool | None = None) -> CheckedLevel:
    """Run every check on one level (module docstring); the matrices as read. ``interface``: as in
    :func:`constrained_displacements`."""
    for mat, path in ((A, level.A), (B, level.B), (G, level.G)):
        check_finite(mat, path)
    check_shapes(level, A, B, G)
    A, B = sp.csr_matrix(A), sp.csr_matrix(B)
    A.eliminate_zeros()
    B.eliminate_zeros()
    mult, notes = constrained_multipliers(level, B, G, tgv)
    dofs, more = constrained_displacements(level, A, B, constrained, tgv, interface)
    notes += more
    keep_m = np.setdiff1d(np.arange(B.shape[0]), mult)
    keep_n = np.setdiff1d(np.arange(A.shape[0]), dofs)
    for left, path, what in ((keep_m, level.B, "multiplier rows"), (keep_n, level.A, "dofs")):
        if not len(left):
            raise SystemFileError(path, f"every one of its {what} is constrained ({'; '.join(notes)}): nothing "
                                  "is left to compute beta_h on")
    was_zero = np.diff(B.indptr)[keep_m] == 0
    A, B = A[keep_n][:, keep_n], B[keep_m][:, keep_n]
    G = sp.csr_matrix(G)[keep_m][:, keep_m] if sp.issparse(G) else np.asarray(G, float)[np.ix_(keep_m, keep_m)]
    B.eliminate_zeros()
    orphan = np.flatnonzero((np.diff(B.indptr) == 0) & ~was_zero)
    if len(orphan):
        notes.append(f"{level.B.name}: {len(orphan)} multipliers couple only to the removed dofs (rows "
                     f"{_rows(keep_m[orphan])}): a kernel of B^T")
    check_symmetric(A, level.A, "A")
    G = check_gram(G, level.G)
    check_positive_definite(A, level.A)
    return CheckedLevel(sp.csc_matrix(A), sp.csr_matrix(B), G, notes, len(dofs), len(mult), keep_m)


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
    121,680 rows, SuperLU's LDLᵀ was most of the check)."""
    A = sp.csc_matrix(A)
    n = A.shape[0]
    if n and not np.any(A.data):  # every entry zero: no pivot to scale a shift by
        raise SystemFileError(path, f"{what} is zero ({n} x {n}, every entry 0): not positive definite (an empty "
                              "export?)")
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
        try:
            shifted = spla.splu(A + shift * sp.identity(n, format="csc"), permc_spec="MMD_AT_PLUS_A",
                                diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
        except RuntimeError:  # singular even shifted (entries of mixed magnitudes): no null vector to show
            raise SystemFileError(path, f"{what} is singular: {max(zero, 1)} or more zero pivots of {n} (a floating "
                                  "body: rigid motions not fixed?)") from None
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
