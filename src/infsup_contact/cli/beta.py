"""``infsup-contact beta``: β_h (eq. (4.5)) for one mesh pair, one CSV row per case × norm."""
from __future__ import annotations

import sys

from .verdict_formats import add_table_output, force_use, output_path
from .worst_mode import check_worst_mode, mode_frame, write_modes
from .common import (FlagUse, declare_flag_uses, material_columns, model_flag_uses, system_flag_uses,
                     add_dry_run, add_model, check_memory, SPACE_HELP, space_value, write_csv)
from .request import cases, face_cases, material, mesh_options, norms, request


def add(sub) -> None:
    from ..discretization.segment.meshes import FAMILIES
    from ..discretization.spaces.registry import space_ids

    from ..solvers.kernel import KERNEL_CRITERION

    p = sub.add_parser("beta", help="β_h for one mesh pair (CSV: one row per case × norm)",
                       description="β_h (eq. (4.5)) for one mesh pair, one CSV row per case × norm. Column "
                       f"kernel_dim: {KERNEL_CRITERION}. beta is 0 where kernel_dim > 0 and smallest_nonzero "
                       "is beta above the kernel. kernel_check compares the numerical count with the "
                       "proven one (agree, above_structural: modes beyond the proof, below_structural: the "
                       "error level was exceeded); gap_over_roundoff is the first pencil eigenvalue above "
                       "the kernel over the pencil's round-off level n*eps*lambda_max (a cross-check).")
    p.add_argument("--case", default=None, choices=[*space_ids(None), "all"],
                   help="a registered space, or all (the default) for every one defined for k in the "
                        "paper's list and the duals; on a 3D model also every space its face elements "
                        "build for k (k = 2: DUAL-Q9, TDUAL-Q8, PWLIN-Q9, ... on hexahedra, TDUAL-T6, "
                        "PWLIN-T6 on tetrahedra; DUAL-Q8 and DUAL-T6, refused by construction, by name)")
    p.add_argument("--space", metavar="FILE.py:FUNC", type=space_value, help=SPACE_HELP)
    p.add_argument("--system", metavar="LEVELS.yaml", default=None,
                   help="a saddle-point system exported by another code (a manifest of mesh levels "
                   "{h, A, B, G}): one row per level; instead of --case/--k/--N1/--N2")
    p.add_argument("--k", type=int, default=None, help="displacement degree, 1..4 (required unless --system)")
    p.add_argument("--family", default="structured", choices=FAMILIES)
    p.add_argument("--N1", type=int, default=None, help="segments on Γ of the Ω1 mesh (>= 1; a 3D model: "
                   "cells per direction on the face Γ)")
    p.add_argument("--N2", type=int, default=None, help="segments on Γ of the Ω2 mesh (>= 1; a 3D model: "
                   "cells per direction on the face Γ)")
    p.add_argument("--multiplier-mesh", default="omega2", choices=["omega2", "omega1", "union"])
    add_model(p)
    p.add_argument("--norm", default="all", choices=["H", "L2", "all"])
    p.add_argument("--h-route", default="logkernel", choices=["logkernel", "series"],
                   help="H^{-1/2}_00 Gram: closed-form log kernel or truncated sine series (a 3D "
                   "model's contact face: always the extrapolated double sine series)")
    p.add_argument("--seed", type=int, default=0, help="seed of the perturbed family (>= 0)")
    p.add_argument("--alpha", type=float, default=0.2, help="perturbation amplitude / h, in [0, 0.2] (larger can invert triangles)")
    p.add_argument("--worst-mode", metavar="FILE", type=output_path, default=None,
                   help="also write, for every row, the worst mode on Γ to FILE (CSV, atomically): the "
                   "eigenvector of the smallest eigenvalue of S m = beta^2 G m (a kernel vector where beta = 0) "
                   "as mu_h = sum m_j mu_j at sample points of Γ, max |mu_h| = 1; columns case, multiplier_mesh, "
                   "c1, c2, norm, beta, x (, y on a face), mu. With --system: one mode per level, for a manifest "
                   "describing its multipliers (gamma, levels[i].multipliers)")
    add_table_output(p)
    add_dry_run(p)
    system_uses = [u for u in system_flag_uses(p) if u.dest != "worst_mode"]  # a mode per level (worst_mode.py)
    declare_flag_uses(p, [*system_uses, *FLAG_USES, *model_flag_uses(), force_use()])
    p.set_defaults(run=_run_beta, check=_check_beta)


def _model_dim(args) -> int:
    from ..models import MODELS

    return MODELS[args.model].dim


FLAG_USES = [
    FlagUse("seed", lambda a: a.family == "perturbed", "--family perturbed", lambda a: f"--family {a.family}"),
    FlagUse("alpha", lambda a: a.family == "perturbed", "--family perturbed", lambda a: f"--family {a.family}"),
    FlagUse("h_route", lambda a: _model_dim(a) == 2 and a.norm in ("H", "all"),
            "the H norm (--norm H or all) of a 2D model (the face of a 3D model has one H route)",
            lambda a: f"--model {a.model} --norm {a.norm}"),
]
"""The flags of ``beta`` only some requests use (:func:`~.common.refuse_unused`)."""


def _check_beta(args):
    from .. import resources
    from ..errors import InputError

    if args.system is not None:
        from ..systems.levels import dry_check
        from ..systems.manifest import load_manifest

        args.manifest = load_manifest(args.system, min_levels=1)
        if args.worst_mode is not None:
            check_worst_mode(args)
        est = dry_check(args.manifest)
        check_memory(est, "system", args.system)
        return est
    for key in ("k", "N1", "N2"):
        if getattr(args, key) is None:
            raise InputError(key, "an integer (required unless --system)")

    args.cases = cases(args)
    material(args)
    args.mesh, args.gamma_obj = mesh_options(args)
    args.cases = face_cases(args)
    args.request = request(args)
    if args.worst_mode is not None:
        check_worst_mode(args)
    est = resources.beta_estimate(args.family, args.k, args.N1, args.N2, args.multiplier_mesh,
                                  norms(args), args.h_route,
                                  components=args.model_obj.components, dim=args.model_obj.dim,
                                  element=args.mesh.element, n_spaces=len(args.cases))
    check_memory(est, *(("N1", args.N1) if args.N1 >= args.N2 else ("N2", args.N2)))
    return est


def _run_beta(args) -> None:
    if args.system is not None:
        from ..systems.levels import NORM_NOTES

        if args.manifest.norm not in ("given", "H"):  # H: the paper's norm, no caveat
            print(f"infsup-contact: note: {NORM_NOTES[args.manifest.norm]}", file=sys.stderr)
    from ..solvers.side_by_side import worker_processes

    modes = None if args.worst_mode is None else []
    with worker_processes():  # one mesh pair: its spaces in forked workers (solvers/side_by_side.py)
        frame = beta_frame(args, modes)
    if modes is not None:
        write_modes(args.worst_mode, mode_frame(modes))
    write_csv(frame, float_format="%.12g", output=args.output)


def beta_frame(args, modes: list | None = None):
    """The table of a validated ``beta`` request (what ``beta`` writes; :mod:`infsup_contact.api`);
    ``modes`` receives each row's worst mode (:mod:`infsup_contact.solvers.modes`) where given."""
    import pandas as pd

    if args.system is not None:
        from ..systems.levels import system_rows

        return pd.DataFrame(system_rows(args.manifest, modes=modes)).drop(columns="N2")

    from ..solvers.infsup import beta_table

    rows = beta_table(args.request, modes=modes)
    frame = pd.DataFrame(rows)
    for i, (name, value) in enumerate(args.mesh.columns(args.model_obj, args.gamma_obj).items()):  # e.g. element, after family
        frame.insert(frame.columns.get_loc("family") + 1 + i, name, value)
    return material_columns(frame, args)
