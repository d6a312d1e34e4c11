"""Command line: one computation, CSV on stdout.

    infsup-contact beta --case all --k 2 --family structured --N1 16 --N2 16
    infsup-contact beta --model elastic --case T3 --k 2 --N1 16 --N2 16 --nu 0.3 --E1 1 --E2 1
    infsup-contact contact --scene manufactured --case T3 --k 2 --N1 16 --N2 16
    infsup-contact contact --model elastic --scene patch --case all --k 2 --N1 5 --N2 4
    infsup-contact contact --model elastic --scene hertz --case T4 --k 2 --N1 32 --N2 32 --R 1 --d 0.05
    infsup-contact rates contact.csv
    infsup-contact bench --what beta --N 32 64 --k 2
    infsup-contact verdict --case T3 --k 2 --expect stable
    infsup-contact provenance

Bad input gets one line on stderr naming the flag and exit code 2; no traceback, and no
computation: every subcommand validates the whole request first — values, the files it reads
and its estimated memory against the available memory (``resources.py``) — and ``--dry-run``
stops right there (exit 0, the estimate on stdout). ``verdict --expect`` exits with 1 when the
verdict is not the expected one.
"""
from __future__ import annotations

import argparse
import os
import sys

from .errors import InputError, check_prestress
from .io import TableError


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

    from .solvers.kernel import KERNEL_CRITERION

    p = sub.add_parser("beta", help="β_h for one mesh pair (CSV: one row per case × norm)",
                       description="β_h (eq. (4.5)) for one mesh pair, one CSV row per case × norm. Column "
                       f"kernel_dim: {KERNEL_CRITERION}. Column kernel_check compares it with "
                       "structural_kernel_dim = max(dim M − dim(W1 + W2), 0), a lower bound, exact for "
                       "Rem 5.2/5.4 on matching meshes (agree, below_structural, above_structural); "
                       "gap_over_roundoff is the first eigenvalue above the kernel over eta.")
    p.add_argument("--case", default=None, choices=[*space_ids(), "all"],
                   help="a registered space, or all (the default) for every one defined for k")
    p.add_argument("--space", metavar="FILE.py:FUNC", help=SPACE_HELP)
    p.add_argument("--k", type=int, required=True, help="displacement degree, 1..4")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--N1", type=int, required=True, help="segments on Γ of the Ω1 mesh (>= 1)")
    p.add_argument("--N2", type=int, required=True, help="segments on Γ of the Ω2 mesh (>= 1)")
    p.add_argument("--multiplier-mesh", default="omega2", choices=["omega2", "omega1", "union"])
    p.add_argument("--c1", type=float, default=None, help="membranes: prestress c1 (default 1)")
    p.add_argument("--c2", type=float, default=None, help="membranes: prestress c2 (default 1)")
    _add_model(p)
    p.add_argument("--norm", default="all", choices=["H", "L2", "all"])
    p.add_argument("--h-route", default="logkernel", choices=["logkernel", "series"],
                   help="H^{-1/2}_00 Gram: closed-form log kernel or truncated sine series")
    p.add_argument("--seed", type=int, default=0, help="seed of the perturbed family (>= 0)")
    p.add_argument("--alpha", type=float, default=0.2, help="perturbation amplitude / h, in [0, 0.5)")
    _add_dry_run(p)
    p.set_defaults(run=_run_beta, check=_check_beta)


def _add_model(p) -> None:
    p.add_argument("--model", default="membranes", choices=["membranes", "elastic"],
                   help="membranes (the paper's Section 3, default) or elastic (plane strain, "
                   "vector P_k, frictionless normal contact; material scale c_i = E_i)")
    p.add_argument("--nu", type=float, default=None,
                   help="elastic: Poisson ratio of both bodies, -1 < nu < 0.5 (default 0.3)")
    p.add_argument("--E1", type=float, default=None, help="elastic: Young's modulus of Ω1 (default 1)")
    p.add_argument("--E2", type=float, default=None, help="elastic: Young's modulus of Ω2 (default 1)")


def _material(args):
    """Resolve --model/--nu/--E1/--E2/--c1/--c2: sets ``args.model_obj``, ``args.c1``,
    ``args.c2`` (c_i = E_i for elastic). The membranes take --c1 --c2 only, the elastic
    bodies --nu --E1 --E2 only: the other model's flags are refused, naming the flag."""
    from .models import MODELS
    from .models.elastic import check_modulus, check_nu, elastic_model

    if args.model == "membranes":
        for key in ("nu", "E1", "E2"):
            if getattr(args, key) is not None:
                raise InputError(key, "only with --model elastic (the membranes take --c1 --c2)",
                                 got=getattr(args, key))
        args.c1 = 1.0 if args.c1 is None else args.c1
        args.c2 = 1.0 if args.c2 is None else args.c2
        args.model_obj = MODELS["membranes"]
        return
    for key in ("c1", "c2"):
        if getattr(args, key) is not None:
            raise InputError(key, "only with --model membranes (an elastic body's scale is --E1/--E2)",
                             got=getattr(args, key))
    nu = check_nu(0.3 if args.nu is None else args.nu, "nu")
    args.c1 = check_modulus(1.0 if args.E1 is None else args.E1, "E1")
    args.c2 = check_modulus(1.0 if args.E2 is None else args.E2, "E2")
    args.nu = nu
    args.model_obj = elastic_model(nu)


def _norms(args) -> tuple:
    return ("H", "L2") if args.norm == "all" else (args.norm,)


def _check_beta(args):
    from . import resources
    from .discretization.meshes import check_perturbation
    from .solvers.infsup import check_inputs

    args.cases = _cases(args)
    _material(args)
    check_inputs([c for c in args.cases if isinstance(c, str)], args.k, args.family, args.N1, args.N2,
                 args.c1, args.c2, _norms(args), args.multiplier_mesh)
    check_perturbation(args.alpha, args.seed)
    est = resources.beta_estimate(args.family, args.k, args.N1, args.N2, args.multiplier_mesh,
                                  _norms(args), args.h_route,
                                  components=2 if args.model == "elastic" else 1)
    _check_memory(est, *(("N1", args.N1) if args.N1 >= args.N2 else ("N2", args.N2)))
    return est


def _run_beta(args) -> None:
    import pandas as pd

    from .solvers.infsup import beta_rows

    kwargs = {}
    if args.family == "perturbed":
        kwargs = dict(seed=args.seed, alpha=args.alpha)
    rows = beta_rows(args.family, args.k, args.N1, args.N2, args.cases, args.multiplier_mesh,
                     args.c1, args.c2, _norms(args), h_route=args.h_route, model=args.model_obj, **kwargs)
    frame = pd.DataFrame(rows)
    if args.model == "elastic":  # c_i = E_i: the columns under their elastic names, and ν
        frame = frame.rename(columns={"c1": "E1", "c2": "E2"})
        frame.insert(frame.columns.get_loc("E2") + 1, "nu", args.nu)
        frame.insert(0, "model", "elastic")
    frame.to_csv(sys.stdout, index=False, float_format="%.12g")


def _add_contact(sub) -> None:
    from .discretization.meshes import FAMILIES
    from .discretization.registry import space_ids

    p = sub.add_parser("contact", help="solve (4.1) for one case and mesh pair (CSV: one row)")
    p.add_argument("--scene", required=True, choices=["manufactured", "membranes", "patch", "hertz"],
                   help="membranes model: manufactured, membranes; elastic model: patch (the contact "
                   "patch test, study/patch.py), hertz (study/hertz.py)")
    p.add_argument("--case", choices=[*space_ids(), "all"], help="a registered space, or all")
    p.add_argument("--space", metavar="FILE.py:FUNC", help=SPACE_HELP)
    p.add_argument("--k", type=int, required=True, help="displacement degree, 1..4")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--N1", type=int, required=True)
    p.add_argument("--N2", type=int, required=True)
    p.add_argument("--c1", type=float, default=None, help="membranes: prestress c1 (default 1)")
    p.add_argument("--c2", type=float, default=None, help="membranes: prestress c2 (default 1)")
    _add_model(p)
    p.add_argument("--p", type=float, default=3.0, help="manufactured: λ = x (a − x)₊^p, p > 3/2")
    p.add_argument("--q", type=float, default=3.0, help="manufactured: g = (x − a)₊^q (1 − x), q > 3/2")
    p.add_argument("--R", type=float, default=None, help="hertz: radius of the gap (x - 1/2)^2/(2R), "
                   "0 < R <= 1e6 (default 1)")
    p.add_argument("--d", type=float, default=None, help="hertz: indentation of Ω2's top, 0 < d < 0.5 "
                   "(default 0.05)")
    p.add_argument("--n-ref", type=int, default=64,
                   help="membranes: reference mesh N (degree k + 1), at least 2 max(N1, N2)")
    _add_dry_run(p)
    p.set_defaults(run=_run_contact, check=_check_contact)


def _check_contact(args):
    from . import resources
    from .config_checks import REFERENCE_MARGIN
    from .discretization import meshes, registry
    from .study.scenes import _exponent

    if args.case is None and args.space is None:
        raise InputError("case", "one of --case ID|all or --space FILE.py:FUNC")
    args.cases = _cases(args)
    _material(args)
    elastic_scenes = ("patch", "hertz")
    if (args.model == "elastic") != (args.scene in elastic_scenes):
        key, value = ("model", args.model) if args.model == "elastic" else ("scene", args.scene)
        raise InputError(key, "--model elastic with --scene patch or hertz; --model membranes (the default) "
                         "with --scene manufactured or membranes", got=value)
    if args.scene != "hertz":
        for key in ("R", "d"):
            if getattr(args, key) is not None:
                raise InputError(key, "only with --scene hertz", got=getattr(args, key))
    else:
        from .study.hertz import check_geometry

        args.R, args.d = check_geometry(1.0 if args.R is None else args.R, 0.05 if args.d is None else args.d)
    if not 1 <= args.k <= 4:
        raise InputError("k", "an integer in 1..4", got=args.k)
    for case in args.cases:
        registry.check_case(case, args.k)
    meshes.check_mesh_args(args.family, args.N1, "N1")
    meshes.check_mesh_args(args.family, args.N2, "N2")
    check_prestress("c1", args.c1)
    check_prestress("c2", args.c2)
    _exponent("p", args.p)  # used by the manufactured scene only, but a bad value is bad anyway
    _exponent("q", args.q)
    if args.scene in elastic_scenes:  # structured blocks; estimate: the β one of the pair, both components
        if args.family != "structured":
            raise InputError("family", "structured (the blocks of the elastic scenes)", got=args.family)
        est = resources.beta_estimate("structured", args.k, args.N1, args.N2, "omega2", ("L2",), components=2)
        _check_memory(est, *(("N1", args.N1) if args.N1 >= args.N2 else ("N2", args.N2)))
        return est
    need = REFERENCE_MARGIN * max(args.N1, args.N2)
    if args.n_ref < 1 or (args.scene == "membranes" and args.n_ref < need):
        raise InputError("n_ref", f"an integer >= {need} for the membranes scene ({REFERENCE_MARGIN}x the finest "
                         "mesh: a coarser reference gives errors that are not errors), >= 1 otherwise",
                         got=args.n_ref)
    n_ref = args.n_ref if args.scene == "membranes" else None
    est = resources.contact_estimate(args.scene, args.family, args.k, args.N1, args.N2, n_ref, len(args.cases))
    alone = resources.contact_estimate(args.scene, args.family, args.k, args.N1, args.N2, None, len(args.cases))
    if n_ref is not None and est.bytes > 2 * alone.bytes:  # the reference dominates
        _check_memory(est, "n_ref", args.n_ref)
    _check_memory(est, *(("N1", args.N1) if args.N1 >= args.N2 else ("N2", args.N2)))
    return est


def _run_contact(args) -> None:
    import pandas as pd

    from .study.contact_rows import contact_row

    cases = args.cases
    if args.scene == "patch":
        from .study.patch import patch_rows

        rows = patch_rows(cases, [args.k], [(args.N1, args.N2)], args.nu, (args.c1, args.c2))
        pd.DataFrame(rows).to_csv(sys.stdout, index=False, float_format="%.6g")
        return
    if args.scene == "hertz":
        from .study.hertz import hertz_row

        rows = [hertz_row(case, args.k, args.N1, args.N2, args.R, args.d, args.nu, (args.c1, args.c2))
                for case in cases]
        pd.DataFrame(rows).to_csv(sys.stdout, index=False, float_format="%.6g")
        return
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
    p.add_argument("--window", type=int, default=3,
                   help="number of finest meshes in the fit (2 .. the meshes of the shortest series)")
    _add_dry_run(p)
    p.set_defaults(run=_run_rates, check=_check_rates)


def _check_rates(args):
    from . import resources
    from .io import read_table

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
    from .study.rates import rate_table

    rate_table(args.frame, args.window).to_csv(sys.stdout, index=False, float_format="%.6g")


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
    _add_dry_run(p)
    p.set_defaults(run=_run_bench, check=_check_bench)


def _check_bench(args):
    from . import resources
    from .bench.peers import SOLVERS

    for key, values, ok, allowed in (("N", args.N, lambda n: n >= 1, "integers >= 1"),
                                     ("k", args.k, lambda k: 1 <= k <= 4, "integers in 1..4")):
        for v in values:
            if not ok(v):
                raise InputError(key, allowed, got=v)
        if len(set(values)) < len(values):
            raise InputError(key, f"{allowed}, each once", got=" ".join(map(str, values)))
    if args.repeats < 1:
        raise InputError("repeats", "an integer >= 1", got=args.repeats)
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
    _check_memory(est, "N", max(args.N))
    return est


def _run_bench(args) -> None:
    import pandas as pd

    from . import bench

    peers = args.peer_list
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
    _add_dry_run(p)
    p.set_defaults(run=_run_verdict, check=_check_verdict)


def _check_verdict(args):
    from . import resources
    from .discretization import meshes, registry
    from .discretization.user_spaces import load_user_space
    from .study.verdict import check_criterion, check_mesh_sizes

    args.space_or_case = args.case if args.space is None else load_user_space(args.space)
    case = args.case if args.space is None else args.space_or_case.id
    if not 1 <= args.k <= 4:
        raise InputError("k", "an integer in 1..4", got=args.k)
    registry.check_case(case, args.k)
    meshes.check_mesh_args(args.family, 1)
    ns = check_mesh_sizes(args.N)
    check_criterion(args.slope_tolerance, args.beta_floor, args.confidence)
    est = resources.verdict_estimate(args.family, args.k, ns, args.norm, args.multiplier_mesh)
    _check_memory(est, "N", max(ns))
    return est


def _run_verdict(args) -> int:
    import pandas as pd

    from .study.verdict import verdict_rows

    space = args.space_or_case
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


def _add_dry_run(p) -> None:
    p.add_argument("--dry-run", action="store_true",
                   help="validate the request (values, files, estimated memory) and print the "
                   "memory and time estimate instead of computing")


def _check_memory(est, key: str, value) -> None:
    """InputError naming ``key`` when the estimate exceeds MemAvailable (/proc/meminfo)."""
    from . import resources

    avail = resources.available_bytes()
    if avail is not None and est.bytes > avail:
        raise InputError(key, f"a size whose estimated memory fits in the {resources.human_bytes(avail)} "
                         f"available (this request: {est.describe()})", got=value)


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


def flag_names(parser: argparse.ArgumentParser, command: str) -> dict:
    """dest → the flag as typed (``n_ref`` → ``--n-ref``) for the options of ``command``."""
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[command]
    return {a.dest: max(a.option_strings, key=len) for a in sub._actions if a.option_strings}


def _message(err: Exception, parser, command: str) -> str:
    """The error's one line, with its key spelled as the flag the user typed."""
    text = " ".join(str(err).split())
    key = getattr(err, "key", None)
    flag = flag_names(parser, command).get(key) if key else None
    if flag and text.startswith(f"invalid {key}"):
        text = f"invalid {flag}" + text[len(f"invalid {key}"):]
    return text


def validate(argv) -> tuple:
    """Parse and validate a command line without computing: ``(args, estimate)``; raises
    InputError/TableError (bad values) or SystemExit(2) (argparse: unknown flag, wrong type)."""
    args = build_parser().parse_args(argv)
    return args, (args.check(args) if hasattr(args, "check") else None)


def main(argv=None) -> int:
    _threads_default()
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        estimate = args.check(args) if hasattr(args, "check") else None  # before any computation
        if getattr(args, "dry_run", False):
            from .resources import available_bytes, human_bytes

            avail = available_bytes()
            print(f"dry run: valid request; estimated {estimate.describe()}"
                  + (f" (available memory {human_bytes(avail)})" if avail is not None else ""))
            return 0
        code = args.run(args)
    except (InputError, TableError) as err:
        print(f"infsup-contact: error: {_message(err, parser, args.command)}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # `| head` closed the pipe: not an error of ours
        return 0
    return code or 0
