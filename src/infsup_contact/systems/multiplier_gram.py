"""Gram matrices of a described multiplier space (:mod:`.multiplier_basis`) on Γ of any size.

The space is held on the pull-back of Γ: the unit interval, or the unit square. Its Grams there
are those ``beta --norm H`` computes (the log kernel on the segment,
:func:`~infsup_contact.discretization.segment.norms.gram`; the double sine series on the face,
:func:`~infsup_contact.discretization.face.norms.tensor.gram_h_face`), and Γ's size enters as a factor:

**Segment Γ = (0, L).** The Dirichlet Laplacian of (0, L) has the L²-orthonormal eigenfunctions
√(2/L) sin(nπx/L), eigenvalues (nπ/L)², so ‖μ‖²_{H^{-1/2}_00(0,L)} = Σ_n μ_n² L/(nπ) with
μ_n = √(2/L) ∫_0^L μ sin(nπx/L) dx. For μ(x) = μ̃(x/L), μ_n = √L μ̃_n, hence

    ‖μ‖²_{H^{-1/2}_00(0,L)} = L² ‖μ̃‖²_{H^{-1/2}_00(0,1)},     ‖μ‖²_{L²(0,L)} = L ‖μ̃‖²_{L²(0,1)}:

G_H = L² G̃_H, M = L M̃ (the norm itself scales like L, as ⟨μ, v⟩ ~ L while |v|_{H^{1/2}} is
invariant in one dimension).

**Rectangle Γ = (0, a) × (0, b).** Eigenfunctions (2/√(ab)) sin(mπx/a) sin(nπy/b), eigenvalues
π²((m/a)² + (n/b)²); for μ(x, y) = μ̃(x/a, y/b) the coefficient is √(ab) μ̃_mn, so

    ‖μ‖² = Σ ab μ̃_mn² / (π √((m/a)² + (n/b)²)) = b³ Σ α μ̃_mn² / (π √((m/α)² + n²)),  α = a/b,

the series of ``gram_h_face(..., aspect=α)`` times b³: G_H = b³ G̃_H(α), M = ab M̃. A square
of side L: G_H = L³ G̃_H (the norm scales like L^{3/2}).

**What is invariant.** Scaling the whole geometry by L leaves β_h unchanged: in 2D the
stiffness A (∫∇u·∇v) is invariant, B (∫_Γ μ v) scales by L and G_H by L²; in 3D A scales by L,
B by L², G_H by L³. Either way B A⁻¹ Bᵀ and G_H scale alike (tests/systems/test_systems_norm_h.py).
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from .readers import SystemFileError

GRAM_COPIES = 10
"""Dense m × m arrays alive while a Gram is made and ordered (the Gram, its reordering, the
pencil's copies: as ``resources._dense_bytes`` counts them)."""
LOGKERNEL_BYTES_PER_PAIR = 600
"""Bytes per pair of intervals of the log-kernel route, plus 110 (s + 1)² (``resources._dense_bytes``)."""
FACE_BYTES_PER_M2 = 200
"""Bytes per (dim M)² of the face series (the m² term of ``resources.LARGE_ROUTE_3D``, which
holds the Grams, the pencils and the series' arrays: 132 to 197)."""


def gram(described, norm: str) -> tuple:
    """(G, info): the Gram of ``norm`` ∈ {"H", "L2"} in the order of B's rows, scaled to Γ."""
    from ..discretization.face.norms.tensor import gram_h_face, gram_l2_face

    space, size = described.space, described.gamma.size
    if described.gamma.shape == "segment":
        G, info = described.gamma.interface.gram(space, norm)
        scale = size[0] ** 2 if norm == "H" else size[0]
    elif norm == "H":
        a, b = size
        G, info = gram_h_face(space, aspect=1.0 if a == b else a / b)  # a = b: bit for bit the square's
        scale = b ** 3
    else:
        G, info = gram_l2_face(space), {"n_max": 0, "nmax_rel_error": 0.0}
        scale = size[0] * size[1]
    inv = np.argsort(described.rows)  # row r of B holds basis function inv[r]
    G = np.asarray(G, float)[np.ix_(inv, inv)]
    return (G * scale if scale != 1.0 else G), info


def gram_bytes(described) -> float:
    """Bytes to assemble the H Gram and the L² check of ``described`` (the memory gate's share)."""
    m = float(described.m)
    if described.gamma.shape == "segment":
        n = float(described.space.n_intervals)
        s = described.space.degree
        return 8.0 * GRAM_COPIES * m * m + (LOGKERNEL_BYTES_PER_PAIR + 110 * (s + 1) ** 2) * n * (n + 1) / 2
    return FACE_BYTES_PER_M2 * m * m


def mass_distance(G_file, M) -> float:
    """‖G_file − M‖_F / ‖M‖_F: how far an exported L² mass is from the description's."""
    import scipy.sparse as sp

    D = (G_file - M) if not sp.issparse(G_file) else (G_file.toarray() - M)
    return float(np.linalg.norm(D) / np.linalg.norm(M))


MASS_RTOL = 1e-8
"""Largest ‖G_file − M‖_F / ‖M‖_F accepted between an exported L² mass and the described basis's.
Exact quadrature leaves round-off of ~1e-15; one pair of rows of B swapped against the
description changes a P_1 (or dual) mass by 0.25, 0.084, 0.021 relative at m = 7, 63, 1023
(≳ 1/(4√m): M ≈ h/6 tridiag(1, 4, 1)), above 1e-4 for any m ≤ 10⁶: the gap between the two is
what tells a wrong row order from round-off. A permutation that leaves M unchanged (P_0 on
cells of equal length, M = h I) cannot be seen by this check."""


def _label(manifest, level) -> Path:
    """What the checks name when the described Gram fails one (not a file: the manifest's key)."""
    return Path(f"{manifest.path}#levels[{level.index}].multipliers")


def check_description(manifest, level, B, G_file) -> tuple:
    """(level with G named by its description, a G standing in for the shape checks, bytes of its
    Gram): the description read and checked against B and the G file, nothing m × m allocated."""
    from .multiplier_basis import describe

    d = describe(manifest.path, level.index, level.multipliers, manifest.gamma)
    if d.m != B.shape[0]:
        hint = ("; hint: B appears transposed: give B as m x n (a row per multiplier, a column per dof)"
                if B.shape[1] == d.m else "")
        raise SystemFileError(d.source, f"{d.key}: describes m = {d.m} basis "
                              f"functions, B ({level.B.name}) has {B.shape[0]} rows: one row of B per function{hint}")
    if G_file is not None and G_file.shape != (d.m, d.m):
        raise SystemFileError(level.G, f"G is {G_file.shape[0]} x {G_file.shape[1]}; with norm: H it is the L2 mass "
                              f"of the {d.m} described multipliers ({d.m} x {d.m})")
    if manifest.norm == "H" and G_file is None and level.traces is None:
        raise SystemFileError(manifest.path, f"levels[{level.index}]: norm: H with the multipliers described needs G "
                              "(their L2 mass) or traces (the bodies' trace bases on Gamma) to check the description "
                              "against: without either a wrong row order, breakpoints, basis or nodes gives a wrong "
                              "beta_h silently")
    if manifest.norm != "H":  # G is the file's; with L2 / h-L2 its dense copy meets the mass
        return level, G_file, (8.0 * 4 * d.m * d.m if manifest.norm in ("L2", "h-L2") else 0.0), d
    stand_in = np.broadcast_to(0.0, (d.m, d.m))  # dense like the Gram (the route), no memory
    return replace(level, G=_label(manifest, level)), stand_in, gram_bytes(d), d


INDEPENDENCE_RTOL = 1e-12
"""A Cholesky pivot² of the Jacobi-scaled L² mass below this is a linearly dependent basis (the
suite's check of users' spaces, ``user_spaces.check_space``, uses the same 1e-12)."""


def _independent(d, M) -> None:
    """The described basis is linearly independent: Cholesky of D^{-1/2} M D^{-1/2} (D = diag M)
    with no pivot² ≤ :data:`INDEPENDENCE_RTOL`; else one line naming the description."""
    import scipy.linalg as sla

    dg = np.sqrt(np.diag(M))
    ok = bool(np.all(dg > 0))
    if ok:
        try:
            L = sla.cholesky(M / dg[:, None] / dg[None, :], lower=True, check_finite=False)
            ok = bool(np.min(np.diag(L)) ** 2 > INDEPENDENCE_RTOL)
        except sla.LinAlgError:
            ok = False
    if not ok:
        raise SystemFileError(d.source, f"{d.key}: the described basis functions are linearly dependent (their "
                              f"L2 mass is singular to {INDEPENDENCE_RTOL:g}): not a basis of the multipliers")


def _coupling_check(manifest, level, d, B, keep) -> str:
    """``coupling`` where one body's block of B is its exact coupling with the described traces
    (:func:`.mortar_distance.block_distances` within :data:`.mortar_distance.CHECKED_RTOL`), else
    ``none``: the description is then unchecked and the verdict INCONCLUSIVE (:mod:`.levels`)."""
    from .mortar_distance import CHECKED_RTOL, block_distances

    return "coupling" if min(block_distances(manifest, level, d, B, keep)) <= CHECKED_RTOL else "none"


def _rows_check(manifest, level, d, B, keep) -> None:
    """Refuse B whose rows are, on every body, farther from the exact coupling of the described
    traces than quadrature puts them (:data:`.mortar_distance.ROW_RTOL`): with G matching, a
    permutation of rows of equal mass (P_0 on equal cells), which the mass cannot see."""
    from .mortar_distance import ROW_RTOL, block_distances

    worst = min(block_distances(manifest, level, d, B, keep, per_row=True))
    if worst > ROW_RTOL:
        raise SystemFileError(manifest.path, f"levels[{level.index}].multipliers: a row of B is {worst:.3g} (against "
                              f"its block's largest row) from the exact coupling of the described traces on every "
                              f"body, where quadrature error stays below {ROW_RTOL:g}: B's rows in another order than "
                              "the description (rows:; the L2 mass cannot see a permutation of equal masses)?")


def described_grams(manifest, level, B, G_file) -> tuple:
    """(level, B, G, L² mass from the G file or None, info) of a level describing its multipliers.
    ``norm: H``: G the described H Gram (``info`` its series' info), the G file (optional) the L²
    mass; ``L2`` / ``h-L2``: G the file's, checked as the L² mass; ``given``: G the file's,
    unchecked. A G file farther than :data:`MASS_RTOL` from the description's L² mass is
    refused. Multipliers the producer constrained (B's row zero, G's row decoupled: the rule of
    :func:`~.checks.constrained_multipliers`) are left out of that comparison and, with ``norm: H``,
    removed from B and the Gram here (μ_i = 0: the Gram of the constrained space), counted in
    ``info["removed_multipliers"]`` with ``info["notes"]``. ``info["coupling_distance"]``: B's
    distance to the exact coupling of the described traces on the rows kept (:mod:`.mortar_distance`;
    NaN without ``traces``); ``info["described"]``, ``info["kept"]``: the description and the rows of
    B as read that the returned B holds (a mode is drawn with them, :func:`.levels.level_mode`)."""
    import scipy.sparse as sp

    from .checks import check_finite, check_gram, constrained_multipliers
    from .mortar_distance import coupling_distance

    labelled, _, _, d = check_description(manifest, level, B, G_file)
    keep, notes = np.arange(d.m), []
    if G_file is not None and manifest.norm != "given":
        check_finite(G_file, level.G)
        drop, notes = constrained_multipliers(level, sp.csr_matrix(B), G_file, manifest.tgv)
        keep = np.setdiff1d(keep, drop)
    distance = coupling_distance(manifest, level, d, B, keep)
    if manifest.norm == "given":
        return level, B, G_file, None, {"coupling_distance": distance, "described": d, "kept": np.arange(d.m)}
    M = gram(d, "L2")[0]
    _independent(d, M)
    G, info = gram(d, "H") if manifest.norm == "H" else (G_file, {})
    mass = None
    if G_file is not None:
        sub = np.ix_(keep, keep)
        dist = mass_distance(sp.csr_matrix(G_file)[keep][:, keep] if sp.issparse(G_file) else G_file[sub], M[sub])
        if not dist <= MASS_RTOL:
            raise SystemFileError(level.G, f"differs from the L2 mass of levels[{level.index}].multipliers by "
                                  f"{dist:.3g} relative (Frobenius; round-off is below {MASS_RTOL:g}): B's rows in "
                                  "another order than the description (rows:), another basis, or other breakpoints?")
    info = dict(info, coupling_distance=distance, described=d, kept=np.arange(d.m))  # B's rows as returned
    if G_file is not None and level.traces is not None:  # what the mass cannot see: equal masses permuted
        _rows_check(manifest, level, d, B, keep)
    if manifest.norm == "H":  # what checked the description: G's mass, else an exact body block of B
        info["description_check"] = "mass" if G_file is not None else _coupling_check(manifest, level, d, B, keep)
    if manifest.norm != "H":  # the checks remove the constrained rows of the file's G themselves
        return labelled, B, G, mass, info
    if len(keep) < d.m:
        B, G = sp.csr_matrix(B)[keep], G[np.ix_(keep, keep)]
        G_file = None if G_file is None else (sp.csr_matrix(G_file)[keep][:, keep] if sp.issparse(G_file)
                                              else np.asarray(G_file)[np.ix_(keep, keep)])
        info.update(removed_multipliers=d.m - len(keep), notes=notes, kept=keep)
    if G_file is not None:
        mass = check_gram(G_file, level.G)
    return labelled, B, G, mass, info
