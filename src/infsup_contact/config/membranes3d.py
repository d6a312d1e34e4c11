"""Cross-key checks of the model table's ``membranes3d`` studies (the 3D membranes on the contact face).

What the schema cannot state: the model is a registered one with a 3D face, each element is
one of its ``element`` mesh options, each case id is a registered space the face can build for
some k of ``membranes3d.k`` (built on the 2 × 2 grid of Γ: a face-only space added to the registry
later passes by config alone), a non-matching pair has N1 ≠ N2, and the face studies' keys
(:func:`check_face_studies`). Each raises one
:class:`~infsup_contact.config.schema.ConfigError` naming the key under the study's entry
(``membranes3d.k`` below: ``studies.membranes3d.k`` for the entry ``membranes3d``).

Non-matching families (``membranes3d.nonmatching_families``: family → element → N1 list):
the rules of the 2D study's families (:data:`~infsup_contact.discretization.gamma.mesh_series.FAMILY_RULES`:
``sqrt2`` n → round(√2 n), ``plus1`` n → n + 1) give the *finer* side from the coarser one, and on
the face Ω2 is the finer side as in ``membranes3d.nonmatching`` (G_h = the trace of Ω2): N2 = rule(N1),
e.g. sqrt2 5:7, 7:10, 10:14. They are listed per element and explicitly, so ``membranes3d.max_N`` does not
cap them (one √2 pair per element keeps the DAG cheap).
"""
from __future__ import annotations

import numpy as np

from .schema import ConfigError, naming_key


def check_membranes3d(cfg) -> None:
    """Check every ``membranes3d`` study of the model table (none: nothing to check)."""
    from .models import study_entries

    for at, fc in study_entries(cfg, "membranes3d"):
        _check_face(cfg, fc, at)


def _check_face(cfg, fc: dict, at: str) -> None:
    """Check one membranes3d study's scenes ``fc``, its errors naming the keys under ``at`` (``studies.<name>``)."""
    from ..models import MODELS

    model = MODELS.get(fc["model"])
    if model is None or getattr(model, "dim", 2) != 3:
        raise ConfigError(f"{at}.model", "not a registered model with a 3D face", got=fc["model"],
                          allowed=", ".join(m.name for m in MODELS.values() if getattr(m, "dim", 2) == 3))
    options = dict(model.mesh_options).get("element", ())
    for i, element in enumerate(fc["elements"]):
        check_element(f"{at}.elements[{i}]", model, element)
        _check_degrees(f"{at}.elements[{i}]", model, element, fc["k"], f"{at}.k")
    for element, top in (fc.get("max_N") or {}).items():
        if element not in fc["elements"]:
            raise ConfigError(f"{at}.max_N.{element}", f"not an element of {at}.elements", got=element,
                              allowed=", ".join(fc["elements"]))
        if sum(n <= top for n in fc["N"]) < 3:
            raise ConfigError(f"{at}.max_N.{element}", f"keeps fewer than 3 matching meshes of {at}.N (a slope "
                              "fit needs 3)", got=top, allowed=f">= {sorted(fc['N'])[2]}")
    _check_l2_max_n(fc, at)
    for i, pair in enumerate(fc["nonmatching"]):
        if pair[0] == pair[1]:
            raise ConfigError(f"{at}.nonmatching[{i}]", "a non-matching pair needs N1 != N2", got=pair,
                              allowed=f"[N1, N2] with N1 != N2 (matching meshes go under {at}.N)")
    _check_face_families(fc, at)
    _check_face_cases(cfg, fc, options, at)
    _check_face_meshes(fc, at)
    check_face_studies(fc, model, at)


def _check_face_meshes(fc, at: str) -> None:
    """Every face mesh gets the minimum its spaces need, as the command line's rule
    (:func:`~infsup_contact.discretization.spaces.registry.check_pair_spaces`): a case of
    ``membranes3d.cases`` built from the segment's space (T3, DUAL, ...) with dim M_h = 0 on the
    N2 × N2 cells of Γ (T3 with k = 1 on N = 1) is refused, naming the key, the case and k."""
    from ..discretization.spaces.registry import SPACES, case_name, is_empty, min_intervals

    meshes = [(f"{at}.N[{i}]", n, n) for i, n in enumerate(fc["N"])]
    meshes += [(f"{at}.nonmatching[{i}]", pair, pair[1]) for i, pair in enumerate(fc["nonmatching"])]
    segment = [c for c in fc["cases"] if c in SPACES and SPACES[c].defined_on(1)]
    for key, value, n2 in meshes:
        for k in fc["k"]:
            for case in (c for c in segment if SPACES[c].valid_for(k)):
                if is_empty(case, k, n2):
                    raise ConfigError(key, f"case {case_name(case)} with k = {k} has dim M_h = 0 on the {n2} x {n2} "
                                      "cells of the face: nothing to compute", got=value,
                                      allowed=f"N >= {min_intervals(case, k)} for it ({at}.cases, {at}.k)")


def _check_degrees(key: str, model, element: str, ks, k_key: str) -> None:
    """ConfigError unless the element's bodies exist for every k of ``ks`` (HEX20: k = 2 only)."""
    gamma = model.gamma(element=element)
    bad = [int(k) for k in ks if not gamma.allows(int(k))]
    if bad:
        raise ConfigError(key, f"the {element} bodies have no degree k = {bad[0]} ({k_key})", got=element,
                          allowed=f"an element with every degree of {k_key}, or {k_key} without {bad[0]}")


def check_face_studies(fc, model, at: str) -> None:
    """The face studies' keys (jobs of the membranes3d study, plans/membranes3d.py) the schema
    cannot state: the patch test's elements are the model's, with contact scenes and at least one
    degree of ``membranes3d.patch.k`` (an element runs the degrees it has: HEX20 k = 2), its pairs
    non-matching; the α sweep's elements are face elements with a transformed (non-identity)
    basis; edge dropping keeps at least 3 θ at or below ``fit_theta_max`` (a slope fit). Each
    raises one ConfigError naming the key."""
    from ..discretization.face.spaces.cellwise import QUAD_ELEMENTS
    from ..discretization.face.spaces.dual_bases import transformation

    options = dict(model.mesh_options).get("element", ())
    for i, element in enumerate(fc["patch"]["elements"]):
        check_element(f"{at}.patch.elements[{i}]", model, element)
        gamma = model.gamma(element=element)
        if not gamma.contact:
            raise ConfigError(f"{at}.patch.elements[{i}]", f"the {element} bodies serve β_h only (no contact "
                              "scene, so no patch test)", got=element,
                              allowed=", ".join(e for e in options if model.gamma(element=e).contact))
        if not any(gamma.allows(int(k)) for k in fc["patch"]["k"]):  # the others are skipped for it
            raise ConfigError(f"{at}.patch.elements[{i}]", f"the {element} bodies have none of the degrees "
                              f"{at}.patch.k = {list(fc['patch']['k'])}", got=element,
                              allowed=f"an element with a degree of {at}.patch.k, or a degree it has in {at}.patch.k")
    for i, pair in enumerate(fc["patch"]["pairs"]):
        if pair[0] == pair[1]:
            raise ConfigError(f"{at}.patch.pairs[{i}]", "the patch test's pairs are non-matching: N1 != N2",
                              got=pair, allowed="[N1, N2] with N1 != N2")
    transformed = [e for e in QUAD_ELEMENTS if not np.allclose(transformation(e, 0.25), np.eye(len(transformation(e))))]
    for i, element in enumerate(fc["alpha"]["elements"]):
        if element not in transformed:
            raise ConfigError(f"{at}.alpha.elements[{i}]", "not a face element with a transformed dual basis",
                              got=element, allowed=", ".join(transformed))
    ed = fc["edge_dropping"]
    _check_edge_dropping(fc, ed, at)
    kept = sorted(t for t in ed["theta"] if t <= ed["fit_theta_max"])
    if len(kept) < 3:
        raise ConfigError(f"{at}.edge_dropping.fit_theta_max", f"keeps fewer than 3 of {at}.edge_dropping.theta "
                          "(a slope fit needs 3)", got=ed["fit_theta_max"],
                          allowed=f">= {sorted(ed['theta'])[2]}" if len(ed["theta"]) >= 3 else "more θ")


def check_element(key: str, model, element) -> None:
    """``element`` is one of ``model``'s: the request's rule for its mesh option
    (:func:`~infsup_contact.solvers.request.check_mesh_option`), the error naming ``key``."""
    from ..solvers.request import check_mesh_option

    with naming_key(key, f"not an element of {model.name}"):
        check_mesh_option(model, "element", element)


def _check_edge_dropping(fc, ed, at: str) -> None:
    """Each θ is one the geometry resolves at the largest N (a narrower cut column was dropped
    whole: θ = 1e-12 computed θ = 0), and each k has an edge case among ``membranes3d.cases`` (a k
    without one computed nothing)."""
    from ..discretization.face.spaces.clipped import SLIVER_MIN, min_covered_fraction
    from ..discretization.spaces.registry import edge_cases

    n = max(ed["N"])
    for i, theta in enumerate(ed["theta"]):
        if not min_covered_fraction(n) <= theta <= 1.0:
            raise ConfigError(f"{at}.edge_dropping.theta[{i}]", f"a covered fraction the geometry resolves at "
                              f"N = {n} (the cut column, θ/N wide, at least {SLIVER_MIN:g})", got=theta,
                              allowed=f"{min_covered_fraction(n):g} <= θ <= 1")
    for i, k in enumerate(ed["k"]):
        run = [c for c in edge_cases(k) if c in fc["cases"]]
        if not run:
            raise ConfigError(f"{at}.edge_dropping.k[{i}]", f"k = {k} has no edge case among {at}.cases "
                              "(nothing would be computed)", got=k,
                              allowed=f"k with one of {at}.cases in {', '.join(edge_cases(k)) or 'none'}")


def _check_face_families(fc, at: str) -> None:
    from ..discretization.gamma.mesh_series import FAMILY_RULES

    for name, per_element in (fc.get("nonmatching_families") or {}).items():
        key = f"{at}.nonmatching_families.{name}"
        if name not in FAMILY_RULES:
            raise ConfigError(key, "not a non-matching family", got=name, allowed=", ".join(FAMILY_RULES))
        for element, n1s in per_element.items():
            if element not in fc["elements"]:
                raise ConfigError(f"{key}.{element}", f"not an element of {at}.elements", got=element,
                                  allowed=", ".join(fc["elements"]))
            for i, n1 in enumerate(n1s):
                if FAMILY_RULES[name][0](n1) == n1:
                    raise ConfigError(f"{key}.{element}[{i}]", f"the {name} pair of N1 = {n1} is matching "
                                      f"(N2 = N1: matching meshes go under {at}.N)", got=n1, allowed="N1 >= 2")


def family_pairs(fc, element: str) -> list:
    """(N1, N2 = rule(N1)) of every ``membranes3d.nonmatching_families`` entry of ``element`` (module
    docstring: Ω2 the finer side), in the config's order."""
    from ..discretization.gamma.mesh_series import FAMILY_RULES

    return [(int(n1), FAMILY_RULES[name][0](int(n1)))
            for name, per_element in (fc.get("nonmatching_families") or {}).items()
            for n1 in per_element.get(element, ())]


def _check_l2_max_n(fc, at: str) -> None:
    """``membranes3d.l2_max_N``: an element with a ``membranes3d.max_N``, not below it, and L2 among the norms."""
    caps = fc.get("max_N") or {}
    for element, top in (fc.get("l2_max_N") or {}).items():
        key = f"{at}.l2_max_N.{element}"
        if element not in caps:
            raise ConfigError(key, f"an element with a {at}.max_N (without one every N gets both norms)",
                              got=element, allowed=", ".join(caps) or f"none: {at}.max_N is empty")
        if top < caps[element]:
            raise ConfigError(key, f"at least {at}.max_N.{element}", got=top, allowed=f">= {caps[element]}")
        if "L2" not in fc["norms"]:
            raise ConfigError(key, f"needs L2 in {at}.norms", got=fc["norms"], allowed=f"{at}.norms with L2")


def l2_only_sizes(fc, element: str) -> list:
    """The matching N of ``membranes3d.N`` above the element's ``membranes3d.max_N`` and up to its
    ``membranes3d.l2_max_N``: they get L²(Γ) rows only. The L² Gram is exact (a mass matrix); what
    ``max_N`` caps is the H^{-1/2}_00 Gram of the triangles (a double series per triangle), so the
    L² slope of Remark 3.1 gets finer meshes than the H rows can afford."""
    top, l2_top = (fc.get("max_N") or {}).get(element), (fc.get("l2_max_N") or {}).get(element)
    if top is None or l2_top is None:
        return []
    return [int(n) for n in fc["N"] if top < n <= l2_top]


def face_pairs(fc, element: str) -> list:
    """The mesh pairs of one element: every matching N and non-matching pair of the config,
    up to the element's ``membranes3d.max_N`` where it has one, then the element's family pairs
    (:func:`family_pairs`, not capped)."""
    top = (fc.get("max_N") or {}).get(element, max(max(fc["N"]), *(max(p) for p in fc["nonmatching"])))
    pairs = [(n, n) for n in fc["N"]] + [tuple(p) for p in fc["nonmatching"]]
    capped = [(a, b) for a, b in pairs if max(a, b) <= top]
    return list(dict.fromkeys(capped + family_pairs(fc, element)))


def _check_face_cases(cfg, fc, options, at: str) -> None:
    """Each face case is built by the face of one of the configured elements (``membranes3d.elements``
    or ``membranes3d.patch.elements``): a space no configured element carries (PWLIN-T6 with hexahedra
    only) was accepted and silently never computed."""
    from ..study.claims.membranes3d import element_interfaces

    patch = [e for e in fc["patch"]["elements"] if e in options]  # the others: check_face_studies
    elements = list(dict.fromkeys([*fc["elements"], *patch]))
    check_face_case_ids(cfg, at, fc["cases"], fc["k"], element_interfaces(fc["model"], elements),
                        need_builder=True)


def check_face_case_ids(cfg, at: str, cases, ks_config, faces, need_builder: bool = False) -> None:
    """Each id of ``<at>.cases``: registered, defined for one of ``<at>.k``, and built
    on every face of ``faces`` (a list, or element → face) that builds it; ``need_builder``: at
    least one face must (the error names the elements and the ids their faces build)."""
    from ..discretization.spaces.user_spaces import config_case_ids
    from ..discretization.spaces.registry import SPACES
    from ..discretization.face.shapes.square import SQUARE
    from ..discretization.face.partitions.tensor_grid import TensorPartition

    ids = config_case_ids(cfg, gamma_dim=SQUARE.dim)
    names = list(faces) if isinstance(faces, dict) else None
    faces = list(faces.values()) if isinstance(faces, dict) else list(faces)
    x = np.linspace(0.0, 1.0, 3)
    for i, case in enumerate(cases):
        key = f"{at}.cases[{i}]"
        if case not in ids:
            raise ConfigError(key, f"{case!r} is not a registered space", got=case, allowed=", ".join(ids))
        spec = SPACES[case]
        ks = [k for k in ks_config if spec.valid_for(k)]
        if not ks:
            raise ConfigError(key, f"{case} is defined for none of {at}.k = {ks_config}", got=case,
                              allowed=f"k >= {spec.min_k} in {at}.k")
        builders = [g for g in faces if g.builds(spec)]  # the faces of the cells it is defined on
        if need_builder and not builders:
            carried = [c for c in ids if any(SPACES[c].valid_for(k) for k in ks_config)
                       and any(g.builds(SPACES[c]) for g in faces)]
            where = f"the elements {', '.join(names)}" if names else "the elements"
            raise ConfigError(key, f"{case} is built by the face of none of {where} (it would never be computed)",
                              got=case, allowed=", ".join(carried) or "none")
        try:
            for gamma in builders:
                gamma.space(spec, ks[0], TensorPartition(x, x))
        except Exception as err:  # noqa: BLE001 - any failure to build means: not a face space
            raise ConfigError(key, f"{case} cannot be built on the face ({err})", got=case) from None
