"""``infsup-contact verdict``: the stability verdict for one space, as a user's CI calls it."""
from __future__ import annotations

import sys

from ..errors import InputError
from .common import (declare_flag_uses, model_flag_uses, system_flag_uses, add_dry_run, add_model, check_memory,
                     SPACE_HELP, space_value)
from .request import mesh_options, run_intervals
from .verdict_formats import add_output_args, emit, force_use


VERDICT_DEFAULTS = {"slope_tolerance": 0.15, "beta_floor": 0.001, "confidence": 0.95}
"""Defaults of ``verdict``'s criterion: the ``claims:`` section of config/config.yaml (a test
keeps them equal), so the command and the ledger judge a series alike."""


_EXPECT = {"stable": "STABLE", "unstable": "UNSTABLE"}


def add(sub) -> None:
    from ..discretization.segment.meshes import FAMILIES
    from ..discretization.spaces.registry import space_ids

    p = sub.add_parser(
        "verdict", help="is a multiplier space stable? β_h over a series of meshes → STABLE, "
        "UNSTABLE or INCONCLUSIVE (CSV: one row)",
        description="β_h (eq. (4.5)) on the mesh pairs N1 = N + --N1-offset, N2 = N for each --N "
        "(matching by default; h = 1/N2), judged by the "
        "claims ledger's criterion: a numerical kernel on any mesh is UNSTABLE; otherwise PASS/"
        "FAIL/INCONCLUSIVE of 'β_h bounded away from 0' (min β_h > --beta-floor and the "
        "--confidence interval of the slope of log β_h vs log h inside ±--slope-tolerance) is "
        "STABLE/UNSTABLE/INCONCLUSIVE. With --expect the exit code is 0 if the verdict matches, "
        "1 if not (INCONCLUSIVE never matches); bad input is exit code 2.")
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument("--case", choices=space_ids(None),
                       help="a registered space: one of the segment's, or on a 3D model one its face "
                       "elements build (k >= 2: DUAL-Q9, TDUAL-Q8, ... with --element hex; TDUAL-T6, "
                       "PWLIN-T6 with --element tet)")
    which.add_argument("--space", metavar="FILE.py:FUNC", type=space_value, help=SPACE_HELP)
    which.add_argument("--system", metavar="LEVELS.yaml",
                       help="a saddle-point system exported by another code: a manifest of mesh levels "
                       "{h, A, B, G} (docs/foreign-systems.md); --k, --family, "
                       "--N, --N1-offset, --norm and --multiplier-mesh do not apply")
    p.add_argument("--k", type=int, default=None, help="displacement degree, 1..4 (with --case/--space)")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--N", type=int, nargs="+", default=[8, 16, 32, 64],
                   help="segments on Γ of the Ω2 meshes (a 3D model: cells per direction on the face), "
                   "at least 3 distinct (default: 8 16 32 64)")
    p.add_argument("--N1-offset", type=int, default=0,
                   help="N1 = N + offset: a non-matching series (default 0: matching meshes)")
    p.add_argument("--norm", default="H", choices=["H", "L2"],
                   help="multiplier norm: H = H^{-1/2}_00(Γ) (the paper's, default); in L2 "
                   "stable spaces decay like h^{1/2} (Remark 3.1)")
    p.add_argument("--multiplier-mesh", default="omega2", choices=["omega2", "omega1", "union"])
    add_model(p, materials=False)
    p.add_argument("--expect", choices=sorted(_EXPECT),
                   help="exit code 0 if the verdict is this, 1 otherwise")
    for key, text in (("slope_tolerance", "slope tolerance τ"), ("beta_floor", "β floor"),
                      ("confidence", "confidence level of the slope interval")):
        p.add_argument("--" + key.replace("_", "-"), dest=key, type=float, default=VERDICT_DEFAULTS[key],
                       help=f"{text} (default {VERDICT_DEFAULTS[key]:g}: claims.{key} in config/config.yaml)")
    add_output_args(p)
    add_dry_run(p)
    declare_flag_uses(p, [*system_flag_uses(p), *model_flag_uses(), force_use()])
    p.set_defaults(run=_run_verdict, check=_check_verdict)


def _check_verdict(args):
    from .. import resources
    from ..study.verdict import check_criterion

    if args.system is not None:
        from ..systems.levels import dry_check
        from ..systems.manifest import load_manifest

        args.manifest = load_manifest(args.system)
        check_criterion(args.slope_tolerance, args.beta_floor, args.confidence)
        est = dry_check(args.manifest)
        check_memory(est, "system", args.system)
        return est
    if args.k is None:
        raise InputError("k", "an integer in 1..4 (required with --case and --space)")
    from ..discretization.segment import meshes
    from ..discretization.spaces import registry
    from ..discretization.spaces.user_spaces import load_user_space
    from ..solvers.request import check_k
    from ..study.verdict import check_criterion, check_mesh_sizes, check_model_case, check_n1_offset

    args.space_or_case = args.case if args.space is None else load_user_space(args.space, run_intervals(args))
    case = args.case if args.space is None else args.space_or_case.id
    check_k(args.k)
    registry.check_case(case, args.k)
    from ..models import make_model

    args.model_obj = make_model(args.model)
    args.mesh, args.gamma_obj = mesh_options(args)
    meshes.check_mesh_args(args.family, 1)
    ns = check_mesh_sizes(args.N)
    check_n1_offset(ns, args.N1_offset)
    for n in ns:
        meshes.check_mesh_args(args.family, n + args.N1_offset, "N1_offset")
    if args.space is None:  # a face-only id on a 2D model, a face space of the other element: one line
        check_model_case(case, args.k, args.model_obj, args.family, args.mesh, args.gamma_obj)
    for n in ns:  # an empty space on a small N is refused here, before any β_h
        registry.check_pair_spaces([case], args.k, n + args.N1_offset, n, (args.multiplier_mesh,), key="N")
    check_criterion(args.slope_tolerance, args.beta_floor, args.confidence)
    est = resources.verdict_estimate(args.family, args.k, ns, args.norm, args.multiplier_mesh, args.model_obj.dim,
                                     n1_offset=args.N1_offset, components=args.model_obj.components)
    check_memory(est, *(("N1_offset", args.N1_offset) if args.N1_offset > 0 else ("N", max(ns))))
    return est


def _run_verdict(args) -> int:
    row, levels = verdict_row(args)
    if args.system is not None:
        if row["norm"] not in ("given", "H"):  # H: the paper's norm, no caveat
            print(f"infsup-contact: note: {row['norm_note']}", file=sys.stderr)
        return emit(args, row, levels, manifest_expect=args.manifest.expect)
    return emit(args, row)


def verdict_row(args) -> tuple:
    """The verdict row of a validated ``verdict`` request and, for ``--system``, its per-level
    rows (else None): what ``verdict`` renders (:mod:`infsup_contact.api`)."""
    if args.system is not None:
        from ..systems.levels import system_verdict

        return system_verdict(args.manifest, tol=args.slope_tolerance, floor=args.beta_floor,
                              confidence=args.confidence)

    from ..study.verdict import verdict_rows

    out = verdict_rows(args.space_or_case, args.k, args.family, args.N, args.norm,
                       tol=args.slope_tolerance, floor=args.beta_floor, confidence=args.confidence,
                       multiplier_mesh=args.multiplier_mesh, model=args.model_obj, n1_offset=args.N1_offset,
                       mesh=args.mesh, gamma=args.gamma_obj)
    return out, None
