"""The registry of contact scenes, like the registry of spaces
(:mod:`infsup_contact.discretization.registry`): every scene id with the models it is defined
for, its data, its exact or reference solution, what it measures and the rows of one
``infsup-contact contact`` call.

A consumer asks the registry and never branches on a scene's id: the CLI offers
:func:`scene_ids`, refuses a (model, scene) pair the registry does not declare
(:func:`check_pair`, one line naming the allowed pairs), checks a scene's own parameters
and estimates its memory (:attr:`SceneSpec.check`) and gets its rows
(:attr:`SceneSpec.rows`). A new scene is one :func:`register` call; a new model reaches a
scene by adding its name to that scene's ``models``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from ..errors import InputError
from ..models import DEFAULT_MODEL, make_model
from . import hertz, patch


@dataclass(frozen=True)
class SceneSpec:
    """One contact scene as its consumers see it.

    Attributes
    ----------
    id : str
        The scene's name (``--scene``, the ``scene`` column).
    models : tuple of str
        The models it is defined for (names of :data:`infsup_contact.models.MODELS`); the
        first is its default.
    description : str
        Its data, one line.
    reference : str
        What a row is compared with: an exact solution or a reference solve.
    measures : tuple of str
        The row's columns that measure the solution.
    params : tuple of str
        The CLI parameters it takes beyond the common ones (others are refused).
    rows : callable
        ``rows(model, cases, k, family, n1, n2, c, args) -> list[dict]``.
    check : callable
        ``check(args) -> (Estimate, (key, value))``: its own checks of a CLI request, its
        memory estimate and the parameter to name if that does not fit.
    float_format : str
        The precision of its CSV rows.
    """

    id: str
    models: tuple
    description: str
    reference: str
    measures: tuple
    rows: Callable
    check: Callable
    params: tuple = ()
    float_format: str = "%.12g"
    families: tuple | None = field(default=None)


_SCENES: dict[str, SceneSpec] = {}


def register(spec: SceneSpec) -> SceneSpec:
    """Add ``spec`` to the registry (ids are unique)."""
    if spec.id in _SCENES:
        raise ValueError(f"scene {spec.id!r} registered twice")
    _SCENES[spec.id] = spec
    return spec


def scene_ids() -> list:
    """Every registered scene id, in registration order."""
    return list(_SCENES)


def scene_spec(scene: str) -> SceneSpec:
    if scene not in _SCENES:
        raise InputError("scene", ", ".join(_SCENES), got=scene)
    return _SCENES[scene]


def allowed_pairs() -> str:
    """'model/scene' of every declared pair, for one-line refusals."""
    return ", ".join(f"{m}/{s.id}" for s in _SCENES.values() for m in s.models)


def check_pair(model: str, scene: str) -> SceneSpec:
    """The spec of ``scene`` if it is defined for ``model``; :class:`InputError` naming the
    allowed (model, scene) pairs otherwise."""
    spec = scene_spec(scene)
    if model not in spec.models:
        key, value = ("model", model) if model != spec.models[0] else ("scene", scene)
        raise InputError(key, f"a declared --model/--scene pair: {allowed_pairs()}", got=f"{model}/{scene}")
    return spec


def scene_model(scene: str, **params):
    """The default model of ``scene`` (its first), with the model's ``params`` (elastic: nu)."""
    return make_model(scene_spec(scene).models[0], **params)


# ------------------------------------------------------------------------ the entries
def _membrane_rows(model, cases, k, family, n1, n2, c, args) -> list:
    from .contact_rows import contact_row, reference_solution
    from .scenes import scene

    params = dict(p=args.p, q=args.q) if "p" in scene_spec(args.scene).params else {}
    ref = None
    if "n_ref" in scene_spec(args.scene).params:
        ref = reference_solution(scene(args.scene, c1=c[0], c2=c[1]), k, args.n_ref, model=model)
    return [contact_row(args.scene, case, k, family, n1, n2, c[0], c[1], reference=ref, scene_params=params,
                        model=model) for case in cases]


def _membrane_check(args):
    from .. import resources
    from ..config_checks import REFERENCE_MARGIN

    spec = scene_spec(args.scene)
    need = REFERENCE_MARGIN * max(args.N1, args.N2)
    if args.n_ref < 1 or ("n_ref" in spec.params and args.n_ref < need):
        raise InputError("n_ref", f"an integer >= {need} for the membranes scene ({REFERENCE_MARGIN}x the finest "
                         "mesh: a coarser reference gives errors that are not errors), >= 1 otherwise",
                         got=args.n_ref)
    n_ref = args.n_ref if "n_ref" in spec.params else None
    est = resources.contact_estimate(args.scene, args.family, args.k, args.N1, args.N2, n_ref, len(args.cases))
    alone = resources.contact_estimate(args.scene, args.family, args.k, args.N1, args.N2, None, len(args.cases))
    if n_ref is not None and est.bytes > 2 * alone.bytes:  # the reference dominates
        return est, ("n_ref", args.n_ref)
    return est, _finest(args)


def _finest(args) -> tuple:
    return ("N1", args.N1) if args.N1 >= args.N2 else ("N2", args.N2)


def _blocks_check(args):
    """Structured blocks; estimate: the β one of the pair, both displacement components."""
    from .. import resources

    est = resources.beta_estimate("structured", args.k, args.N1, args.N2, "omega2", ("L2",), components=2)
    return est, _finest(args)


def _hertz_check(args):
    args.R, args.d = hertz.check_geometry(1.0 if args.R is None else args.R, 0.05 if args.d is None else args.d)
    return _blocks_check(args)


def _patch_rows(model, cases, k, family, n1, n2, c, args) -> list:
    return patch.patch_rows(cases, [k], [(n1, n2)], args.nu, c)


def _hertz_rows(model, cases, k, family, n1, n2, c, args) -> list:
    return [hertz.hertz_row(case, k, n1, n2, args.R, args.d, args.nu, c) for case in cases]


_ERRORS = ("energy_error", "l2_error", "lambda_l2_error", "lambda_hm12_error", "contact_set_error")
register(SceneSpec(
    "manufactured", ("membranes",), "exact u, λ with contact on (0, a), gap on (a, 1); regularity p, q",
    "exact", _ERRORS, _membrane_rows, _membrane_check, params=("p", "q")))
register(SceneSpec(
    "membranes", ("membranes",), "the paper's Fig. 4 loads ±4(1 − 2x)",
    "fine-mesh reference (structured N_ref, degree k + 1, the registry's reference space)", _ERRORS,
    _membrane_rows, _membrane_check, params=("n_ref",)))
register(SceneSpec(
    patch.SCENE, patch.SCENE_MODELS, "the contact patch test: blocks on rollers, uniform compression",
    "exact (λ = p, u linear)", ("lambda_max_rel_error", "u_max_rel_error", "passes", "kernel_dim"),
    _patch_rows, _blocks_check, float_format="%.6g", families=("structured",)))
register(SceneSpec(
    hertz.SCENE, hertz.SCENE_MODELS, "clamped blocks with the gap (x − 1/2)²/(2R), Ω2's top moved by d",
    "plane-strain Hertz for the measured resultant", ("P", "p_max", "half_width", "oscillation"),
    _hertz_rows, _hertz_check, params=("R", "d"), float_format="%.6g", families=("structured",)))
