"""Command line: one computation, CSV on stdout.

    infsup-contact beta --case all --k 2 --family structured --N1 16 --N2 16
    infsup-contact contact --scene manufactured --case T3 --k 2 --N1 16 --N2 16
    infsup-contact rates contact.csv
    infsup-contact bench --what beta --N 32 64 --k 2
    infsup-contact verdict --case T3 --k 2 --expect stable
    infsup-contact provenance

Bad input gets one line on stderr and exit code 2; no traceback. ``verdict --expect`` exits
with 1 when the verdict is not the expected one.
"""
from __future__ import annotations

import argparse
import os
import sys

from .errors import InputError


def _threads_default() -> None:
    # a single-threaded BLAS is the fast choice for the small dense problems here and
    # avoids oversubscription when jobs run in parallel (set before numpy loads BLAS)
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        os.environ.setdefault(var, "1")


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 — argparse's own convention
        self.exit(2, f"infsup-contact: error: {message}\n")


SPACE_HELP = ("a user-defined multiplier space: a file or module and a function returning a "
              "SpaceSpec (see examples/macro_p0.py); instead of --case")


def _cases(args) -> list:
    """Case ids of a request: --space (loaded, checked, registered), else --case (all: every
    registered space defined for k)."""
    from .discretization.registry import ids_valid_for
    from .discretization.user_spaces import load_user_space

    if args.space is not None:
        if args.case not in (None,):
            raise InputError("case", "either --case or --space, not both", got=args.case)
        return [load_user_space(args.space).id]
    if args.case in (None, "all"):
        if not 1 <= args.k <= 4:
            raise InputError("k", "an integer in 1..4", got=args.k)
        return ids_valid_for(args.k)
    return [args.case]


def _add_beta(sub) -> None:
    from .discretization.meshes import FAMILIES
    from .discretization.registry import space_ids

    p = sub.add_parser("beta", help="β_h for one mesh pair (CSV: one row per case × norm)")
    p.add_argument("--case", default=None, choices=[*space_ids(), "all"],
                   help="a registered space, or all (the default) for every one defined for k")
    p.add_argument("--space", metavar="FILE.py:FUNC", help=SPACE_HELP)
    p.add_argument("--k", type=int, required=True, help="displacement degree, 1..4")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--N1", type=int, required=True, help="segments on Γ of the Ω1 mesh (>= 1)")
    p.add_argument("--N2", type=int, required=True, help="segments on Γ of the Ω2 mesh (>= 1)")
    p.add_argument("--multiplier-mesh", default="omega2", choices=["omega2", "omega1", "union"])
    p.add_argument("--c1", type=float, default=1.0)
    p.add_argument("--c2", type=float, default=1.0)
    p.add_argument("--norm", default="all", choices=["H", "L2", "all"])
    p.add_argument("--h-route", default="logkernel", choices=["logkernel", "series"],
                   help="H^{-1/2}_00 Gram: closed-form log kernel or truncated sine series")
    p.add_argument("--seed", type=int, default=0, help="seed of the perturbed family")
    p.add_argument("--alpha", type=float, default=0.2, help="perturbation amplitude / h")
    p.set_defaults(run=_run_beta)


def _run_beta(args) -> None:
    import pandas as pd

    from .solvers.infsup import beta_rows

    cases = _cases(args)
    norms = ("H", "L2") if args.norm == "all" else (args.norm,)
    kwargs = {}
    if args.family == "perturbed":
        kwargs = dict(seed=args.seed, alpha=args.alpha)
    rows = beta_rows(args.family, args.k, args.N1, args.N2, cases, args.multiplier_mesh,
                     args.c1, args.c2, norms, h_route=args.h_route, **kwargs)
    pd.DataFrame(rows).to_csv(sys.stdout, index=False, float_format="%.12g")


def _add_contact(sub) -> None:
    from .discretization.meshes import FAMILIES
    from .discretization.registry import space_ids

    p = sub.add_parser("contact", help="solve (4.1) for one case and mesh pair (CSV: one row)")
    p.add_argument("--scene", required=True, choices=["manufactured", "membranes"])
    p.add_argument("--case", choices=[*space_ids(), "all"], help="a registered space, or all")
    p.add_argument("--space", metavar="FILE.py:FUNC", help=SPACE_HELP)
    p.add_argument("--k", type=int, required=True, help="displacement degree, 1..4")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--N1", type=int, required=True)
    p.add_argument("--N2", type=int, required=True)
    p.add_argument("--c1", type=float, default=1.0)
    p.add_argument("--c2", type=float, default=1.0)
    p.add_argument("--p", type=float, default=3.0, help="manufactured: λ = x (a − x)₊^p, p > 3/2")
    p.add_argument("--q", type=float, default=3.0, help="manufactured: g = (x − a)₊^q (1 − x), q > 3/2")
    p.add_argument("--n-ref", type=int, default=64, help="membranes: reference mesh N (degree k + 1)")
    p.set_defaults(run=_run_contact)


def _run_contact(args) -> None:
    import pandas as pd

    from .study.contact_rows import contact_row

    if args.case is None and args.space is None:
        raise InputError("case", "one of --case ID|all or --space FILE.py:FUNC")
    cases = _cases(args)
    params = dict(p=args.p, q=args.q) if args.scene == "manufactured" else {}
    ref = None
    rows = []
    for case in cases:
        if args.scene == "membranes" and ref is None:
            from .study.scenes import scene
            from .study.contact_rows import reference_solution
            ref = reference_solution(scene("membranes", c1=args.c1, c2=args.c2), args.k, args.n_ref)
        rows.append(contact_row(args.scene, case, args.k, args.family, args.N1, args.N2,
                                args.c1, args.c2, reference=ref, scene_params=params))
    pd.DataFrame(rows).to_csv(sys.stdout, index=False, float_format="%.12g")


def _add_rates(sub) -> None:
    p = sub.add_parser("rates", help="fit convergence rates of a contact table (CSV in, CSV out)")
    p.add_argument("table", help="CSV written by `infsup-contact contact` or the workflow")
    p.add_argument("--window", type=int, default=3, help="number of finest meshes in the fit")
    p.set_defaults(run=_run_rates)


def _run_rates(args) -> None:
    import pandas as pd

    from .study.rates import rate_table

    try:
        frame = pd.read_csv(args.table)
    except (OSError, pd.errors.ParserError) as err:
        raise InputError("table", "a readable CSV file", got=args.table) from err
    if args.window < 2:
        raise InputError("window", "an integer >= 2", got=args.window)
    rate_table(frame, args.window).to_csv(sys.stdout, index=False, float_format="%.6g")


def _add_bench(sub) -> None:
    p = sub.add_parser("bench", help="speed as ratios in one run (CSV)")
    p.add_argument("--what", required=True, choices=["beta", "contact"])
    p.add_argument("--N", type=int, nargs="+", required=True)
    p.add_argument("--k", type=int, nargs="+", required=True)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--peers", nargs="*", default=["osqp", "clarabel"],
                   help="contact: QP solvers to compare with (osqp, clarabel; none: omit)")
    p.add_argument("--eigsh-max-N", dest="eigsh_max_n", type=int, default=None,
                   help="beta: run the shift-invert Lanczos route only for N <= this")
    p.add_argument("--kkt-max-N", dest="kkt_max_n", type=int, default=64,
                   help="contact: run the sparse-KKT active-set route only for N <= this")
    p.set_defaults(run=_run_bench)


def _run_bench(args) -> None:
    import pandas as pd

    from . import bench

    for n in args.N:
        if n < 1:
            raise InputError("N", "integers >= 1", got=n)
    for k in args.k:
        if not 1 <= k <= 4:
            raise InputError("k", "integers in 1..4", got=k)
    if args.repeats < 1:
        raise InputError("repeats", "an integer >= 1", got=args.repeats)
    from .bench.peers import SOLVERS

    peers = [p for p in args.peers if p != "none"]
    for p in peers:
        if p not in SOLVERS:
            raise InputError("peers", ", ".join([*SOLVERS, "none"]), got=p)
    if args.what == "beta":
        rows = bench.bench_beta(args.N, args.k, args.repeats, eigsh_max_n=args.eigsh_max_n)
    else:
        rows = bench.bench_contact(args.N, args.k, args.repeats, peers=tuple(peers),
                                   kkt_max_n=args.kkt_max_n)
    pd.DataFrame(rows).to_csv(sys.stdout, index=False, float_format="%.6g")


VERDICT_DEFAULTS = {"slope_tolerance": 0.15, "beta_floor": 0.001, "confidence": 0.95}
"""Defaults of ``verdict``'s criterion: the ``claims:`` section of config/config.yaml (a test
keeps them equal), so the command and the ledger judge a series alike."""
_EXPECT = {"stable": "STABLE", "unstable": "UNSTABLE"}


def _add_verdict(sub) -> None:
    from .discretization.meshes import FAMILIES
    from .discretization.registry import space_ids

    p = sub.add_parser(
        "verdict", help="is a multiplier space stable? β_h over matching meshes → STABLE, "
        "UNSTABLE or INCONCLUSIVE (CSV: one row)",
        description="β_h (eq. (4.5)) on matching meshes N1 = N2 = N for each --N, judged by the "
        "claims ledger's criterion: a numerical kernel on any mesh is UNSTABLE; otherwise PASS/"
        "FAIL/INCONCLUSIVE of 'β_h bounded away from 0' (min β_h > --beta-floor and the "
        "--confidence interval of the slope of log β_h vs log h inside ±--slope-tolerance) is "
        "STABLE/UNSTABLE/INCONCLUSIVE. With --expect the exit code is 0 if the verdict matches, "
        "1 if not (INCONCLUSIVE never matches); bad input is exit code 2.")
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument("--case", choices=space_ids(), help="a registered space")
    which.add_argument("--space", metavar="FILE.py:FUNC", help=SPACE_HELP)
    p.add_argument("--k", type=int, required=True, help="displacement degree, 1..4")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--N", type=int, nargs="+", default=[8, 16, 32, 64],
                   help="segments on Γ of the matching meshes, at least 3 distinct (default: 8 16 32 64)")
    p.add_argument("--norm", default="H", choices=["H", "L2"],
                   help="multiplier norm: H = H^{-1/2}_00(Γ) (the paper's, default); in L2 "
                   "stable spaces decay like h^{1/2} (Remark 3.1)")
    p.add_argument("--multiplier-mesh", default="omega2", choices=["omega2", "omega1", "union"])
    p.add_argument("--expect", choices=sorted(_EXPECT),
                   help="exit code 0 if the verdict is this, 1 otherwise")
    for key, text in (("slope_tolerance", "slope tolerance τ"), ("beta_floor", "β floor"),
                      ("confidence", "confidence level of the slope interval")):
        p.add_argument("--" + key.replace("_", "-"), dest=key, type=float, default=VERDICT_DEFAULTS[key],
                       help=f"{text} (default {VERDICT_DEFAULTS[key]:g}: claims.{key} in config/config.yaml)")
    p.set_defaults(run=_run_verdict)


def _run_verdict(args) -> int:
    import pandas as pd

    from .discretization.user_spaces import load_user_space
    from .study.verdict import verdict_rows

    space = args.case if args.space is None else load_user_space(args.space)
    out = verdict_rows(space, args.k, args.family, args.N, args.norm,
                       tol=args.slope_tolerance, floor=args.beta_floor, confidence=args.confidence,
                       multiplier_mesh=args.multiplier_mesh)
    out["N_list"] = " ".join(str(n) for n in out["N_list"])
    pd.DataFrame([out]).to_csv(sys.stdout, index=False, float_format="%.6g")
    if args.expect is None:
        return 0
    return 0 if out["verdict"] == _EXPECT[args.expect] else 1


def _add_provenance(sub) -> None:
    p = sub.add_parser("provenance", help="versions, git commit, platform, date (JSON)")
    p.set_defaults(run=lambda args: print(__import__("json").dumps(
        __import__("infsup_contact.provenance", fromlist=["x"]).provenance(), indent=2)))


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="infsup-contact", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    _add_beta(sub)
    _add_contact(sub)
    _add_rates(sub)
    _add_bench(sub)
    _add_verdict(sub)
    _add_provenance(sub)
    return parser


def main(argv=None) -> int:
    _threads_default()
    args = build_parser().parse_args(argv)
    try:
        code = args.run(args)
    except InputError as err:
        print(f"infsup-contact: error: {err}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `| head` closed the pipe: not an error of ours
        return 0
    return code or 0
