"""The request of a subcommand, built from its parsed flags: the multiplier spaces (--case |
--space), the model and its material flags, the mesh options with the request's Γ resolved once
(:func:`mesh_options`), the norms; ``beta``'s :class:`~infsup_contact.solvers.request.BetaRequest`
(:func:`request`). The flags themselves are declared in :mod:`.common`."""
from __future__ import annotations

from ..errors import InputError
from .common import _material_params, _mesh_options  # noqa: F401 (the flags' owners, declared there)


def cases(args) -> list:
    """Case ids of a request: --space (loaded, checked, registered), else --case (all: every
    registered space defined for k)."""
    from ..discretization.spaces.registry import ids_valid_for
    from ..discretization.spaces.user_spaces import load_user_space
    from ..solvers.request import check_k

    if args.space is not None:
        if args.case not in (None,):
            raise InputError("case", "either --case or --space, not both", got=args.case)
        return [load_user_space(args.space, run_intervals(args)).id]
    if args.case in (None, "all"):
        check_k(args.k)
        return ids_valid_for(args.k)
    return [args.case]


def face_cases(args) -> list:
    """``--case all`` on a 3D model: the paper's spaces and the duals (:func:`cases`), then every
    other registered space the model's face builds for k (the quadratic face elements' on
    hexahedra or tetrahedra; those refused by construction, e.g. DUAL-Q8, left out), on the
    uniform partition of one cell per direction of the request's Γ (``Model.gamma``, resolved
    without a mesh; ``args.mesh`` set)."""
    from ..discretization.spaces.registry import ids_built_on

    base = list(args.cases)
    if args.case not in (None, "all") or args.space is not None or args.model_obj.dim != 3:
        return base
    gamma = args.model_obj.gamma(args.family, **args.mesh.kwargs())
    partition = gamma.uniform_partition(1)
    g_h = gamma.multiplier_partition(partition, partition)
    return base + [c for c in ids_built_on(args.k, gamma, g_h) if c not in base]


def run_intervals(args, limit: int = 1024) -> set:
    """Numbers of intervals of the multiplier meshes a request will use (--N1/--N2 and
    --multiplier-mesh, or the --N list with N1 = N + --N1-offset), for checking a user space on each.
    Sizes that are not valid N are left to their own checks; above ``limit`` the space is
    checked as it is built (user_spaces.guarded_build), not before."""
    from ..discretization.spaces.registry import multiplier_intervals

    choice = getattr(args, "multiplier_mesh", "omega2")
    pairs = ([(getattr(args, "N1", None), getattr(args, "N2", None))] if hasattr(args, "N1")
             else [(n + getattr(args, "N1_offset", 0), n) for n in getattr(args, "N", None) or ()])
    ok = [(a, b) for a, b in pairs if all(isinstance(v, int) and 1 <= v <= limit for v in (a, b))]
    return {multiplier_intervals(a, b, choice) for a, b in ok}


def mesh_options(args):
    """The :class:`~infsup_contact.solvers.request.MeshOptions` of a request for its model
    (``args.model_obj``), defaults filled in, each flag checked by the request's own rule
    (:func:`~infsup_contact.solvers.request.check_mesh_option`); a family the model's mesh builder
    does not build (``Model.families``) is refused (a mesh flag the model does not take was
    refused before, :func:`refuse_unused`)."""
    from ..models.contract import OptionalChoice
    from ..solvers.request import check_mesh_option, mesh_of

    model = args.model_obj
    if model.families is not None and getattr(args, "family", None) not in model.families:
        raise InputError("family", f"{', '.join(model.families)} (the meshes of --model {model.name})",
                         got=getattr(args, "family", None))
    own = dict(model.mesh_options)
    out = {}
    for name in _mesh_options():
        given = getattr(args, name, None)
        if name not in own:  # another model's flag: refused before (refuse_unused)
            continue
        if given is not None:
            check_mesh_option(model, name, given)
        elif isinstance(own[name], OptionalChoice):  # unset: the builder's default, no column
            when = own[name].filled_when
            if when and getattr(args, when[0], None) == when[1]:
                out[name] = own[name].values[0]
            continue
        out[name] = own[name][0] if given is None else given
    return mesh_of(model, getattr(args, "family", "structured"), **out)  # Γ resolved once, here, without a mesh


def material(args):
    """Resolve --model and its material flags from the model contract (``Model.params``): sets
    ``args.model_obj`` (built with the parameters of K_i, e.g. ν), ``args.c1``, ``args.c2``
    (the sides' scales under the model's names, e.g. c_i = E_i) and each parameter's
    attribute. A flag the model does not have was refused before (:func:`refuse_unused`)."""
    from ..models import MODELS, make_model

    model = MODELS[args.model]  # another model's flag was refused before (refuse_unused)
    build = {}
    for prm in model.params:
        given = getattr(args, prm.name)
        value = prm.check(prm.default if given is None else given, prm.name)
        setattr(args, prm.name, value)
        if prm.side is None:
            build[prm.name] = value
        else:
            setattr(args, ("c1", "c2")[prm.side], value)
    args.model_obj = make_model(model.name, **build) if build else model


def norms(args) -> tuple:
    return ("H", "L2") if args.norm == "all" else (args.norm,)


def request(args):
    """The :class:`~infsup_contact.solvers.request.BetaRequest` of the command line, validated once
    (the perturbed family's seed and α with it); the engine runs it unchecked."""
    from ..discretization.segment.meshes import check_perturbation
    from dataclasses import replace

    from ..solvers.request import BetaRequest

    perturbed = dict(seed=args.seed, alpha=args.alpha) if args.family == "perturbed" else {}
    out = BetaRequest(args.family, args.k, args.N1, args.N2, tuple(args.cases), (args.multiplier_mesh,),
                      ((args.c1, args.c2),), norms(args), args.h_route, args.model_obj,
                      replace(args.mesh, **perturbed))
    check_perturbation(args.alpha, args.seed)
    return out
