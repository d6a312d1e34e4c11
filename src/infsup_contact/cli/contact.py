"""``infsup-contact contact``: the discrete contact problem (4.1) for one scene, case and mesh
pair, CSV rows; the scenes and the models each is defined for come from the scene registry
(:mod:`infsup_contact.study.contact.registry`)."""
from __future__ import annotations

from ..errors import InputError, check_prestress
from .verdict_formats import add_table_output, force_use
from .common import FlagUse, add_dry_run, add_model, check_memory, declare_flag_uses, model_flag_uses, SPACE_HELP, space_value, write_csv
from .request import cases, face_cases, material, mesh_options


def add(sub) -> None:
    from ..discretization.segment.meshes import FAMILIES
    from ..discretization.spaces.registry import space_ids
    from ..study.contact.registry import allowed_pairs, scene_ids

    p = sub.add_parser("contact", help="solve (4.1) for one case and mesh pair (CSV: one row)")
    p.add_argument("--scene", required=True, choices=scene_ids(),
                   help=f"a registered scene, defined for the models of these --model/--scene pairs: {allowed_pairs()}")
    p.add_argument("--case", choices=[*space_ids(None), "all"], help="a registered space, or all")
    p.add_argument("--space", metavar="FILE.py:FUNC", type=space_value, help=SPACE_HELP)
    p.add_argument("--k", type=int, required=True, help="displacement degree, 1..4")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--N1", type=int, required=True)
    p.add_argument("--N2", type=int, required=True)
    add_model(p)
    p.add_argument("--p", type=float, default=3.0, help="manufactured: λ = x (a − x)₊^p, p > 3/2")
    p.add_argument("--q", type=float, default=3.0, help="manufactured: g = (x − a)₊^q (1 − x), q > 3/2")
    p.add_argument("--R", type=float, default=None, help="hertz: radius of the gap (x - 1/2)^2/(2R), "
                   "0 < R <= 1e6 (default 1)")
    p.add_argument("--d", type=float, default=None, help="hertz: indentation of Ω2's top, 0 < d < 0.5 "
                   "(default 0.05)")
    p.add_argument("--n-ref", type=int, default=64,
                   help="membranes: reference mesh N (degree k + 1), at least 2 max(N1, N2)")
    add_table_output(p)
    add_dry_run(p)
    declare_flag_uses(p, [*scene_flag_uses(), *model_flag_uses(), force_use()])
    p.set_defaults(run=_run_contact, check=_check_contact)


def scene_flag_uses() -> list:
    """The scene parameters (``--p``, ``--q``, ``--n-ref``, ``--R``, ``--d``): each used by the
    scenes that declare it (:attr:`~infsup_contact.study.contact.registry.SceneSpec.params`);
    refused with any other scene (:func:`~.common.refuse_unused`)."""
    from ..study.contact.registry import scene_ids, scene_spec

    def takers(name):
        return [s for s in scene_ids() if name in scene_spec(s).params]

    names = list(dict.fromkeys(n for s in scene_ids() for n in scene_spec(s).params))
    return [FlagUse(name, lambda a, name=name: a.scene in takers(name),
                    f"--scene {', '.join(takers(name))}",
                    lambda a: f"--scene {a.scene}") for name in names]


def _check_contact(args):
    from ..discretization.segment import meshes
    from ..discretization.spaces import registry
    from ..contact.contact import check_flat_gamma
    from ..solvers.request import check_k
    from ..study.contact.registry import check_pair
    from ..study.contact.scenes import _exponent

    if args.case is None and args.space is None:
        raise InputError("case", "one of --case ID|all or --space FILE.py:FUNC")
    args.cases = cases(args)
    material(args)
    check_flat_gamma(args)  # the flags, before Γ is resolved: a curved Γ is refused as such
    args.mesh, args.gamma_obj = mesh_options(args)  # a mesh flag of another model is refused; the scene's rows read them
    spec = check_pair(args.model, args.scene)
    check_k(args.k)
    # --case all on a 3D model: also the spaces only its face builds, but no Petrov–Galerkin pair (two
    # bases: the contact solve has one; an explicit --case names the pair's refusal)
    args.cases = [c for c in face_cases(args) if c in args.cases or not registry.space_spec(c).petrov_galerkin]
    for case in args.cases:
        registry.check_case(case, args.k)
    meshes.check_mesh_args(args.family, args.N1, "N1")
    meshes.check_mesh_args(args.family, args.N2, "N2")
    registry.check_pair_spaces(args.cases, args.k, args.N1, args.N2)  # G_h = trace of Ω2 (omega2)
    check_prestress("c1", args.c1)
    check_prestress("c2", args.c2)
    if "p" in spec.params:  # the manufactured scene (another scene refused --p/--q before)
        _exponent("p", args.p)
        _exponent("q", args.q)
    if spec.families is not None and args.family not in spec.families:
        raise InputError("family", f"{', '.join(spec.families)} (the meshes of the {args.scene} scene)",
                         got=args.family)
    est, (key, value) = spec.check(args)
    check_memory(est, key, value)
    return est


def _run_contact(args) -> None:
    import pandas as pd

    from ..study.contact.registry import scene_spec

    spec = scene_spec(args.scene)
    rows = spec.rows(args.model_obj, args.cases, args.k, args.family, args.N1, args.N2, (args.c1, args.c2), args)
    write_csv(pd.DataFrame(rows), float_format=spec.float_format, output=args.output)
