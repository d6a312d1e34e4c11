"""``infsup-contact beta``: β_h (eq. (4.5)) for one mesh pair, one CSV row per case × norm."""
from __future__ import annotations

from .common import add_dry_run, add_model, cases, check_memory, material, norms, SPACE_HELP, write_csv


def add(sub) -> None:
    from ..discretization.meshes import FAMILIES
    from ..discretization.registry import space_ids

    from ..solvers.kernel import KERNEL_CRITERION

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
    add_model(p)
    p.add_argument("--norm", default="all", choices=["H", "L2", "all"])
    p.add_argument("--h-route", default="logkernel", choices=["logkernel", "series"],
                   help="H^{-1/2}_00 Gram: closed-form log kernel or truncated sine series")
    p.add_argument("--seed", type=int, default=0, help="seed of the perturbed family (>= 0)")
    p.add_argument("--alpha", type=float, default=0.2, help="perturbation amplitude / h, in [0, 0.5)")
    add_dry_run(p)
    p.set_defaults(run=_run_beta, check=_check_beta)


def _check_beta(args):
    from .. import resources
    from ..discretization.meshes import check_perturbation
    from ..solvers.infsup import check_inputs

    args.cases = cases(args)
    material(args)
    check_inputs([c for c in args.cases if isinstance(c, str)], args.k, args.family, args.N1, args.N2,
                 args.c1, args.c2, norms(args), args.multiplier_mesh)
    check_perturbation(args.alpha, args.seed)
    est = resources.beta_estimate(args.family, args.k, args.N1, args.N2, args.multiplier_mesh,
                                  norms(args), args.h_route,
                                  components=2 if args.model == "elastic" else 1)
    check_memory(est, *(("N1", args.N1) if args.N1 >= args.N2 else ("N2", args.N2)))
    return est


def _run_beta(args) -> None:
    import pandas as pd

    from ..solvers.infsup import beta_rows

    kwargs = {}
    if args.family == "perturbed":
        kwargs = dict(seed=args.seed, alpha=args.alpha)
    rows = beta_rows(args.family, args.k, args.N1, args.N2, args.cases, args.multiplier_mesh,
                     args.c1, args.c2, norms(args), h_route=args.h_route, model=args.model_obj, **kwargs)
    frame = pd.DataFrame(rows)
    if args.model == "elastic":  # c_i = E_i: the columns under their elastic names, and ν
        frame = frame.rename(columns={"c1": "E1", "c2": "E2"})
        frame.insert(frame.columns.get_loc("E2") + 1, "nu", args.nu)
        frame.insert(0, "model", "elastic")
    write_csv(frame, float_format="%.12g")
