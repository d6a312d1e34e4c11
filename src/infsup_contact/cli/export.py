"""``infsup-contact export``: this suite's systems as files another code would write."""
from __future__ import annotations

import sys
from pathlib import Path

from ..errors import InputError
from .common import add_dry_run, add_model, check_memory, declare_flag_uses, model_flag_uses, write_text
from .request import material, mesh_options


def add(sub) -> None:
    from ..discretization.segment.meshes import FAMILIES
    from ..discretization.spaces.registry import space_ids
    from ..systems.export import EXPORT_FORMATS

    p = sub.add_parser("export", help="write A, B, G of a registered space on several meshes and a "
                       "levels.yaml manifest (the layout `verdict --system` reads)",
                       description="A = diag(K1, K2) (free dofs, Γ last), B = [-B1 | B2], G = the Gram "
                       "matrix of --norm, on N1 = N + --N1-offset, N2 = N for each --N; h = 1/N.")
    p.add_argument("--case", required=True, choices=space_ids(None),
                   help="a registered space: one of the segment's, or on a 3D model one its face elements "
                   "build (k >= 2: DUAL-Q9, TDUAL-Q8, ... with --element hex; TDUAL-T6, PWLIN-T6 with --element tet)")
    p.add_argument("--k", type=int, required=True, help="displacement degree, 1..4")
    p.add_argument("--N", type=int, nargs="+", required=True, help="segments on Γ of Ω2, coarse to fine")
    p.add_argument("--N1-offset", type=int, default=0, help="N1 = N + offset (non-matching pairs; default 0)")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--norm", default="H", choices=["H", "L2"],
                   help="H: manifest norm: H, the multipliers described on Γ and G = their L² mass (the "
                   "H^{-1/2}_00(Γ) Gram is assembled by the reader; a space the description cannot express, "
                   "a face's cellwise or triangle space: norm: given, G = the H Gram); L2: G = the L² mass "
                   "(manifest norm: L2)")
    p.add_argument("--multiplier-mesh", default="omega2", choices=["omega2", "omega1", "union"])
    p.add_argument("--format", default="mtx", choices=sorted(EXPORT_FORMATS))
    p.add_argument("--out", required=True, help="directory to write into (created; refused if it holds "
                   "files, unless --force)")
    p.add_argument("--force", action="store_true",
                   help="write into a directory that is not empty, overwriting its levels.yaml and matrices")
    add_model(p)
    add_dry_run(p)
    declare_flag_uses(p, model_flag_uses())
    p.set_defaults(run=_run_export, check=_check_export)


def _check_export(args):
    from pathlib import Path

    from .. import resources
    from ..discretization.segment import meshes
    from ..discretization.spaces import registry
    from ..solvers.request import check_k
    from ..study.verdict import check_model_case, check_n1_offset

    material(args)
    args.mesh, args.gamma_obj = mesh_options(args)
    for prm in args.model_obj.params:  # the sides' scales c_i (E_i of the elastic bodies)
        if prm.side is not None and getattr(args, prm.name) != 1.0:
            raise InputError(prm.name, "1 (an export is at unit material scale)", got=getattr(args, prm.name))
    check_k(args.k)
    registry.check_case(args.case, args.k)
    ns = list(args.N)
    for n in ns:
        meshes.check_mesh_args(args.family, n, "N")
    if ns != sorted(set(ns)):
        raise InputError("N", "distinct sizes, coarse to fine", got=" ".join(map(str, ns)))
    check_n1_offset(ns, args.N1_offset)
    for n in ns:
        meshes.check_mesh_args(args.family, n + args.N1_offset, "N1_offset")
    check_model_case(args.case, args.k, args.model_obj, args.family, args.mesh, args.gamma_obj)
    for n in ns:  # an empty space on a small N: refused here, before any file is written
        registry.check_pair_spaces([args.case], args.k, n + args.N1_offset, n, (args.multiplier_mesh,), key="N")
    out = Path(args.out)
    if not args.out.strip() or (out.exists() and not out.is_dir()):
        raise InputError("out", "a directory to write into (created if missing)", got=args.out)
    if out.is_dir() and not args.force:
        _refuse_nonempty(out, args)
    from .verdict_formats import check_writable_place

    problem = check_writable_place(out)  # /proc, a read-only folder: before anything is computed
    if problem:
        raise InputError("out", "a directory this process can create and write files in", got=f"{args.out} ({problem})")
    est = resources.beta_estimate(args.family, args.k, max(ns) + args.N1_offset, max(ns), args.multiplier_mesh,
                                  (args.norm,), components=args.model_obj.components, dim=args.model_obj.dim)
    check_memory(est, *(("N1_offset", args.N1_offset) if args.N1_offset > max(ns) else ("N", max(ns))))
    return est


def _targets(args) -> list:
    """The files this export writes, in the order it writes them."""
    from ..systems.export import EXPORT_FORMATS

    ext = EXPORT_FORMATS[args.format]
    return ["levels.yaml"] + [f"{key}{i}{ext}" for i in range(len(args.N)) for key in "ABG"]


def _refuse_nonempty(out, args) -> None:
    """An export into a directory holding files (another system's manifest and matrices) would
    overwrite them without a word: refused, naming the first file it would overwrite, or else
    the first file there (the directory must be empty, or ``--force`` given)."""
    try:
        present = sorted(p.name for p in out.iterdir())
    except OSError as err:
        raise InputError("out", "a directory this process can read and write", got=f"{args.out} ({err.strerror})") \
            from None
    if not present:
        return
    clash = [t for t in _targets(args) if t in present]
    what = (f"it would overwrite {out / clash[0]}" + (f" and {len(clash) - 1} more file(s)" if len(clash) > 1 else "")
            if clash else f"it holds {out / present[0]}" + (f" and {len(present) - 1} more" if len(present) > 1 else ""))
    raise InputError("out", "an empty or new directory, or --force to write into this one",
                     got=f"{args.out} ({what})")


def _run_export(args) -> None:
    from ..systems.export import suite_levels, write_system

    levels, norm, gamma = suite_levels(args.case, args.k, args.N, args.N1_offset, args.family, args.norm,
                                       args.multiplier_mesh, model=args.model_obj, mesh=args.mesh,
                                       gamma=args.gamma_obj)
    name = "-".join([args.case, f"k{args.k}", args.model, *(f"{v:g}" if isinstance(v, float) else str(v)
                                                            for v in args.mesh.columns(args.model_obj, args.gamma_obj).values())]
                    + ([f"N1{args.N1_offset:+d}"] if args.N1_offset else []))
    out = Path(args.out)
    before = {p.name for p in out.iterdir()} if out.is_dir() else set()
    written = []
    path = write_system(args.out, levels, args.format, name, norm=norm, gamma=gamma, written=written)
    stale = sorted(before - set(written))
    if stale:  # --force: what the new manifest does not name is left, and said so
        print(f"infsup-contact: note: --force: {len(stale)} file(s) not written by this export left in {out} "
              f"(not in its levels.yaml): {', '.join(stale[:5])}{' ...' if len(stale) > 5 else ''}", file=sys.stderr)
    write_text(f"{path}\n")
