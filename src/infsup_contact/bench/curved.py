"""What a curved Γ costs: β_h on the arc (``bench --what arc``, results/benchmarks/arc.csv).

Per (N, N + 1) pair and k, one run interleaves (:func:`~.harness.run_interleaved`):

``flat``
    β_h of every registered space on the paper's segment (the reference);
``exact``, ``projection``
    the same on the arc of radius R with each coupling (:mod:`infsup_contact.discretization.segment.arc`):
    the meshes curved at the bodies' degree, the couplings, the pencils;
``couplings_exact``, ``couplings_projection``
    only the couplings B_i of every space on the pair's built sides (the projection's own cost:
    the slave's curve, the master points, the longer rule), basis caches emptied before each;
``limit``
    one sparse factorization of the larger body's stiffness (SuperLU, its best order): no β_h
    route can be cheaper than factorizing the bodies once.

Columns: ``ratio_to_limit`` (route / limit) and ``ratio_to_exact`` (route / the same work with the
exact coupling: the projection's price).
"""
from __future__ import annotations

import numpy as np

from ..discretization.gamma.coupling import coupling_matrix
from ..discretization.spaces import registry
from ..models.membranes import MEMBRANES, displacement_space, laplace_stiffness
from ..solvers.infsup import beta_table
from ..solvers.request import BetaRequest, resolve_gamma
from ..solvers.side_cache import SideCache
from .beta_bench import splu_best_order
from .harness import _log, _stats, run_interleaved

COLUMNS = ("what", "route", "radius", "k", "N1", "N2", "seconds_median", "seconds_min", "seconds_max",
           "ratio_to_limit", "ratio_to_exact", "repeats", "n_problems", "max_abs_diff_to_flat")


def _gamma(radius: float, coupling: str | None):
    """The request's Γ: the arc of ``radius`` with ``coupling``; None (coupling None): the flat segment."""
    return None if coupling is None else resolve_gamma(MEMBRANES, gamma="arc", radius=float(radius), coupling=coupling)


def _betas(k, n1, n2, cases, gamma):
    return beta_table(BetaRequest("structured", k, n1, n2, tuple(cases), norms=("H",), gamma=gamma))


def _couplings(k, n1, n2, cases, gamma):
    sides = SideCache().pair(MEMBRANES, "structured", k, n1, n2, gamma=gamma)
    gamma = sides[0].trace.gamma
    g_h = gamma.multiplier_partition(*(s.trace.partition for s in sides), "omega2")
    spaces = [registry.case_space(c, k, g_h, gamma) for c in cases]

    def run():
        for s in sides:
            s.trace.forget_basis()
        return [coupling_matrix(s.trace, space, k) for space in spaces for s in sides]
    return run


def _limit(k, n, radius):
    body = MEMBRANES.subdomain_mesh("structured", n, 2, gamma=_gamma(radius, "exact"))
    body.interface.curve(body.mesh, k)
    fes = displacement_space(body.mesh, k)
    K = laplace_stiffness(fes)
    free = np.flatnonzero(np.array(fes.FreeDofs(), dtype=bool))
    K = K[free][:, free].tocsc()
    return lambda: splu_best_order(K)


def curved_rows(ns, ks, radius: float = 2.0, repeats: int = 3, budget: float = 10.0) -> list:
    """The rows of the module docstring for every N of ``ns`` (the pair N : N + 1) and k of ``ks``."""
    rows = []
    for k in ks:
        cases = registry.common_ids(k)
        for n in ns:
            n1, n2 = n, n + 1
            routes = {"limit": _limit(k, max(n1, n2), radius)}
            routes.update({name: (lambda c=coupling: _betas(k, n1, n2, cases, _gamma(radius, c)))
                           for name, coupling in (("flat", None), ("exact", "exact"), ("projection", "projection"))})
            routes.update({f"couplings_{c}": _couplings(k, n1, n2, cases, _gamma(radius, c))
                           for c in ("exact", "projection")})
            _log(f"arc k={k} N={n1}:{n2} R={radius:g}: {', '.join(routes)}")
            _betas(k, min(n1, 4), min(n1, 4) + 1, cases, _gamma(radius, "projection"))  # one-time start-up: untimed
            out = run_interleaved(routes, repeats, budget)
            flat = np.array([r["beta"] for r in out["flat"][0]])
            limit = _stats(out["limit"][1])[0]
            for name, (result, times) in out.items():
                med, lo, hi = _stats(times)
                ref = {"projection": "exact", "couplings_projection": "couplings_exact"}.get(name, name)
                diff = (np.abs(np.array([r["beta"] for r in result]) - flat).max()
                        if name in ("flat", "exact", "projection") else np.nan)
                rows.append(dict(what="arc", route=name, radius=np.inf if name == "flat" else radius, k=k, N1=n1,
                                 N2=n2, seconds_median=med, seconds_min=lo, seconds_max=hi,
                                 ratio_to_limit=med / limit, ratio_to_exact=med / _stats(out[ref][1])[0],
                                 repeats=len(times), n_problems=len(cases), max_abs_diff_to_flat=diff))
    return rows
