"""``infsup-contact rates``: convergence rates fitted on a contact table (CSV in, CSV out)."""
from __future__ import annotations

from ..errors import InputError
from ..io import TableError
from .common import add_dry_run, declare_flag_uses, write_csv
from .verdict_formats import add_table_output, force_use


def add(sub) -> None:
    p = sub.add_parser("rates", help="fit convergence rates of a contact table (CSV in, CSV out)")
    p.add_argument("table", help="CSV written by `infsup-contact contact` or the workflow; - for standard input")
    p.add_argument("--window", type=int, default=3,
                   help="number of finest meshes in the fit (2 .. the meshes of the shortest series)")
    add_table_output(p)
    add_dry_run(p)
    declare_flag_uses(p, [force_use()])  # every other flag of rates is used by every request
    p.set_defaults(run=_run_rates, check=_check_rates)


def _check_rates(args):
    from .. import resources
    from ..io import read_table
    from ..study.contact.rates import check_rate_input, series_sizes

    if args.window < 2:
        raise InputError("window", "an integer >= 2", got=args.window)
    frame = read_table(args.table, "contact_input")  # read once: `-` and /dev/stdin are pipes
    name = "<stdin>" if args.table == "-" else args.table
    check_rate_input(frame, name)
    if not (frame.N1 == frame.N2).any():
        raise TableError(name, "no rows with N1 = N2 (rates are fitted over matching meshes)")
    sizes = series_sizes(frame)
    if args.window > sizes.min():
        key = sizes.idxmin()
        key = key if isinstance(key, tuple) else (key,)
        raise InputError("window", f"at most {sizes.min()}: the series {'/'.join(str(v) for v in key if v == v)} of "
                         f"{name} has {sizes.min()} meshes (a window is never shrunk silently)",
                         got=args.window)
    args.frame, args.name = frame, name
    return resources.Estimate(resources.PROCESS_BYTES["beta"], resources.START_SECONDS)


def _run_rates(args) -> None:
    from ..study.contact.rates import rate_table

    write_csv(rate_table(args.frame, args.window, args.name), float_format="%.6g", output=args.output)
