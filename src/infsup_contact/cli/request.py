"""The request of a subcommand. First the namespace from typed values (:func:`build`): the flags
as each subcommand declares them once (:class:`Declared`), their defaults, each value checked
and converted as the command line converts its text (:func:`typed`); the command line's parsed
flags (``cli.parse``) and the Python API's keywords (``cli.request_of``) both come this way,
and no command line is parsed for the API. Then its parts: the multiplier spaces (--case |
--space), the model and its material flags, the mesh options with the request's Γ resolved once
(:func:`mesh_options`), the norms; ``beta``'s :class:`~infsup_contact.solvers.request.BetaRequest`
(:func:`request`). The shared flags themselves are declared in :mod:`.common`."""
from __future__ import annotations

import argparse
from dataclasses import dataclass, field

from ..errors import InputError
from .common import _material_params, _mesh_options  # noqa: F401 (the flags' owners, declared there)


def cases(args) -> list:
    """Case ids of a request: --space (loaded, checked, registered), else --case (all: every
    registered space defined for k)."""
    from ..discretization.spaces.registry import common_ids
    from ..discretization.spaces.user_spaces import load_user_space
    from ..solvers.request import check_k

    if args.space is not None:
        if args.case not in (None,):
            raise InputError("case", "either --case or --space, not both", got=args.case)
        return [load_user_space(args.space, run_intervals(args)).id]
    if args.case in (None, "all"):
        check_k(args.k)
        return common_ids(args.k)
    return [args.case]


def face_cases(args) -> list:
    """``--case all`` on a 3D model: the paper's spaces and the duals (:func:`cases`), then every
    other registered space the model's face builds for k (the quadratic face elements' on
    hexahedra or tetrahedra; those refused by construction, e.g. DUAL-Q8, left out), on the
    uniform partition of one cell per direction of the request's Γ (``args.gamma_obj``, else the
    model's flat one, ``Model.gamma``: resolved without a mesh; ``args.mesh`` set)."""
    from ..discretization.spaces.registry import ids_built_on

    base = list(args.cases)
    if args.case not in (None, "all") or args.space is not None or args.model_obj.dim != 3:
        return base
    gamma = args.gamma_obj if args.gamma_obj is not None else args.model_obj.gamma(args.family, **args.mesh.kwargs())
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


def mesh_options(args) -> tuple:
    """(:class:`~infsup_contact.solvers.request.MeshOptions`, Γ) of a request for its model
    (``args.model_obj``): the mesh builder's options and the request's Γ (``--gamma``, ``--radius``,
    ``--coupling`` resolved once, here, without a mesh; None: the model's flat Γ), defaults filled in, each flag checked by the request's own rule
    (:func:`~infsup_contact.solvers.request.check_mesh_option`); a family the model's mesh builder
    does not build (``Model.families``) is refused (a mesh flag the model does not take was
    refused before, :func:`refuse_unused`)."""
    from ..models.contract import OptionalChoice
    from ..solvers.request import check_mesh_option, options_of

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
    return options_of(model, getattr(args, "family", "structured"), **out)  # Γ resolved once, here, without a mesh


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
                      replace(args.mesh, **perturbed), args.gamma_obj)
    if args.family != "perturbed":  # the perturbed family's: checked by the request itself
        check_perturbation(args.alpha, args.seed)
    return out


# ---------------------------------------------------------------- the request from typed values
@dataclass
class Declared:
    """What a subcommand declares, once, for both the command line and the Python API: its
    options (argparse actions: dest, type, default, choices, nargs, option strings), the
    defaults it sets (``run``, ``check``, ``flag_uses``, ...) and its exclusive groups
    (``([dest, ...], required)``). Filled as the subcommand's parser is declared (``cli._Parser``)."""

    options: list = field(default_factory=list)
    defaults: dict = field(default_factory=dict)
    exclusive: list = field(default_factory=list)


_TYPE_NAMES = {int: "an integer", float: "a number"}


def build(declared: Declared, command: str, values: dict, given) -> argparse.Namespace:
    """The request of ``command``: its declared defaults, then ``values`` (dest → value) each
    checked and converted as the command line converts its text (:func:`typed`), the required
    flags and exclusive groups checked, ``given`` (the dests the caller gave, for
    :func:`~.common.refuse_unused`) kept as ``args.given``. The namespace is the one argparse
    would make from the same flags; the command's checks come after (``cli.check``).

    Raises
    ------
    InputError
        A key that is not one of the command's options, or a bad value, naming the key.
    """
    by_dest = {a.dest: a for a in declared.options if a.dest != argparse.SUPPRESS}
    args = argparse.Namespace(command=command)
    for dest, action in by_dest.items():
        default = action.default
        if default is argparse.SUPPRESS:  # --help: no attribute, as argparse
            continue
        if isinstance(default, str) and action.type is not None:  # argparse converts a string default too
            default = action.type(default)
        setattr(args, dest, default)
    for key, value in declared.defaults.items():
        setattr(args, key, value)
    for key, value in values.items():
        if key not in by_dest:
            raise InputError(key, "one of " + ", ".join(sorted(by_dest)))
        setattr(args, key, typed(key, by_dest[key], value))
    given = set(given)
    for dests, required in declared.exclusive:
        chosen = [d for d in dests if d in given]
        if len(chosen) > 1 or (required and not chosen):
            raise InputError(chosen[-1] if chosen else dests[0], f"exactly one of {', '.join(dests)}",
                             got=chosen or None)
    for dest, action in by_dest.items():
        if action.required and dest not in given:
            raise InputError(dest, "a value (required)")
    args.given = given
    return args


def typed(key: str, action, value):
    """``value`` of the option ``action`` as the command line makes it from its text: a number
    given as its text to the declared ``type`` (``np.int64(2)`` → 2, ``"2"`` → 2, 2.5 refused by
    ``int``), then the declared ``choices`` and ``nargs``; a switch takes True or False. A type
    marked ``takes_objects`` (``--space``) receives any other object as it is."""
    if action.nargs == 0:  # a switch
        if not isinstance(value, bool):
            raise InputError(key, "True or False", got=value)
        return action.const if value else action.default
    if hasattr(value, "tolist"):  # numpy: a scalar (np.int64(2)) becomes its Python number, an array a list
        value = value.tolist()
    many = action.nargs in ("+", "*") or isinstance(action.nargs, int)
    if not many:
        if isinstance(value, (list, tuple, range)):
            raise InputError(key, "one value", got=value)
        return _one(key, action, value)
    values = list(value) if isinstance(value, (list, tuple, range)) else [value]
    if not values and action.nargs != "*":
        raise InputError(key, "at least one value", got=value)
    return [_one(key, action, v) for v in values]


def _one(key: str, action, value):
    if not isinstance(value, str) and getattr(action.type, "takes_objects", False):
        out = action.type(value)
    else:
        text = str(value)
        try:
            out = text if action.type is None else action.type(text)
        except (TypeError, ValueError):
            raise InputError(key, _TYPE_NAMES.get(action.type, getattr(action.type, "__name__", "a value")),
                             got=value) from None
        except argparse.ArgumentTypeError as err:  # "<why>: expected <what>" (output_path) → one InputError line
            why, sep, what = str(err).partition(": expected ")
            raise InputError(key, f"{what} ({why})" if sep else str(err), got=value) from None
    if action.choices is not None and out not in action.choices:
        raise InputError(key, "one of " + ", ".join(map(str, action.choices)), got=value)
    return out
