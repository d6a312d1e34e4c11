"""A manifest's levels → one β row per level → the verdict, by ``verdict --case``'s criterion.

The rows carry what :func:`infsup_contact.criteria.stability.stability_verdict` reads (``N2`` is
1/h, so its h is the manifest's) plus the route, residual, kernel decision, the entries'
round-off in η (``entry_rtol_used``, ``entry_rtol_source``), the pencil's cross-check
(``pencil_margin_decades``), what a close decision asks of the user (``kernel_advice``), the
constrained rows removed (``removed_dofs``, ``removed_multipliers``) and notes. The
norm caveats (module :mod:`.manifest`, key ``norm``) are part of every row.
"""
from __future__ import annotations

import sys
import time

import numpy as np
import scipy.sparse as sp

from .. import progress
from ..solvers.kernel import MARGIN_DECADES
from ..criteria.stability import stability_verdict
from .checks import check_level, check_sequence
from .engine import close_advice, level_spectrum
from .hints import system_hints, transposed_b_hint
from .manifest import Manifest, constrained_dofs
from .readers import SystemFileError, read_matrix

NORM_NOTES = {
    "given": "G as given (the norm the inf-sup condition is stated in)",
    "L2": ("L2 verdict: G is the L2 mass of the multipliers; stable contact spaces decay like h^1/2 in L2 "
           "(Remark 3.1), so this is not the H^-1/2 verdict"),
    "h-L2": ("h-weighted L2 (G = h*M): a mesh-dependent norm weaker than H^-1/2 on quasi-uniform meshes "
             "(h^1/2|mu|_L2 <~ |mu|_H^-1/2); STABLE here does not prove H^-1/2 stability"),
    "H": ("H^-1/2_00(Gamma) verdict: G assembled from the multipliers described on Gamma (gamma, multipliers); "
          "a G file, where given, is their L2 mass (checked against the description; its verdict is verdict_L2)"),
}


UNCHECKED = ("levels[{i}].multipliers unchecked: no G, and no body's block of B is the exact coupling of the "
             "described traces (to 1e-8): a wrong row order, breakpoints, basis or nodes cannot be told from "
             "quadrature error, so beta_h is not certified; give G (the L2 mass of the multipliers)")


def load_level(manifest: Manifest, level):
    """Read and check one level: a :class:`~.checks.CheckedLevel` (G scaled by h for ``h-L2``;
    for ``H`` the Gram of the described multipliers, :func:`.multiplier_gram.described_grams`)."""
    return _load_level(manifest, level)[0]


def declared_shape(path):
    """The (rows, cols) a matrix file's header declares, its body unread (MatrixMarket, .npy), or
    None (another format, or a header its reader will refuse with its own message)."""
    from .readers import _mtx_header, _npy_header, extension

    ext = extension(path)
    try:
        if ext in (".mtx", ".mtx.gz"):
            return _mtx_header(path, ext)[:2]
        if ext == ".npy":
            with open(path, "rb") as fh:
                shape = _npy_header(fh)[0]
            return shape if len(shape) == 2 else None
    except (OSError, ValueError, EOFError):  # SystemFileError too: read_matrix says it again
        return None
    return None


def check_declared_shapes(level) -> None:
    """A, B, G of one level against each other by their headers, before any body is read: a
    small file (a sparse .npy of 4 kB) can declare a 12000 x 12000 A that B does not fit."""
    from types import SimpleNamespace

    from .checks import check_shapes

    shapes = {key: None if p is None else declared_shape(p) for key, p in (("A", level.A), ("B", level.B),
                                                                           ("G", level.G))}
    if level.C is not None and shapes["B"] is not None and declared_shape(level.C) is not None:
        from .stabilised import check_c_shape

        check_c_shape(level, declared_shape(level.C), shapes["B"][0])
    if shapes["A"] is None or shapes["B"] is None:
        return
    G = shapes["G"] or (shapes["B"][0], shapes["B"][0])  # no G (norm H): the described Gram, m x m
    mats = [SimpleNamespace(shape=tuple(s)) for s in (shapes["A"], shapes["B"], G)]
    with transposed_b_hint(*mats):
        check_shapes(level if level.G is not None else SimpleNamespace(A=level.A, B=level.B, G=level.B), *mats)


def _load_level(manifest: Manifest, level):
    """(checked level, the L² mass of a ``norm: H`` level given as G or None, the H Gram's info)."""
    check_declared_shapes(level)
    A, B = (read_matrix(p) for p in (level.A, level.B))
    G = None if level.G is None else read_matrix(level.G)
    A = sp.csr_matrix(A) if not sp.issparse(A) else A
    B = sp.csr_matrix(B) if not sp.issparse(B) else B
    mass, info, m_read = None, None, B.shape[0]
    if level.multipliers is not None:
        from .multiplier_gram import described_grams

        level, B, G, mass, info = described_grams(manifest, level, B, G)
    with transposed_b_hint(A, B, G):
        checked = check_level(level, A, B, G, constrained_dofs(level, A.shape[0]), manifest.tgv,
                              True if manifest.gamma is not None else None)
    if info and info.get("removed_multipliers"):  # constrained rows the description's Gram left out
        checked.notes[:0] = info["notes"]
        checked.removed_multipliers += info["removed_multipliers"]
    if manifest.norm == "h-L2":
        checked.G = checked.G * level.h
    if level.C is not None:  # the rows the checks kept: B's as read, after the description's reordering
        from .stabilised import check_stabilisation

        kept = np.arange(B.shape[0]) if checked.kept_multipliers is None else checked.kept_multipliers
        kept = kept if info is None else np.asarray(info["kept"])[kept]  # in the rows of B as read
        checked.C = check_stabilisation(level, read_matrix(level.C), m_read, kept)
    return checked, mass, info


def system_rows(manifest: Manifest, route: str = "auto", notes=sys.stderr, modes: list | None = None) -> list:
    """One row per level: β_h, the kernel decision, the route and its residual. ``modes``: a list
    that receives each level's worst mode (:func:`level_mode`; the levels describe their multipliers)."""
    rows, shapes = [], []
    for level in progress.steps(manifest.levels, "level", lambda lv: f"h={lv.h:g}"):
        t0 = time.perf_counter()
        progress.note("reading A, B, G")
        lv, mass, info = _load_level(manifest, level)
        shapes.append((lv.A.shape[0] + lv.removed, lv.B.shape[0] + lv.removed_multipliers))
        check_sequence(manifest, shapes)
        t_read = time.perf_counter() - t0
        if manifest.known_kernel >= lv.B.shape[0]:
            raise SystemFileError(manifest.path, f"known_kernel = {manifest.known_kernel} >= m = {lv.B.shape[0]} "
                                  f"multipliers at levels[{level.index}]")
        progress.note(f"spectrum of B A^-1 B^T m = β² G m (m = {lv.B.shape[0]})")
        res = level_spectrum(lv.A, lv.B, lv.G, manifest.known_kernel, route, manifest.entry_rtol,
                             vectors=modes is not None, keep_schur=lv.C is not None)
        if modes is not None:
            modes.append(level_mode(manifest, level, lv, info, res))
        k = res.kernel
        if k.numerical < k.proven:
            raise SystemFileError(manifest.path, f"known_kernel = {k.proven}, but at levels[{level.index}] only "
                                  f"{k.numerical} singular values of the scaled B^T are <= eta = {k.tol:.2g}: the "
                                  "declared kernel is not a kernel of B^T")
        if res.roundoff.source != "exact":  # what η was raised by, and why
            lv.notes.append(f"{level.B.name}: {res.roundoff.evidence}")
        advice = close_advice(res) if k.decision == "close" else ""
        for note in lv.notes + ([advice] if advice else []):
            print(f"infsup-contact: note: {note}", file=notes)
        rows.append(dict(
            system=manifest.name, level=level.index, h=level.h, N2=1.0 / level.h, n=lv.A.shape[0], m=lv.B.shape[0],
            n_touched=res.n_touched, kernel_structural=max(lv.B.shape[0] - res.n_touched, 0),
            removed_dofs=lv.removed, removed_multipliers=lv.removed_multipliers, norm=manifest.norm,
            beta=res.beta, kernel_dim=k.dim, known_kernel=k.proven, kernel_detected=k.detected,
            kernel_margin_decades=k.margin_decades, kernel_decision=k.decision, kernel_tol=k.tol,
            entry_rtol_used=res.roundoff.rtol, entry_rtol_source=res.roundoff.source,
            pencil_margin_decades=res.pencil_margin, kernel_advice=advice, beta_uncertain=uncertain_beta(res),
            smallest_nonzero=res.smallest_nonzero, route=res.route, residual=res.residual,
            t_read=t_read, t_factorize=res.seconds.get("factorize", np.nan),
            t_eigen=res.seconds.get("eigen", np.nan), t_kernel=res.seconds["kernel"],
            notes="; ".join(lv.notes)))
        if lv.C is not None:  # β_C = λ_min(B A⁻¹ Bᵀ + C, G)^1/2 on the same route (module .stabilised)
            from .stabilised import stabilised_columns, stabilised_spectrum

            progress.note("spectrum of (B A^-1 B^T + C) m = β_C² G m")
            rows[-1].update(stabilised_columns(stabilised_spectrum(lv.A, lv.B, lv.G, lv.C, res.route,
                                                                   float(k.singular[-1]) ** 2, res.schur)))
        if info is not None:  # described: B's distance to the exact coupling of described traces
            rows[-1]["coupling_distance"] = info["coupling_distance"]
        if info is not None and "description_check" in info:  # norm H: what checked the description
            rows[-1]["description_check"] = info["description_check"]
            if info["description_check"] == "none":
                rows[-1]["notes"] = "; ".join(filter(None, [rows[-1]["notes"], UNCHECKED.format(i=level.index)]))
                print(f"infsup-contact: note: {UNCHECKED.format(i=level.index)}", file=notes)
        if manifest.norm == "H":  # the Gram's stated error, and the L2 row beside it where G is given
            rows[-1]["gram_rel_error"] = info["nmax_rel_error"]
            l2 = (level_spectrum(lv.A, lv.B, mass, manifest.known_kernel, route)
                  if mass is not None and mass.shape[0] == lv.B.shape[0] else None)
            rows[-1].update(beta_L2=np.nan if l2 is None else l2.beta,
                            smallest_nonzero_L2=np.nan if l2 is None else l2.smallest_nonzero)
    return rows


def level_mode(manifest: Manifest, level, lv, info: dict, res):
    """The worst mode of one level (``res.mode``, in the rows of B the checks kept) as a
    :class:`~infsup_contact.solvers.modes.Mode` of the described basis: row r of B as read holds
    basis function j with ``rows[j] = r``; a multiplier the producer constrained is 0."""
    from ..solvers.modes import Mode

    described = info["described"]
    rows = np.zeros(described.m)
    kept = info["kept"] if lv.kept_multipliers is None else info["kept"][lv.kept_multipliers]
    rows[kept] = res.mode
    keys = dict(system=manifest.name, level=level.index, h=level.h, norm=manifest.norm)
    gamma = described.gamma.interface  # the manifest's Γ, pulled back
    size = described.gamma.size if len(described.gamma.size) == 2 else described.gamma.size * 2
    return Mode(keys, res.beta, rows[described.rows], res.kernel.detected > 0, described.space, gamma, size)


def uncertain_beta(res) -> float:
    """√λ of the pencil mode whose count a ``close`` kernel decision leaves open — the last mode
    counted zero (the zero side) or the first counted non-zero (the other side; both if both are
    close) — the largest of them; NaN where it was not computed (the shift-invert route sets
    the kernel's eigenvalues to 0 without computing them) or where the open count is that of
    the declared kernel.

    If it is below the verdict's β floor, the decision cannot change the verdict: counted as
    kernel the level is UNSTABLE (an undeclared kernel), counted non-zero its β_h is that
    value, below the floor, and the series is UNSTABLE by the floor (:func:`system_verdict`)."""
    k = res.kernel
    if k.decision != "close" or res.route == "shift-invert":
        return np.nan
    d, s, ev = k.dim, np.asarray(k.singular, float), np.asarray(res.bottom, float)
    margin = 10.0 ** MARGIN_DECADES
    sides = []
    if d >= 1 and (s[d - 1] <= 0 or k.tol / s[d - 1] < margin):
        sides.append(d - 1)
    if d < len(s) - 1 and (s[d] / k.tol < margin or res.pencil_margin < MARGIN_DECADES):
        sides.append(d)
    if not sides:  # the decision's own margin did not say which: both neighbours of the count
        sides = [i for i in (d - 1, d) if 0 <= i]
    if min(sides) < k.proven or max(sides) >= len(ev):
        return np.nan
    return float(max(np.sqrt(max(ev[i], 0.0)) for i in sides))


def system_verdict(manifest: Manifest, *, tol: float, floor: float, confidence: float, route: str = "auto",
                   notes=None, modes: list | None = None) -> tuple:
    """(verdict row, level rows). The criterion of ``verdict --case``
    (:func:`~infsup_contact.criteria.stability.stability_verdict`) on the kernel *beyond* the
    declared one: a kernel of Bᵀ larger than ``known_kernel`` on any level is UNSTABLE; a
    ``close`` kernel decision on any level makes the verdict INCONCLUSIVE (both by
    ``stability_verdict`` itself), the evidence saying what the user can do. η includes the
    round-off of B's entries, declared (``entry_rtol``) or estimated (:mod:`.roundoff`). Its
    ``hints`` (:mod:`.hints`, also on ``notes``) say what mistake the numbers suggest. ``modes``: a
    list that receives each level's worst mode (:func:`system_rows`; the levels describe their
    multipliers)."""
    t0 = time.perf_counter()
    notes = sys.stderr if notes is None else notes  # the stream of now (a default would bind import time's)
    rows = system_rows(manifest, route, notes, modes)
    immaterial = [r for r in rows if r["kernel_decision"] == "close" and r["beta_uncertain"] < floor]
    series = [dict(r, kernel_dim=r["kernel_detected"], case=manifest.name,
                   kernel_decision="clear" if r in immaterial else r["kernel_decision"]) for r in rows]
    out = stability_verdict(series, tol, floor, confidence)  # a close kernel decision: INCONCLUSIVE
    out["evidence"] = out["evidence"].replace("over N = ", "over 1/h = ").replace("(N = ", "(1/h = ")
    if manifest.norm == "H" and all(np.isfinite(r["beta_L2"]) for r in rows):  # the given L2 mass, for comparison
        l2 = stability_verdict([dict(r, beta=r["beta_L2"], smallest_nonzero=r["smallest_nonzero_L2"]) for r in series],
                               tol, floor, confidence)
        out.update(verdict_L2=l2["verdict"], beta_min_L2=l2["beta_min"], slope_L2=l2["slope"])
    if any(np.isfinite(r.get("coupling_distance", np.nan)) for r in rows):
        out["coupling_distance_max"] = float(np.nanmax([r.get("coupling_distance", np.nan) for r in rows]))
    if out["verdict"] == "UNSTABLE" and out["kernel_dim"] > 0:  # name the kernel nobody declared
        dims = [r["kernel_detected"] for r in rows]
        structural = [r["kernel_structural"] for r in rows]
        inv_h = ", ".join(f"{1 / r['h']:g}" for r in rows)
        out["evidence"] = (f"β_h = 0: a kernel of B^T not declared (known_kernel: {manifest.known_kernel}) "
                           f"of dim {dims} over 1/h = {inv_h}"
                           + (f"; B has more rows than the dofs it touches (m - touched = {structural})"
                              if any(structural) else "")
                           + "; slope of the eigenvalue above the kernel; " + _kernel_advice(manifest, rows))
    unchecked = [r["level"] for r in rows if r.get("description_check") == "none"]
    if unchecked and not (out["verdict"] == "UNSTABLE" and out["kernel_dim"] > 0):  # a kernel of B^T needs no G
        out["verdict"] = "INCONCLUSIVE"
        out["evidence"] += "; " + UNCHECKED.format(i=", ".join(map(str, unchecked)))
    if immaterial:
        out["evidence"] += "; " + "; ".join(
            f"levels[{r['level']}]: kernel decision close, but the mode in question has beta {r['beta_uncertain']:.2g} "
            f"<= floor {floor:g}: UNSTABLE whichever way it is counted" for r in immaterial)
    close = [r for r in rows if r["kernel_decision"] == "close" and r not in immaterial]
    if out["verdict"] == "INCONCLUSIVE" and close:
        out["evidence"] += f"; levels[{close[0]['level']}]: {close[0]['kernel_advice']}"
    if all("beta_C" in r for r in rows):  # a stabilised system: the unstabilised verdict stays in "verdict"
        from .stabilised import stabilisation_verdict

        out.update(stabilisation_verdict(rows, out, tol=tol, floor=floor, confidence=confidence))
    head = dict(system=manifest.name, norm=manifest.norm, known_kernel=manifest.known_kernel)
    head.update(out)
    head["hints"] = "; ".join(system_hints(rows, out, tol, confidence, notes))  # the verdict unchanged
    head.update(h_list=" ".join(f"{r['h']:g}" for r in rows), routes=" ".join(sorted({r["route"] for r in rows})),
                max_residual=max(r["residual"] for r in rows), norm_note=NORM_NOTES[manifest.norm],
                seconds=time.perf_counter() - t0)
    return head, rows


def _kernel_advice(manifest: Manifest, rows) -> str:
    """What to do about an undeclared kernel: for a contact coupling (the manifest's ``gamma``, or B
    on an interface, :data:`~.checks.INTERFACE_TOUCHED`) the kernel is the instability itself — a
    multiplier no displacement sees — so it is to be removed from the space, not declared; for a
    whole-body coupling (Stokes) it may be a known one (a constant pressure)."""
    from .checks import INTERFACE_TOUCHED

    if manifest.gamma is not None or all(r["n_touched"] <= INTERFACE_TOUCHED * r["n"] for r in rows):
        return ("for contact multipliers a kernel of B^T is the instability (multipliers no displacement "
                "sees), not a constant to declare with known_kernel: remove it from the multiplier space (drop "
                "the multipliers at Gamma's Dirichlet ends, as T3 does, or coarsen the multiplier mesh)")
    return "declare the kernel with known_kernel if it is meant (e.g. a constant pressure of an enclosed flow)"


def dry_check(manifest: Manifest, route: str = "auto"):
    """What ``--dry-run`` and every run check before computing: each file readable, finite,
    the shapes of each level and between levels, and the memory estimate
    (:func:`infsup_contact.resources.system_estimate`)."""
    from .. import resources
    from .checks import check_finite, check_shapes
    from .engine import choose_route, touched_dofs

    sizes, shapes = [], []
    extra = extra_c = 0.0  # the described Gram's bytes, C's (both held beside the route's blocks)
    for level in manifest.levels:  # every level's headers before any body is read
        check_declared_shapes(level)
    for level in manifest.levels:
        mats = [None if p is None else read_matrix(p) for p in (level.A, level.B, level.G)]
        for mat, path in zip(mats, (level.A, level.B, level.G)):
            if mat is not None:
                check_finite(mat, path)
        A, B, G = mats
        if level.multipliers is not None:  # the description read, its Gram's memory counted (never made here)
            from .multiplier_gram import check_description

            level, G, bytes_, _ = check_description(manifest, level, B, G)
            extra = max(extra, bytes_)
        with transposed_b_hint(A, B, G):
            check_shapes(level, A, B, G)
        constrained_dofs(level, A.shape[0])
        shapes.append((A.shape[0], B.shape[0]))
        check_sequence(manifest, shapes)
        nt = len(touched_dofs(sp.csr_matrix(B)))
        r = choose_route(A.shape[0], B.shape[0], nt, sp.issparse(G)) if route == "auto" else route
        sizes.append((A.shape[0], B.shape[0], nt, sp.csr_matrix(A).nnz, r))
        if level.C is not None:  # checked as a run checks it; its memory beside the route's
            from .stabilised import check_stabilisation, stabilised_bytes

            kept = None
            if G is not None and level.multipliers is None:  # the multiplier rows the run keeps (checks)
                from .checks import constrained_multipliers

                kept = np.setdiff1d(np.arange(B.shape[0]), constrained_multipliers(level, B, G, manifest.tgv)[0])
            C = check_stabilisation(level, read_matrix(level.C), B.shape[0], kept, penalty=level.multipliers is None)
            extra_c = max(extra_c, stabilised_bytes(C, r))
    est = resources.system_estimate(sizes)
    extra += extra_c
    seconds = 2.0 * est.seconds if extra_c else est.seconds  # β_C: the route's factorization and pencil again
    return resources.Estimate(est.bytes + extra, seconds) if extra else est
