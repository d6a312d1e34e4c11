"""What one ``infsup-contact contact`` call runs for each registered scene: its rows and its
checks of a request (memory estimate included). The scene registry
(:mod:`.scene_registry`) names these functions by path; they call the scenes' own code.
"""
from __future__ import annotations

from ... import progress, resources
from ...errors import InputError
from . import hertz
from ..patch import face as face_patch, elastic3d as elastic_face_patch, segment as patch
from .rows import contact_row, reference_solution
from .registry import REFERENCE_MARGIN, scene_data, scene_spec


def membrane_rows(model, cases, k, family, n1, n2, c, args) -> list:
    """One row per case; a scene measured against a reference solves it first (``--n-ref``)."""
    params = dict(p=args.p, q=args.q) if "p" in scene_spec(args.scene).params else {}
    ref = None
    if "n_ref" in scene_spec(args.scene).params:
        ref = reference_solution(scene_data(args.scene, c1=c[0], c2=c[1]), k, args.n_ref, model=model)
    return [contact_row(args.scene, case, k, family, n1, n2, c[0], c[1], reference=ref, scene_params=params,
                        model=model) for case in progress.steps(cases, "space")]


def membrane_check(args):
    """``--n-ref`` against :data:`~.scene_registry.REFERENCE_MARGIN`; the estimate with the
    reference where it dominates (then ``n_ref`` is the key to name)."""
    spec = scene_spec(args.scene)
    need = REFERENCE_MARGIN * max(args.N1, args.N2)
    if args.n_ref < 1 or ("n_ref" in spec.params and args.n_ref < need):
        raise InputError("n_ref", f"an integer >= {need} for the membranes scene ({REFERENCE_MARGIN}x the finest "
                         "mesh: a coarser reference gives errors that are not errors), >= 1 otherwise",
                         got=args.n_ref)
    n_ref = args.n_ref if "n_ref" in spec.params else None
    est = resources.contact_estimate(args.family, args.k, args.N1, args.N2, n_ref, len(args.cases))
    alone = resources.contact_estimate(args.family, args.k, args.N1, args.N2, None, len(args.cases))
    if n_ref is not None and est.bytes > 2 * alone.bytes:  # the reference dominates
        return est, ("n_ref", args.n_ref)
    return est, _finest(args)


def _finest(args) -> tuple:
    return ("N1", args.N1) if args.N1 >= args.N2 else ("N2", args.N2)


def blocks_check(args):
    """Structured blocks; estimate: the β one of the pair, both displacement components."""
    est = resources.beta_estimate("structured", args.k, args.N1, args.N2, "omega2", ("L2",), components=2)
    return est, _finest(args)


def hertz_check(args):
    """R and d (defaults 1, 0.05) checked, then as :func:`blocks_check`."""
    args.R, args.d = hertz.check_geometry(1.0 if args.R is None else args.R, 0.05 if args.d is None else args.d)
    return blocks_check(args)


def patch_rows(model, cases, k, family, n1, n2, c, args) -> list:
    """The patch test's rows on the pair (its own model instance with ``--nu``)."""
    return patch.patch_rows(cases, [k], [(n1, n2)], args.nu, c)


def hertz_rows(model, cases, k, family, n1, n2, c, args) -> list:
    """One Hertz row per case (geometry R, d as checked)."""
    return [hertz.hertz_row(case, k, n1, n2, args.R, args.d, args.nu, c) for case in progress.steps(cases, "space")]


def face_patch_rows(model, cases, k, family, n1, n2, c, args) -> list:
    """The 3D patch test's rows on the pair, on the request's element (``--element``)."""
    return face_patch.face_patch_rows(cases, [k], [(n1, n2)], c, element=_element(args), model=model)


def _element(args) -> str:
    """The request's 3D element (``--element``, :class:`~infsup_contact.solvers.request.MeshOptions`
    in ``args.mesh``); ``hex`` where the request has none."""
    mesh = getattr(args, "mesh", None)
    return "hex" if mesh is None or mesh.element is None else mesh.element


def face_check(args):
    """The face's structured bodies; estimate: the β one of the pair in 3D (one component)."""
    est = resources.beta_estimate("structured", args.k, args.N1, args.N2, "omega2", ("L2",), dim=3)
    return est, _finest(args)


def elastic_face_patch_rows(model, cases, k, family, n1, n2, c, args) -> list:
    """The 3D elastic patch test's rows on the pair (moduli ``c`` = (E1, E2), ``--nu`` built into
    ``model``), on the request's element (``--element``)."""
    return elastic_face_patch.elastic_face_patch_rows(
        cases, [k], [(n1, n2)], c, args.nu, element=_element(args),
        model=model)


def elastic_face_check(args):
    """The face's structured bodies; estimate: the β one of the pair in 3D, three components."""
    est = resources.beta_estimate("structured", args.k, args.N1, args.N2, "omega2", ("L2",), components=3, dim=3)
    return est, _finest(args)
