"""Stabilised systems: the (2,2) block −C of [[A, Bᵀ], [B, −C]] and what it does to β.

A manifest level may carry ``C`` (a file like G: m × m, symmetric positive semidefinite). The
quantity certified beside the unstabilised β_h is

    β_C² = λ_min(B A⁻¹ Bᵀ + C, G),

the inf-sup constant of the stabilised problem: sup_v b(v, μ)²/‖v‖_A² + c(μ, μ) ≥ β_C² ‖μ‖_G²
(Brezzi–Fortin, "A minimal stabilisation procedure for mixed finite element methods", Numer.
Math. 89, 2001). It is computed on the route of the unstabilised pencil (:mod:`.engine`): the
dense routes add C to S = B A⁻¹ Bᵀ; shift-invert factorizes [[A, Bᵀ], [B, −(C + δG)]], whose
(2,1) Schur complement gives p = −(S + C + δG)⁻¹ r.

Two numbers per level say how much of β_C comes from C:

``c_share``
    xᵀC x / xᵀ(S + C) x at the bottom mode x of (S + C, G): the fraction of β_C² that C
    supplies there, in [0, 1]. 1: the mode is a kernel mode of Bᵀ held by C alone; 0: C adds
    nothing at the bottom (β_C = β_h).
``c_scale``
    λ_max(C, G) / λ_max(S, G): C's size against the pencil's. Below :data:`REGULARISED_MAX`
    C is a regularisation (C ≈ ε M with ε tiny, e.g. the 1e-10 mass a code puts in the (2,2)
    block so that its direct solver gets through a singular system), not a stabilisation.

The verdict (:func:`stabilisation_verdict`) keeps the unstabilised verdict in ``verdict`` and
adds ``stabilisation``: ``stable-without-C`` (the unstabilised verdict is STABLE),
``regularised`` (the unstabilised pair not STABLE and C tiny, :data:`REGULARISED_MAX`, or lifting
the kernel only to β_C ≤ the floor on every level, as where B = 0 leaves no pencil to compare C with),
``stabilised`` (C controls the kernel or the decay: the one-sided slope test of ``verdict
--case`` on the β_C series, :func:`uniform_verdict`, says "uniformly in h" or "not uniformly"),
``none`` (C is zero). The evidence starts with the label and what C does ("regularised: C ~
eps*M ...", "stabilised: C controls a kernel of dimension 1 ... (uniformly in h)"), then the
unstabilised evidence ("without C: ..."). Without ``C`` none of these columns is written and
the rows are those of an unstabilised system, unchanged.

**Bubble condensation.** Enrich the displacements with bubbles b (one per slave element):
A_e = [[A, K_ub], [K_ubᵀ, K_bb]], B_e = [D, D_b]. Eliminating b from
[[A_e, B_eᵀ], [B_e, 0]] gives the condensed system [[S_A, B_cᵀ], [B_c, −C]] with
S_A = A − K_ub K_bb⁻¹ K_ubᵀ, B_c = D − D_b K_bb⁻¹ K_ubᵀ and C = D_b K_bb⁻¹ D_bᵀ (PSD; GEOS and
GReS write the (2,2) block itself, −D_b K_bb⁻¹ D_bᵀ). The block inverse of A_e through the
Schur complement S_A of K_bb gives, term by term,

    B_e A_e⁻¹ B_eᵀ = B_c S_A⁻¹ B_cᵀ + D_b K_bb⁻¹ D_bᵀ,

so the condensed system's β_C is β_h of the bubble-enriched unstabilised pair, eigenvalue by
eigenvalue (:func:`condense_bubbles`; tests/systems/test_systems_stabilised.py checks it on the
paper's membranes with P0 multipliers and one edge bubble per slave edge of Γ).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..criteria.stability import stability_verdict
from .checks import check_finite, check_symmetric
from .readers import SystemFileError

REGULARISED_MAX = 1e-6
"""``c_scale`` = λ_max(C, G)/λ_max(B A⁻¹ Bᵀ, G) below this on every level: C is a regularisation
(ε M, ε tiny), not a stabilisation. A stabilisation that controls a kernel with a β_C of the
order of the stable spaces' (0.1–1 in H^{-1/2}) has λ_max(C, G) ≳ β_C², far above it."""
PSD_RTOL = 1e-10
"""C is positive semidefinite when its smallest eigenvalue is ≥ −PSD_RTOL · its largest |eigenvalue|."""
DENSE_PSD_MAX_M = 3000
"""Largest m whose C is checked by a dense eigenvalue decomposition; above it by the inertia of
an LDLᵀ of C + δI (Sylvester)."""
N_BOTTOM = 6
"""Eigenvalues of (S + C, G) computed from the bottom (as the unstabilised routes)."""


@dataclass(frozen=True)
class StabilisedSpectrum:
    """β_C and what C contributes on one level (module docstring)."""

    beta_C: float
    c_share: float
    c_scale: float
    residual: float
    lam_c: float  # λ_max(C, G)
    lam_s: float  # λ_max(S, G)


def check_stabilisation(level, C, m: int, kept=None, penalty: bool = True):
    """C as read (``level.C``) checked: finite, m × m (m = B's rows as read), symmetric, positive
    semidefinite; returned restricted to the multiplier rows the checks kept (``kept``: the rows
    of B as read that the checked B holds; constrained multipliers go from C as from B and G);
    ``penalty``: refuse penalty rows left in it (:func:`check_no_penalty`; the dry run of a level
    that describes its multipliers does not know the rows the description removes)."""
    path = level.C
    check_finite(C, path)
    check_c_shape(level, C.shape, m)
    check_symmetric(C, path, "C")
    check_semidefinite(C, path)
    if kept is not None and len(kept) < m:
        C = sp.csr_matrix(C)[kept][:, kept] if sp.issparse(C) else np.asarray(C, float)[np.ix_(kept, kept)]
    if penalty:
        check_no_penalty(C, path)
    return sp.csr_matrix(C) if sp.issparse(C) else np.asarray(C, float)


def check_no_penalty(C, path) -> None:
    """Refuse penalty rows ("tgv", a diagonal >= 1e15 × the median non-zero one) left in C after
    the constrained multipliers went: a multiplier fixed by a penalty in the (2,2) block is a
    constrained row, which the one rule reads from G (a penalty or unit row there) and B."""
    from .checks import _penalty_rows, _rows

    diag = sp.csr_matrix(C).diagonal() if sp.issparse(C) else np.diag(np.asarray(C, float))
    pen, med = _penalty_rows(diag)
    if len(pen):
        raise SystemFileError(path, f"{len(pen)} penalty rows of C (diagonal up to {np.abs(diag).max():.3g} vs median "
                              f"{med:.3g}), rows {_rows(pen)} of those kept: multipliers fixed by a penalty in the "
                              "(2,2) block; mark them in G as well (a penalty or unit row, the constrained-rows rule) "
                              "or export without them")


def check_c_shape(level, shape, m: int) -> None:
    """C must be m × m, m = B's rows as read (also from the headers, before any body is read)."""
    if tuple(shape) != (m, m):
        raise SystemFileError(level.C, f"C is {shape[0]} x {shape[1]}, but B ({level.B.name}) has {m} rows: expected "
                              f"{m} x {m} (the (2,2) block of [[A, B^T], [B, -C]], one row per multiplier)")


def stabilised_bytes(C, route) -> float:
    """The memory β_C adds to a level (``--dry-run``): on the dense routes (``route`` None: the
    route ``auto`` picks, counted as dense) C dense, S + C and its copy in the pencil's solver,
    3 m² doubles; on shift-invert the entries of C in the KKT matrix and their fill, 3 × 12 bytes
    per entry (the LUs of [[A, Bᵀ], [B, −(C + δG)]] and of A are made after the unstabilised
    route's are freed: the route's own estimate is their peak)."""
    m = C.shape[0]
    if route == "shift-invert":
        return 3 * 12.0 * sp.csr_matrix(C).nnz
    return 3 * 8.0 * m * m


def check_semidefinite(C, path) -> None:
    """Refuse a C with an eigenvalue below −:data:`PSD_RTOL` · max |eigenvalue| (one line naming
    the file; a negative semidefinite C is the (2,2) block itself, exported with its sign)."""
    m = C.shape[0]
    Cs = sp.csr_matrix(C)
    scale = float(abs(Cs).max()) if Cs.nnz else 0.0
    if scale == 0.0:
        return
    if m <= DENSE_PSD_MAX_M:
        ev = np.linalg.eigvalsh(Cs.toarray())
        low, top = float(ev[0]), float(np.max(np.abs(ev)))
        bad = low < -PSD_RTOL * top
        negdef = bool(np.all(ev <= PSD_RTOL * top))
    else:  # the inertia of C + δI: its negative pivots count the eigenvalues of C below −δ
        delta = PSD_RTOL * scale * m
        try:
            lu = spla.splu(sp.csc_matrix(Cs + delta * sp.identity(m)), permc_spec="MMD_AT_PLUS_A",
                           diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
            neg = int(np.sum(lu.U.diagonal() < 0))
        except RuntimeError:  # an exactly zero pivot of C + δI: an eigenvalue at −δ
            neg = 1
        bad, low, top, negdef = neg > 0, np.nan, scale, neg == m
    if bad:
        sign = " (every eigenvalue <= 0: this is the (2,2) block itself; C is minus it)" if negdef else ""
        where = f"smallest eigenvalue {low:.3g} vs largest |eigenvalue| {top:.3g}" if np.isfinite(low) else \
            f"{neg} negative pivots of C + {PSD_RTOL * scale * m:.2g} I"
        raise SystemFileError(path, f"C is not positive semidefinite: {where}{sign}; the system is "
                              "[[A, B^T], [B, -C]] with C symmetric positive semidefinite")


def stabilised_spectrum(A, B, G, C, route: str, smax2: float, S=None) -> StabilisedSpectrum:
    """β_C, c_share, c_scale of one checked level on ``route`` (:data:`.engine.ROUTES`, not
    ``auto``); ``smax2`` = σ_max(W)², the Jacobi scale that sets shift-invert's δ; ``S``: B A⁻¹ Bᵀ
    where the unstabilised dense route formed it already (``LevelSpectrum.schur``), else formed here."""
    A, B = sp.csc_matrix(A), sp.csr_matrix(B)
    if route == "shift-invert" and B.shape[0] > 2:  # Lanczos needs k < m (m <= 2: the dense pencil)
        return _shift_invert(A, B, G, C, smax2)
    from ..la.bottom import lam_max
    from .engine import touched_dofs

    S = _dense_schur(A, B, touched_dofs(B), route) if S is None else S
    Cd = C.toarray() if sp.issparse(C) else np.asarray(C, float)
    Gd = G.toarray() if sp.issparse(G) else np.asarray(G, float)
    T = S + 0.5 * (Cd + Cd.T)
    k = min(N_BOTTOM, T.shape[0])
    ev, x = sla.eigh(T, Gd, subset_by_index=[0, k - 1])
    res = np.linalg.norm(T @ x - (Gd @ x) * ev, axis=0)
    scale = (np.linalg.norm(T, 2) + np.abs(ev) * np.linalg.norm(Gd, 2)) * np.linalg.norm(x, axis=0)
    L = sla.cholesky(Gd, lower=True, check_finite=False)
    # B = 0 (a code whose coupling integrals are empty: FreeFEM's tutorial as Debian runs it): no pencil
    lam_s = 0.0 if not np.any(S) else lam_max(S, L) if S.shape[0] > 1 else float(S[0, 0] / Gd[0, 0])
    lam_c = 0.0 if not np.any(Cd) else (lam_max(Cd, L) if Cd.shape[0] > 1 else float(Cd[0, 0] / Gd[0, 0]))
    return _spectrum(ev[0], x[:, 0], Cd, T, float(np.max(res / scale)), lam_c, lam_s)


def _spectrum(lam, x, C, T, residual, lam_c, lam_s) -> StabilisedSpectrum:
    total = float(x @ (T @ x))
    share = float(x @ (C @ x)) / total if total > 0 else np.nan
    return StabilisedSpectrum(float(np.sqrt(max(lam, 0.0))), min(max(share, 0.0), 1.0),
                              lam_c / lam_s if lam_s > 0 else np.inf, residual, lam_c, lam_s)


def _dense_schur(A, B, touched, route) -> np.ndarray:
    """S = B A⁻¹ Bᵀ as the unstabilised dense routes form it (:func:`.engine._dense`)."""
    from ..la.schur import gamma_factorization

    if route == "gamma-dense":
        rest = np.setdiff1d(np.arange(A.shape[0]), touched)
        order = np.concatenate([rest, touched])
        fac = gamma_factorization(A[order][:, order], len(touched), gamma_dim=None)  # as .engine._dense
        Bg = B[:, touched].toarray()
        S = Bg @ fac.steklov_times(Bg.T)
    else:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
        S = B @ lu.solve(B.T.toarray())
    return 0.5 * (S + S.T)


def _shift_invert(A, B, G, C, smax2) -> StabilisedSpectrum:
    """The bottom of (S + C, G) by shift-invert Lanczos: one sparse LU of
    [[A, Bᵀ], [B, −(C + δG)]] gives (S + C + δG)⁻¹, an independent LU of A gives S."""
    from .engine import NCV_MIN, SHIFT, _pencil_top

    m, n = B.shape
    Gs, Cs = sp.csc_matrix(G), sp.csc_matrix(C)
    delta = SHIFT * smax2
    K = sp.bmat([[A, B.T], [B, -(Cs + delta * Gs)]], format="csc")
    lu = spla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
    luA = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))
    rhs = np.zeros(n + m)

    def inv(r):
        rhs[:] = 0.0
        rhs[n:] = np.ravel(r)
        return -lu.solve(rhs)[n:]

    def schur(x):
        return B @ luA.solve(np.asarray(B.T @ x))

    def total(x):
        return schur(x) + Cs @ x

    k = max(1, min(N_BOTTOM, m - 2))
    op = spla.LinearOperator((m, m), matvec=inv, dtype=float)
    T_op = spla.LinearOperator((m, m), matvec=total, matmat=total, dtype=float)
    v0 = np.random.default_rng(0).standard_normal(m)
    _, x = spla.eigsh(T_op, k=k, M=Gs, sigma=-delta, OPinv=op, which="LM", tol=1e-12, v0=v0,
                      ncv=min(m, max(2 * k + 1, NCV_MIN)))
    Tx, Gx = total(x), Gs @ x
    ev = np.einsum("ij,ij->j", x, Tx) / np.einsum("ij,ij->j", x, Gx)  # Rayleigh quotients, exact S + C
    j = int(np.argmin(ev))
    g_norm = float(spla.eigsh(Gs, k=1, which="LA", tol=1e-3, return_eigenvectors=False)[0])
    t_norm = float(np.max(np.linalg.norm(Tx, axis=0) / np.linalg.norm(x, axis=0)))
    res = np.linalg.norm(Tx - Gx * ev, axis=0) / ((t_norm + np.abs(ev) * g_norm) * np.linalg.norm(x, axis=0))
    lam_s = _pencil_top(schur, Gs) if B.nnz and abs(B).max() > 0 else 0.0
    lam_c = _pencil_top(lambda y: Cs @ y, Gs) if Cs.nnz and abs(Cs).max() > 0 else 0.0
    xj = x[:, j]
    share = float(xj @ (Cs @ xj)) / float(xj @ Tx[:, j])
    return StabilisedSpectrum(float(np.sqrt(max(ev[j], 0.0))), min(max(share, 0.0), 1.0),
                              lam_c / lam_s if lam_s > 0 else np.inf, float(np.max(res)), lam_c, lam_s)


def stabilised_columns(spec: StabilisedSpectrum) -> dict:
    """The level row's columns of C (module docstring)."""
    return dict(beta_C=spec.beta_C, c_share=spec.c_share, c_scale=spec.c_scale, residual_C=spec.residual)


def stabilisation_verdict(rows, out: dict, *, tol: float, floor: float, confidence: float) -> dict:
    """The head's columns of C, and ``out``'s evidence extended (module docstring): ``beta_C``
    (per level), ``verdict_C``, ``beta_C_min``, ``slope_C`` (the slope test of ``verdict --case``
    on the β_C series), ``c_share``, ``c_scale_max``, ``stabilisation``."""
    vc = uniform_verdict(rows, tol, floor, confidence)
    scale = max(r["c_scale"] for r in rows)
    betas = ", ".join(f"{r['beta_C']:.4g}" for r in rows)
    inv_h = ", ".join(f"{1 / r['h']:g}" for r in rows)
    c_text = (f"beta_C = {betas} over 1/h = {inv_h} (slope {vc['slope']:.3g} [{vc['slope_lo']:.3g}, "
              f"{vc['slope_hi']:.3g}]); C's share of beta_C^2 at the bottom mode "
              f"{min(r['c_share'] for r in rows):.2g}-{max(r['c_share'] for r in rows):.2g}; "
              f"lambda_max(C,G)/lambda_max(BA^-1B^T,G) <= {scale:.2g}")
    dims = [int(r["kernel_detected"]) for r in rows]
    if out["verdict"] == "STABLE":
        label, words = "stable-without-C", "the unstabilised pair is STABLE, C is not needed for stability; "
    elif scale == 0.0:
        label, words = "none", "C is zero: no stabilisation; "
    elif scale < REGULARISED_MAX:
        label, words = "regularised", (f"C ~ eps*M with eps tiny (below {REGULARISED_MAX:g} of the pencil): it "
                                       "regularises the solve, it does not stabilise the pair; ")
    elif max(r["beta_C"] for r in rows) <= floor:
        # no pencil to compare C with (B A^-1 B^T = 0) or C lifting the kernel only below the floor
        label, words = "regularised", (f"C lifts the kernel only to beta_C <= the floor {floor:g} on every level: it "
                                       "regularises the solve, it does not stabilise the pair; ")
    else:
        what = (f"a kernel of dimension {max(dims)} (dims {dims})" if max(dims) > 0
                else "the decay of the unstabilised beta_h")
        how = {"STABLE": "uniformly in h", "UNSTABLE": "not uniformly: beta_C decays",
               "INCONCLUSIVE": "uniformity in h inconclusive"}[vc["verdict"]]
        label, words = "stabilised", f"C controls {what} ({how}); "
    evidence = f"{label}: {words}{c_text}; without C: {out['evidence']}"
    return dict(evidence=evidence, stabilisation=label, verdict_C=vc["verdict"], beta_C=[r["beta_C"] for r in rows],
                beta_C_min=vc["beta_min"], slope_C=vc["slope"], slope_C_lo=vc["slope_lo"], slope_C_hi=vc["slope_hi"],
                c_share_max=max(r["c_share"] for r in rows), c_scale_max=scale)


def uniform_verdict(rows, tol: float, floor: float, confidence: float) -> dict:
    """The slope test of ``verdict --case`` on the β_C series, one-sided: β_C bounded *below*
    uniformly in h is STABLE when min β_C > floor and the slope interval of log β_C against
    log h lies below +tol (a β_C that grows as h → 0, as C = α h⁻¹ M would give, is bounded
    below); UNSTABLE when min β_C <= floor or the interval lies above +tol (β_C decays);
    INCONCLUSIVE otherwise. ``verdict``, ``beta_min``, ``slope``, ``slope_lo``, ``slope_hi``."""
    h = np.array([r["h"] for r in rows], float)
    beta = np.array([r["beta_C"] for r in rows], float)
    series = [dict(N2=1.0 / r["h"], beta=r["beta_C"], kernel_dim=0, smallest_nonzero=r["beta_C"],
                   kernel_decision="clear", case=r["system"]) for r in rows]
    out = stability_verdict(series, tol, floor, confidence)  # the fit, and the floor's test
    if beta.min() <= floor:
        verdict = "UNSTABLE"
    elif len(h) >= 3 and np.isfinite(out["slope_hi"]) and out["slope_hi"] <= tol:
        verdict = "STABLE"
    elif np.isfinite(out["slope_lo"]) and out["slope_lo"] > tol:
        verdict = "UNSTABLE"
    else:
        verdict = "INCONCLUSIVE"
    return dict(out, verdict=verdict)


def condense_bubbles(A, K_ub, K_bb, D, D_b) -> tuple:
    """(S_A, B_c, C) of the bubble condensation (module docstring): S_A = A − K_ub K_bb⁻¹ K_ubᵀ,
    B_c = D − D_b K_bb⁻¹ K_ubᵀ, C = D_b K_bb⁻¹ D_bᵀ (the (2,2) block is −C); K_bb is the
    bubbles' stiffness (block diagonal for element bubbles: the products stay sparse)."""
    K_bb = sp.csc_matrix(K_bb)
    K_ub, D_b = sp.csr_matrix(K_ub), sp.csr_matrix(D_b)
    X = sp.csr_matrix(spla.spsolve(K_bb, sp.csc_matrix(K_ub.T)))  # K_bb⁻¹ K_ubᵀ, sparse for element bubbles
    Y = sp.csr_matrix(spla.spsolve(K_bb, sp.csc_matrix(D_b.T)))  # K_bb⁻¹ D_bᵀ
    S_A = sp.csr_matrix(A) - K_ub @ X
    B_c = sp.csr_matrix(D) - D_b @ X
    C = sp.csr_matrix(D_b @ Y)
    for M in (S_A, B_c, C):
        M.eliminate_zeros()
    return 0.5 * (S_A + S_A.T), B_c, 0.5 * (C + C.T)
