"""``infsup-contact contact``: the discrete contact problem (4.1) for one scene, case and mesh
pair (membranes: manufactured, membranes; elastic: patch, hertz), CSV rows."""
from __future__ import annotations

from ..errors import InputError, check_prestress
from .common import add_dry_run, add_model, cases, check_memory, material, SPACE_HELP, write_csv


def add(sub) -> None:
    from ..discretization.meshes import FAMILIES
    from ..discretization.registry import space_ids

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
    add_model(p)
    p.add_argument("--p", type=float, default=3.0, help="manufactured: λ = x (a − x)₊^p, p > 3/2")
    p.add_argument("--q", type=float, default=3.0, help="manufactured: g = (x − a)₊^q (1 − x), q > 3/2")
    p.add_argument("--R", type=float, default=None, help="hertz: radius of the gap (x - 1/2)^2/(2R), "
                   "0 < R <= 1e6 (default 1)")
    p.add_argument("--d", type=float, default=None, help="hertz: indentation of Ω2's top, 0 < d < 0.5 "
                   "(default 0.05)")
    p.add_argument("--n-ref", type=int, default=64,
                   help="membranes: reference mesh N (degree k + 1), at least 2 max(N1, N2)")
    add_dry_run(p)
    p.set_defaults(run=_run_contact, check=_check_contact)


def _check_contact(args):
    from .. import resources
    from ..config_checks import REFERENCE_MARGIN
    from ..discretization import meshes, registry
    from ..study.scenes import _exponent

    if args.case is None and args.space is None:
        raise InputError("case", "one of --case ID|all or --space FILE.py:FUNC")
    args.cases = cases(args)
    material(args)
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
        from ..study.hertz import check_geometry

        args.R, args.d = check_geometry(1.0 if args.R is None else args.R, 0.05 if args.d is None else args.d)
    if not 1 <= args.k <= 4:
        raise InputError("k", "an integer in 1..4", got=args.k)
    for case in args.cases:
        registry.check_case(case, args.k)
    meshes.check_mesh_args(args.family, args.N1, "N1")
    meshes.check_mesh_args(args.family, args.N2, "N2")
    registry.check_pair_spaces(args.cases, args.k, args.N1, args.N2)  # G_h = trace of Ω2 (omega2)
    check_prestress("c1", args.c1)
    check_prestress("c2", args.c2)
    _exponent("p", args.p)  # used by the manufactured scene only, but a bad value is bad anyway
    _exponent("q", args.q)
    if args.scene in elastic_scenes:  # structured blocks; estimate: the β one of the pair, both components
        if args.family != "structured":
            raise InputError("family", "structured (the blocks of the elastic scenes)", got=args.family)
        est = resources.beta_estimate("structured", args.k, args.N1, args.N2, "omega2", ("L2",), components=2)
        check_memory(est, *(("N1", args.N1) if args.N1 >= args.N2 else ("N2", args.N2)))
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
        check_memory(est, "n_ref", args.n_ref)
    check_memory(est, *(("N1", args.N1) if args.N1 >= args.N2 else ("N2", args.N2)))
    return est


def _run_contact(args) -> None:
    import pandas as pd

    from ..study.contact_rows import contact_row

    cases = args.cases
    if args.scene == "patch":
        from ..study.patch import patch_rows

        rows = patch_rows(cases, [args.k], [(args.N1, args.N2)], args.nu, (args.c1, args.c2))
        write_csv(pd.DataFrame(rows), float_format="%.6g")
        return
    if args.scene == "hertz":
        from ..study.hertz import hertz_row

        rows = [hertz_row(case, args.k, args.N1, args.N2, args.R, args.d, args.nu, (args.c1, args.c2))
                for case in cases]
        write_csv(pd.DataFrame(rows), float_format="%.6g")
        return
    params = dict(p=args.p, q=args.q) if args.scene == "manufactured" else {}
    ref = None
    rows = []
    for case in cases:
        if args.scene == "membranes" and ref is None:
            from ..study.scenes import scene
            from ..study.contact_rows import reference_solution
            ref = reference_solution(scene("membranes", c1=args.c1, c2=args.c2), args.k, args.n_ref)
        rows.append(contact_row(args.scene, case, args.k, args.family, args.N1, args.N2,
                                args.c1, args.c2, reference=ref, scene_params=params))
    write_csv(pd.DataFrame(rows), float_format="%.12g")
