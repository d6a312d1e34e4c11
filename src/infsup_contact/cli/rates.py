"""``infsup-contact rates``: convergence rates fitted on a contact table (CSV in, CSV out)."""
from __future__ import annotations

import sys

from ..errors import InputError
from ..io import TableError
from .common import add_dry_run


def add(sub) -> None:
    p = sub.add_parser("rates", help="fit convergence rates of a contact table (CSV in, CSV out)")
    p.add_argument("table", help="CSV written by `infsup-contact contact` or the workflow")
    p.add_argument("--window", type=int, default=3,
                   help="number of finest meshes in the fit (2 .. the meshes of the shortest series)")
    add_dry_run(p)
    p.set_defaults(run=_run_rates, check=_check_rates)


def _check_rates(args):
    from .. import resources
    from ..io import read_table

    if args.window < 2:
        raise InputError("window", "an integer >= 2", got=args.window)
    frame = read_table(args.table, "contact_input")
    matching = frame[frame.N1 == frame.N2]
    if matching.empty:
        raise TableError(args.table, "no rows with N1 = N2 (rates are fitted over matching meshes)")
    sizes = matching.groupby(["scene", "case", "k", "family"]).N2.nunique()
    if args.window > sizes.min():
        key = sizes.idxmin()
        raise InputError("window", f"at most {sizes.min()}: the series {'/'.join(map(str, key))} of "
                         f"{args.table} has {sizes.min()} meshes (a window is never shrunk silently)",
                         got=args.window)
    args.frame = frame
    return resources.Estimate(resources.PROCESS_BYTES["beta"], resources.START_SECONDS)


def _run_rates(args) -> None:
    from ..study.rates import rate_table

    rate_table(args.frame, args.window).to_csv(sys.stdout, index=False, float_format="%.6g")
