"""``infsup-contact bench``: speed as ratios in one run (β_h of a model or contact routes, CSV)."""
from __future__ import annotations

from ..errors import InputError
from .common import FlagUse, add_dry_run, check_memory, declare_flag_uses, write_csv
from .common import is_stream
from .verdict_formats import add_table_output, force_use, output_path


def add(sub) -> None:
    p = sub.add_parser("bench", help="speed as ratios in one run (CSV)")
    p.add_argument("--what", required=True, choices=["beta", "contact", "face", "elastic", "arc"],
                   help="beta / contact: the 2D membranes; face: β_h of the 3D membranes (--model membranes3d); "
                        "elastic: β_h of the plane-strain bodies (--model elastic); arc: β_h on the curved "
                        "segment, both couplings, beside the flat one (pairs N:N+1)")
    p.add_argument("--N", type=int, nargs="+", required=True)
    p.add_argument("--k", type=int, nargs="+", required=True)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--peers", nargs="*", default=["osqp", "clarabel"],
                   help="contact: QP solvers to compare with (osqp, clarabel; none: omit)")
    p.add_argument("--eigsh-max-N", dest="eigsh_max_n", type=int, default=None,
                   help="beta: run the shift-invert Lanczos route only for N <= this")
    p.add_argument("--kkt-max-N", dest="kkt_max_n", type=int, default=64,
                   help="contact: run the sparse-KKT active-set route only for N <= this")
    p.add_argument("--dense-max-size", dest="dense_max_size", type=int, default=2500,
                   help="beta: run the dense eigh route only while the pencil has at most this many rows")
    p.add_argument("--route-budget", dest="route_budget", type=float, default=None,
                   help="seconds: a route is repeated (up to --repeats) only while its accumulated "
                        "time is below this, so slow routes run once (default 10)")
    p.add_argument("--element", default=None,
                   help="face: the 3D bodies' elements (hex, tet; default hex)")
    p.add_argument("--nu", type=float, default=None, help="elastic: Poisson ratio of both bodies (default 0.3)")
    p.add_argument("--radius", type=float, default=None, help="arc: the radius R > 1 of Γ (default 2)")
    p.add_argument("--case", nargs="+", default=None,
                   help="elastic: the space ids to run, each where defined for k (default every registered one)")
    p.add_argument("--phases", default=None, metavar="FILE", type=output_path,
                   help="face: also write where one end-to-end run's time goes, per phase (CPU s, wall s, "
                        "CPU %%, share; CSV), to FILE")
    add_table_output(p)
    add_dry_run(p)
    declare_flag_uses(p, [*FLAG_USES, force_use()])
    p.set_defaults(run=_run_bench, check=_check_bench)


def _what(*whats):
    return lambda args: args.what in whats


FLAG_USES = [FlagUse(dest, _what(what), f"--what {what}", lambda a: f"--what {a.what}")
             for dest, what in (("peers", "contact"), ("kkt_max_n", "contact"), ("eigsh_max_n", "beta"),
                                ("dense_max_size", "beta"), ("element", "face"), ("nu", "elastic"),
                                ("case", "elastic"), ("radius", "arc"), ("phases", "face"))]
"""The flags of ``bench`` only one ``--what`` uses (:func:`~.common.refuse_unused`)."""


def _check_bench(args):
    from .. import resources
    from ..bench.peers import SOLVERS

    for key, values, ok, allowed in (("N", args.N, lambda n: n >= 1, "integers >= 1"),
                                     ("k", args.k, lambda k: 1 <= k <= 4, "integers in 1..4")):
        for v in values:
            if not ok(v):
                raise InputError(key, allowed, got=v)
        if len(set(values)) < len(values):
            raise InputError(key, f"{allowed}, each once", got=" ".join(map(str, values)))
    from ..discretization.spaces.registry import check_pair_spaces, common_ids

    TARGET_CHECKS.get(args.what, lambda _: None)(args)  # a target's own flags
    if args.phases is not None and (args.phases == "-" or is_stream(args.phases)):
        raise InputError("phases", "a file name to write (the table goes to stdout or --output)", got=args.phases)
    for k in args.k:  # every registered space defined for k: a superset of what the routes run
        for n in args.N:
            check_pair_spaces(common_ids(k), k, n, n, key="N")
    if args.repeats < 1:
        raise InputError("repeats", "an integer >= 1", got=args.repeats)
    from ..bench.harness import ROUTE_BUDGET

    args.route_budget = ROUTE_BUDGET if args.route_budget is None else args.route_budget
    if not args.route_budget >= 0 or args.route_budget == float("inf"):
        raise InputError("route_budget", "a finite number of seconds >= 0", got=args.route_budget)
    if args.dense_max_size < 0:
        raise InputError("dense_max_size", "an integer >= 0 (0: never)", got=args.dense_max_size)
    for key in ("eigsh_max_n", "kkt_max_n"):
        value = getattr(args, key)
        if value is not None and value < 0:
            raise InputError(key, "an integer >= 0 (0: never)", got=value)
    args.peer_list = [p for p in args.peers if p != "none"]
    for p in args.peer_list:
        if p not in SOLVERS:
            raise InputError("peers", ", ".join([*SOLVERS, "none"]), got=p)
    if len(set(args.peer_list)) < len(args.peer_list):
        raise InputError("peers", "each peer once", got=" ".join(args.peers))
    est = resources.bench_estimate(args.what, args.N, args.k, args.repeats, args.eigsh_max_n, args.kkt_max_n)
    check_memory(est, "N", max(args.N))
    return est


def _check_face(args) -> None:
    """``--what face``: the element is one of the 3D model's (the 2D routes' flags were refused
    before, :func:`~.common.refuse_unused`)."""
    from ..models.membranes3d import ELEMENTS

    args.element = ELEMENTS[0] if args.element is None else args.element
    if args.element not in ELEMENTS:
        raise InputError("element", ", ".join(ELEMENTS), got=args.element)


def _check_elastic(args) -> None:
    """``--what elastic``: ν in the model's range, every ``--case`` a registered id."""
    from ..discretization.spaces.registry import space_spec
    from ..models.plane_strain import check_nu

    args.nu = check_nu(0.3 if args.nu is None else args.nu)
    for case in args.case or ():
        space_spec(case)


def _check_arc(args) -> None:
    """``--what arc``: the radius R > 1 (finite: the flat segment is its reference route)."""
    from ..discretization.segment.arc import RADIUS_ALLOWED, check_arc_options

    args.radius = 2.0 if args.radius is None else args.radius
    check_arc_options("arc", args.radius, "exact")
    if args.radius == float("inf"):
        raise InputError("radius", RADIUS_ALLOWED.replace(", or inf (the flat segment)", " (finite: the flat "
                                                          "segment is the reference route)"), got=args.radius)


TARGET_CHECKS = {"face": _check_face, "elastic": _check_elastic, "arc": _check_arc}
"""The ``--what`` targets with flags of their own, and their checks."""
PLANE_STRAIN = ("elastic",)
"""The ``--what`` targets of the plane-strain β routes (``--nu``, ``--case``)."""


def _run_bench(args) -> None:
    from ..solvers.side_by_side import worker_processes

    with worker_processes():  # ours as the command line's beta runs it (solvers/side_by_side.py)
        _bench(args)


def _bench(args) -> None:
    import pandas as pd

    from .. import bench

    peers = args.peer_list
    if args.what == "face":
        rows = bench.bench_beta(bench.bench_for("face"), args.N, args.k, args.repeats, args.route_budget,
                                element=args.element, phases=[] if args.phases else None)
        if args.phases:
            from ..bench.phases import COLUMNS
            from ..io import write_atomic

            write_atomic(args.phases, pd.DataFrame(rows.phases, columns=list(COLUMNS)).to_csv(
                index=False, float_format="%.4g"))
    elif args.what == "beta":
        rows = bench.bench_beta(bench.bench_for("beta", dense_max_size=args.dense_max_size,
                                                eigsh_max_n=args.eigsh_max_n), args.N, args.k, args.repeats,
                                args.route_budget)
    elif args.what == "arc":
        from ..bench.curved import COLUMNS, curved_rows

        write_csv(pd.DataFrame(curved_rows(args.N, args.k, args.radius, args.repeats, args.route_budget),
                               columns=list(COLUMNS)), float_format="%.6g", output=args.output)
        return
    elif args.what in PLANE_STRAIN:
        rows = bench.bench_beta(bench.bench_for(args.what, nu=args.nu), args.N, args.k, args.repeats,
                                args.route_budget, cases=args.case)
    else:
        rows = bench.bench_contact(args.N, args.k, args.repeats, peers=tuple(peers),
                                   kkt_max_n=args.kkt_max_n, budget=args.route_budget)
    write_csv(pd.DataFrame(rows), float_format="%.6g", output=args.output)
