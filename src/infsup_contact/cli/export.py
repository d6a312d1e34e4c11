"""``infsup-contact export``: this suite's systems as files another code would write."""
from __future__ import annotations

from ..errors import InputError
from .common import add_dry_run, add_model, check_memory, material


def add(sub) -> None:
    from ..discretization.meshes import FAMILIES
    from ..discretization.registry import space_ids
    from ..systems.export import EXPORT_FORMATS

    p = sub.add_parser("export", help="write A, B, G of a registered space on several meshes and a "
                       "levels.yaml manifest (the layout `verdict --system` reads)",
                       description="A = diag(K1, K2) (free dofs, Γ last), B = [-B1 | B2], G = the Gram "
                       "matrix of --norm, on N1 = N + --N1-offset, N2 = N for each --N; h = 1/N.")
    p.add_argument("--case", required=True, choices=space_ids(), help="a registered space")
    p.add_argument("--k", type=int, required=True, help="displacement degree, 1..4")
    p.add_argument("--N", type=int, nargs="+", required=True, help="segments on Γ of Ω2, coarse to fine")
    p.add_argument("--N1-offset", type=int, default=0, help="N1 = N + offset (non-matching pairs; default 0)")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--norm", default="H", choices=["H", "L2"],
                   help="G: H^{-1/2}_00(Γ) (manifest norm: given) or the L² mass (manifest norm: L2)")
    p.add_argument("--multiplier-mesh", default="omega2", choices=["omega2", "omega1", "union"])
    p.add_argument("--format", default="mtx", choices=sorted(EXPORT_FORMATS))
    p.add_argument("--out", required=True, help="directory to write into (created)")
    p.add_argument("--c1", type=float, default=None, help=argparse_suppress())
    p.add_argument("--c2", type=float, default=None, help=argparse_suppress())
    add_model(p)
    add_dry_run(p)
    p.set_defaults(run=_run_export, check=_check_export)


def argparse_suppress():
    import argparse

    return argparse.SUPPRESS


def _check_export(args):
    from .. import resources
    from ..solvers.infsup import check_inputs

    material(args)
    if args.c1 != 1.0 or args.c2 != 1.0 or (args.model == "elastic" and (args.E1, args.E2) != (1.0, 1.0)):
        raise InputError("E1", "1 (an export is at unit material scale)", got=args.c1)
    ns = list(args.N)
    if ns != sorted(set(ns)):
        raise InputError("N", "distinct sizes, coarse to fine", got=" ".join(map(str, ns)))
    for n in ns:
        check_inputs([args.case], args.k, args.family, n + args.N1_offset, n, 1.0, 1.0, (args.norm,),
                     args.multiplier_mesh)
    est = resources.beta_estimate(args.family, args.k, max(ns) + args.N1_offset, max(ns), args.multiplier_mesh,
                                  (args.norm,), components=2 if args.model == "elastic" else 1)
    check_memory(est, "N", max(ns))
    return est


def _run_export(args) -> None:
    from ..systems.export import suite_system, write_system

    kwargs = {}
    levels = []
    for n in args.N:
        A, B, G = suite_system(args.case, args.k, n + args.N1_offset, n, args.family, args.norm,
                               args.multiplier_mesh, model=args.model_obj, **kwargs)
        levels.append((1.0 / n, A, B, G))
    name = f"{args.case}-k{args.k}-{args.model}"
    path = write_system(args.out, levels, args.format, name, norm="given" if args.norm == "H" else "L2")
    print(path)
