"""Speed against accuracy: wall time of contact solves next to their errors, and the Pareto front."""
from __future__ import annotations

import time

import numpy as np

from ..study.contact.registry import MANUFACTURED
from .harness import _log, _stats, run_interleaved


def pareto_front(times, errors) -> np.ndarray:
    """Boolean mask of the Pareto-optimal points when minimizing both time and error.

    A point is on the front iff no other point is at least as fast and at least as
    accurate and strictly better in one of the two. Points with a non-finite time or
    error are never on the front and dominate nothing; exact duplicates are both kept.
    """
    t = np.asarray(times, dtype=float).reshape(-1)
    e = np.asarray(errors, dtype=float).reshape(-1)
    if t.shape != e.shape:
        raise ValueError(f"times and errors differ in length: {t.shape} vs {e.shape}")
    ok = np.isfinite(t) & np.isfinite(e)
    mask = np.zeros(t.shape, dtype=bool)
    for i in np.flatnonzero(ok):
        dominated = ok & (t <= t[i]) & (e <= e[i]) & ((t < t[i]) | (e < e[i]))
        mask[i] = not dominated.any()
    return mask


def time_contact_solves(cases, k: int, n: int, repeats: int = 3, scene: str = MANUFACTURED.id,
                        family: str = "structured", scene_params: dict | None = None, c=(1.0, 1.0),
                        budget: float = np.inf) -> dict:
    """Wall time of a whole contact solve (:func:`~infsup_contact.contact.contact.solve_contact`,
    no floor timing) for each case on the matching pair N1 = N2 = ``n``, timed in two parts.

    A solve is the build of the pair (meshes, side factorizations, loads:
    :func:`~infsup_contact.contact.contact.contact_pair`), which no multiplier space changes,
    and the case's own part on it (:func:`~infsup_contact.contact.contact.solve_contact_on`:
    space, couplings, interface operator, PDAS, recovery). The build is timed once for all
    cases; each case's part starts from the state a fresh build leaves (nothing an earlier
    case cached on the sides, :meth:`~infsup_contact.models.contract.SideOperator.forget_cached`).
    Each part is repeated up to ``repeats`` times while its accumulated time is below
    ``budget`` seconds.

    Returns
    -------
    {case: (median, min, max, runs)}
        Seconds of build + case part: median(build) + median(part), likewise min and max;
        ``runs``: how often the case's part ran.
    """
    from ..contact.contact import contact_pair, solve_contact_on
    from ..study.contact.scenes import scene as make_scene

    sc = make_scene(scene, c1=c[0], c2=c[1], **(scene_params or {}))
    pair, build = run_interleaved({"build": lambda: contact_pair(sc, k, family, n, n)}, repeats, budget)["build"]

    def part(case):
        for side in pair.sides:
            side.forget_cached()
        t = time.perf_counter()
        solve_contact_on(pair, case, time_floor=False)
        return time.perf_counter() - t

    parts = run_interleaved({case: lambda case=case: part(case) for case in cases}, repeats, budget,
                            self_timed=tuple(cases))
    b = _stats(build)
    return {case: (*(x + y for x, y in zip(b, _stats(times))), len(times)) for case, (_, times) in parts.items()}


def speed_accuracy_table(errors, repeats: int = 3, timing_scene: str = MANUFACTURED.id,
                         timing_params: dict | None = None, c=(1.0, 1.0), budget: float = np.inf):
    """Speed–accuracy points: the errors of every (scene, case, k, N) with wall times.

    Parameters
    ----------
    errors : pandas.DataFrame
        Contact rows (``infsup-contact contact`` / ``results/tables/contact.csv``) with
        scene, case, k, family, N1, N2, energy_error, lambda_hm12_error; matching meshes
        (N1 = N2) are used.
    repeats : timing repetitions (median reported).
    budget : each timed part of a solve (:func:`time_contact_solves`: the pair's build, shared by
        the cases of one (k, N), and each case's own part) is repeated only while its
        accumulated time is below this many seconds (the column ``repeats`` says how often
        the case's part ran).
    timing_scene, timing_params : the scene whose solves are timed; the cost of a
        discretization (case, k, family, N) does not depend on the load, so one timing
        serves every scene.

    Returns
    -------
    pandas.DataFrame with scene, case, k, family, N, seconds (median), seconds_min,
    seconds_max, energy_error, lambda_hm12_error, ndof, dim_M, pareto_energy,
    pareto_lambda (Pareto front per scene and family).
    """
    import pandas as pd

    frame = errors[errors.N1 == errors.N2].copy()
    frame["N"] = frame.N1.astype(int)
    cases = {}
    for r in frame.itertuples():
        cases.setdefault((r.family, int(r.k), int(r.N)), set()).add(r.case)
    timing = {}
    for (family, k, n), cs in sorted(cases.items()):
        for case, t in time_contact_solves(sorted(cs), k, n, repeats, timing_scene, family, timing_params,
                                           c, budget).items():
            timing[case, k, family, n] = t
            _log(f"speed-accuracy {family} {case} k={k} N={n}: {t[0]:.4f} s")
    t = np.array([timing[r.case, int(r.k), r.family, int(r.N)] for r in frame.itertuples()])
    frame["seconds"], frame["seconds_min"], frame["seconds_max"] = t[:, 0], t[:, 1], t[:, 2]
    frame["timing_scene"], frame["repeats"] = timing_scene, t[:, 3].astype(int)
    cols = ["scene", "case", "k", "family", "N", "seconds", "seconds_min", "seconds_max",
            "energy_error", "lambda_hm12_error"]
    cols += [c_ for c_ in ("ndof", "dim_M", "cone", "nonunique", "kernel_dim") if c_ in frame.columns]
    out = frame[cols + ["timing_scene", "repeats"]].reset_index(drop=True)
    out["pareto_energy"] = False
    out["pareto_lambda"] = False
    for _, g in out.groupby(["scene", "family"]):
        out.loc[g.index, "pareto_energy"] = pareto_front(g.seconds, g.energy_error)
        out.loc[g.index, "pareto_lambda"] = pareto_front(g.seconds, g.lambda_hm12_error)
    return pd.DataFrame(out).sort_values(["scene", "family", "k", "case", "N"]).reset_index(drop=True)


def fastest_for_accuracy(table, error: str = "energy_error"):
    """Per scene: the Pareto-front rows (ascending time), i.e. for every accuracy level
    the cheapest discretization reaching it."""
    flag = "pareto_energy" if error == "energy_error" else "pareto_lambda"
    return table[table[flag]].sort_values(["scene", "seconds"])
