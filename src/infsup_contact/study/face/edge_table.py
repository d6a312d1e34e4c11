"""Edge dropping: β_h and the conditioning of the multiplier block when Ω2's
face covers Ω1's only partially — the table: a whole request checked before anything is computed
(:func:`edge_plan`), its rows (:func:`edge_table`, one :func:`~.edge_dropping.edge_row` each) and
the command line ``python -m infsup_contact.study.face.edge_table``.
"""
from __future__ import annotations

import csv
import sys

import numpy as np

from ...discretization.face.spaces.clipped import SLIVER_MIN
from ...discretization.spaces import registry
from ...discretization.spaces.registry import edge_cases
from ...errors import InputError
from .edge_dropping import THETAS, check_theta, edge_row

COLUMNS = ("case", "k", "N", "N2", "theta", "L", "dim_M", "dropped", "kappa_min", "beta_H", "beta_L2",
           "cond_D", "cond_D_kappa", "cond_D_unit", "cond_S", "cond_S_kappa", "cond_S_unit", "cond_G",
           "cond_G_kappa", "cond_G_unit", "beta_route", "beta_H_resolved", "beta_L2_resolved", "beta_L2_kappa", "beta_L2_kappa_resolved", "n_max",
           "h_rel_error", "h_capped")


NORMS = ("H", "L2")


def edge_plan(ks, ns, thetas, cases=None, n2_factor: int = 2, norms=NORMS, h_cap: int | None = None,
              explicit: bool = False) -> list:
    """Check a whole request before anything is computed and return ``[(k, cases of k)]``.

    ``cases``: a filter of :func:`edge_cases` (the config's ``membranes3d.cases``), or with ``explicit``
    the spaces to run for every k (``--case``: any space with a 1D factor defined for k). Each
    bad value raises one :class:`InputError` naming its key (``k``, ``N``, ``theta``, ``case``,
    ``n2_factor``, ``norm``, ``h_cap``) and the allowed values; a k without a space to run is
    refused (never a table of its header only)."""
    ks, ns, thetas, norms = list(ks), list(ns), list(thetas), list(norms)
    for key, values in (("k", ks), ("N", ns), ("theta", thetas), ("norm", norms)):
        if not values:
            raise InputError(key, "at least one value", got=values)
    for n in ns:
        if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 1:
            raise InputError("N", "integers >= 1 (Ω1's cells per direction)", got=n)
    if not isinstance(n2_factor, (int, np.integer)) or isinstance(n2_factor, bool) or n2_factor < 1:
        raise InputError("n2_factor", "an integer >= 1 (N2 = factor · N)", got=n2_factor)
    for th in thetas:
        check_theta(th, max(ns))
    for norm in norms:
        if norm not in NORMS:
            raise InputError("norm", ", ".join(NORMS), got=norm)
    if h_cap is not None and (not isinstance(h_cap, (int, np.integer)) or h_cap < 1):
        raise InputError("h_cap", "an integer >= 1 (the largest n_max of the H series)", got=h_cap)
    with_cases = [k for k in range(1, 5) if edge_cases(k)]
    plan = []
    for k in ks:
        if not isinstance(k, (int, np.integer)) or isinstance(k, bool) or k not in range(1, 5):
            raise InputError("k", f"a degree with an edge case: {', '.join(map(str, with_cases))}", got=k)
        if explicit:
            allowed = registry.common_ids(k)
            for c in cases:
                if c not in allowed:
                    raise InputError("case", f"a registered space with a 1D factor defined for k = {k}: "
                                     f"{', '.join(allowed)}", got=c)
            run = list(cases)
        else:
            run = [c for c in edge_cases(k) if cases is None or c in cases]
        if not run:
            among = [j for j in range(1, 5) if any(cases is None or c in cases for c in edge_cases(j))]
            raise InputError("k", f"a degree with an edge case{' among the cases' if cases is not None else ''}: "
                             f"{', '.join(map(str, among)) or 'none'} (k = {k}: {', '.join(edge_cases(k)) or 'no edge case'})",
                             got=k)
        plan.append((int(k), run))
    return plan


def edge_table(ks=(1,), ns=(4, 8), thetas=THETAS, cases=None, n2_factor: int = 2, norms=NORMS,
               h_cap: int | None = None):
    """Rows of :func:`edge_row` for every k, N (N2 = ``n2_factor`` N: a primary side fine enough
    that B2 has full row rank for the continuous spaces of Ω1's face), θ and case (θ before the
    case: the side operators of one θ serve every space); the cases are :func:`edge_cases` of
    each k, those among ``cases`` when given (e.g. the config's ``membranes3d.cases``). The whole
    request is checked first (:func:`edge_plan`)."""
    plan = edge_plan(ks, ns, thetas, cases, n2_factor, norms, h_cap)
    return [edge_row(c, k, n, n2_factor * n, th, norms, h_cap=h_cap)
            for k, run in plan for n in ns for th in thetas for c in run]


def main(argv=None) -> int:
    """``python -m infsup_contact.study.face.edge_table --k 1 2 --N 4 8``: the table as CSV on stdout;
    bad input is one line on stderr naming the flag, exit 2, before any row."""
    from ...command_line import OneLineParser, run_study

    ap = OneLineParser(prog="python -m infsup_contact.study.face.edge_table", description=__doc__.splitlines()[0])
    ap.add_argument("--k", type=int, nargs="+", default=[1],
                    help="displacement degrees with an edge case (1..4; default 1)")
    ap.add_argument("--N", type=int, nargs="+", default=[4, 8])
    ap.add_argument("--theta", type=float, nargs="+", default=list(THETAS),
                    help=f"covered fractions, {SLIVER_MIN:g}·N <= θ <= 1")
    ap.add_argument("--case", nargs="+", default=None, help="registered face spaces (default: edge_cases(k))")
    ap.add_argument("--n2-factor", type=int, default=2, help="N2 = factor * N (Ω2's cells per direction)")
    ap.add_argument("--norm", nargs="+", default=list(NORMS), choices=NORMS)
    ap.add_argument("--h-cap", type=int, default=None,
                    help="largest n_max of the H series (default 8192; θ = 0.001 needs more, see h_capped)")

    def check(a):
        a.plan = edge_plan(a.k, a.N, a.theta, a.case, a.n2_factor, a.norm, a.h_cap, explicit=a.case is not None)

    def run(a):
        out = csv.DictWriter(sys.stdout, COLUMNS, extrasaction="ignore")
        out.writeheader()
        for k, cases in a.plan:
            for n in a.N:
                for th in a.theta:
                    for c in cases:
                        out.writerow(edge_row(c, k, n, a.n2_factor * n, th, tuple(a.norm), h_cap=a.h_cap))
                        sys.stdout.flush()

    return run_study(ap, argv, check, run)


if __name__ == "__main__":
    raise SystemExit(main())
