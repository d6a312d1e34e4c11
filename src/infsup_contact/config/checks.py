"""Validation of the workflow configuration: one function, one line per error, before any job.

:func:`check_config` is what ``workflow/rules/common.smk`` runs on the loaded config; the
tests call it directly. In order, it

1. registers the user-defined spaces (key ``spaces``), so that their ids are case ids;
2. refuses non-finite numbers anywhere (``.nan``/``.inf``: no key gives them a meaning, and a
   JSON schema lets ``.nan`` through every ``minimum``);
3. validates against ``workflow/schemas/config.schema.yaml`` — a whole float such as ``4.0``
   is *not* an integer here, unlike in JSON Schema, because it would reach the jobs as a float;
4. checks the case ids against the registry and the degrees each space allows;
5. checks what a schema cannot state, across keys (:data:`CROSS_KEY_RULES`).

Every failure is a :class:`ConfigError` whose message is one line,
``config key <key>: <what> (got <value>; allowed <allowed>)``. What is allowed but worth
knowing (a fit window longer than a β series, shrunk explicitly) comes back as notes that the
workflow logs. Pure functions: no Snakemake; a field a β_h request has is checked by the
request's own rule (:mod:`infsup_contact.solvers.request`, the registry), imported where used
and run under the config key (:func:`~.schema.naming_key`).
"""
from __future__ import annotations

import re

from ..discretization.spaces.user_spaces import config_case_ids
from .meshes import check_space_meshes, config_intervals, scene_meshes
from .models import check_models, check_moved_sections, check_required_studies, scenes_of, study_entries
from .schema import (ConfigError, check_finite, describe, key_path, load_schema,  # noqa: F401
                            naming_key, schema_error, show)
from ..errors import InputError
from ..study.contact.registry import REFERENCE_MARGIN, data_scene_ids, scene_spec


MIN_FIT_POINTS = 3
"""A slope interval needs at least 3 meshes (one degree of freedom for Student's t)."""


# ------------------------------------------------------------------ 1. user spaces

def load_spaces(cfg) -> list:
    """Register the user spaces of key ``spaces``; their ``.py`` files (workflow inputs)."""
    from ..discretization.spaces.user_spaces import load_user_space

    refs = cfg.get("spaces") if isinstance(cfg, dict) else None
    refs = [] if refs is None else refs
    if not isinstance(refs, list) or not all(isinstance(r, str) for r in refs):
        raise ConfigError("spaces", "expected a list of FILE.py:FUNC or module:FUNC strings", got=refs,
                          allowed="e.g. [examples/macro_p0.py:space]")
    intervals = config_intervals(cfg)
    for i, ref in enumerate(refs):
        try:
            load_user_space(ref, intervals)
        except InputError as err:
            raise ConfigError(f"spaces[{i}]", str(err), got=ref, allowed="FILE.py:FUNC or module:FUNC "
                              "returning a valid SpaceSpec") from None
    return [r.rpartition(":")[0] for r in refs if r.rpartition(":")[0].endswith(".py")]


# ------------------------------------------------------------------ 4. the registry

def check_cases(cfg) -> None:
    """Case ids are registered spaces; each k is one the space allows (T4, T5: k >= 2; the
    request's rule, :func:`~infsup_contact.discretization.spaces.registry.check_case`)."""
    from ..discretization.spaces.registry import SPACES, check_case

    ids = config_case_ids(cfg, gamma_dim=1)  # the 2D stages: Γ a curve
    for stage in ("infsup", "contact"):
        cases = cfg[stage]["cases"]
        for case, ks in cases.items():
            if case not in ids:
                raise ConfigError(f"{stage}.cases", f"{case!r} was unexpected", got=case,
                                  allowed="registered spaces: " + ", ".join(ids)
                                  + ("" if case not in SPACES else f" ({case} is a face space of the 3D models)"
                                     if not SPACES[case].defined_on(1) else f" ({case} is a user space: list it under spaces)"))
            spec = SPACES[case]
            with naming_key(f"{stage}.cases.{case}", f"{case} needs k >= {spec.min_k} ({spec.paper_ref})",
                            got=ks, allowed=f"degrees {spec.min_k}..4"):
                for k in ks:
                    check_case(case, k)


def figure_cases(cfg):
    """Every case a figure of the config shows: yields ``(key, case id, k or None)`` (k None:
    every k the figure's table has, as figures.nu_slope_cases)."""
    fc = cfg["figures"]
    for name in ("contact_solutions", "dual"):
        for i, case in enumerate(fc[name]["cases"]):
            yield f"figures.{name}.cases[{i}]", case, fc[name]["k"]
    for i, (case, k) in enumerate(fc["elastic_profiles"]["pairs"]):
        yield f"figures.elastic_profiles.pairs[{i}]", case, k
    for i, case in enumerate(fc["nu_slope_cases"]):
        yield f"figures.nu_slope_cases[{i}]", case, None
    for name in ("face_mode", "arc_mode"):  # optional: drawn where the face / arc study runs
        if fc.get(name):
            yield f"figures.{name}.case", fc[name]["case"], fc[name]["k"]


def check_figures(cfg) -> None:
    """A figure's case ids are registered spaces (the built-in ones and the config's own user
    spaces) defined for its k (the request's rule, as :func:`check_cases`); its scene is a name
    under contact.scenes or a scene kind."""
    from ..discretization.spaces.registry import SPACES, check_case

    ids = config_case_ids(cfg, gamma_dim=1)  # the 2D stages: Γ a curve
    for key, case, k in figure_cases(cfg):
        if case not in ids:
            raise ConfigError(key, f"{case!r} is not a registered space", got=case,
                              allowed="registered spaces: " + ", ".join(ids))
        spec = SPACES[case]
        if k is not None:
            with naming_key(key, f"{case} needs k >= {spec.min_k} ({spec.paper_ref}), the figure has k = {k}",
                            got=case, allowed=f"spaces defined for k = {k}"):
                check_case(case, k)
    mode, face = cfg["figures"].get("face_mode"), scenes_of(cfg, "membranes3d")
    if mode and face:
        from ..models import MODELS
        from ..solvers.request import check_mesh_option

        model = MODELS.get(face["model"])  # a model without a face is the face study's own refusal
        if model is not None and dict(model.mesh_options).get("element"):
            with naming_key("figures.face_mode.element", f"not an element of the face model {model.name}"):
                check_mesh_option(model, "element", mode["element"])
    arc = cfg["figures"].get("arc_mode")
    if arc and arc["N1"] == arc["N2"]:
        raise ConfigError("figures.arc_mode.N2", "a non-matching pair: the projection is the identity on matching "
                          "meshes", got=arc["N2"], allowed=f"N2 != N1 = {arc['N1']}")
    kinds = data_scene_ids()
    for name in ("contact_solutions", "dual"):
        scene = cfg["figures"][name]["scene"]
        if scene not in cfg["contact"]["scenes"] and scene not in kinds:
            raise ConfigError(f"figures.{name}.scene", f"{scene!r} is neither a scene of contact.scenes nor a kind",
                              got=scene, allowed="names under contact.scenes: " + ", ".join(cfg["contact"]["scenes"])
                              + "; kinds: " + ", ".join(kinds))


# ------------------------------------------------------------------ 5. across keys

SCENE_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]{0,39}")
"""A scene name becomes part of file names and Snakemake wildcards (``{scene}_{family}_k{k}``)
and of the paper's tables: letters, digits, ``_`` and ``-``, starting with a letter."""


def check_scene_names(cfg) -> None:
    """Every key of contact.scenes is a safe name (:data:`SCENE_NAME`): ``""`` or ``x{k}``
    would break the job file names and their wildcards."""
    for name in cfg["contact"]["scenes"]:
        if not isinstance(name, str) or not SCENE_NAME.fullmatch(name):
            raise ConfigError("contact.scenes", "a scene name that can be part of file names, Snakemake "
                              "wildcards and LaTeX", got=name, allowed="letters, digits, '_' and '-', starting "
                              "with a letter, at most 40 characters (e.g. manufactured_lowreg)")


def check_reference(cfg) -> None:
    """contact.reference_N >= REFERENCE_MARGIN × the largest N of every membranes scene."""
    cc = cfg["contact"]
    for name, spec in cc["scenes"].items():
        if not scene_spec(spec["kind"]).needs_reference:
            continue
        ns = scene_meshes(cfg)[name]
        need = REFERENCE_MARGIN * max(ns)
        if cc["reference_N"] < need:
            raise ConfigError(
                "contact.reference_N", f"the membranes reference must be {REFERENCE_MARGIN}x finer than the "
                f"finest mesh it measures (scene {name} runs N up to {max(ns)}; a coarser reference "
                "gives errors that are not errors)", got=cc["reference_N"], allowed=f"reference_N >= {need}")


def check_rate_window(cfg) -> None:
    """contact.rate_window <= the number of meshes of every scene: refused, never shrunk."""
    rw = cfg["contact"]["rate_window"]
    name, ns = min(scene_meshes(cfg).items(), key=lambda item: len(item[1]))  # the shortest series
    if rw > len(ns):
        raise ConfigError("contact.rate_window", f"longer than the mesh series it fits (scene {name} "
                          f"has {len(ns)} meshes, N = {ns}; a window is never shrunk silently)",
                          got=rw, allowed=f"2..{len(ns)}")


def check_nonmatching(cfg) -> None:
    """A non-matching pair has N1 ≠ N2 (matching pairs belong in infsup.N)."""
    for i, pair in enumerate(cfg["infsup"].get("nonmatching", [])):
        if pair[0] == pair[1]:
            raise ConfigError(f"infsup.nonmatching[{i}]", "a non-matching pair needs N1 != N2", got=pair,
                              allowed="[N1, N2] with N1 != N2 (matching meshes go under infsup.N)")


def check_membranes_parameters(cfg) -> None:
    """A membranes scene takes no manufactured-solution parameter (p, q, a)."""
    for name, spec in cfg["contact"]["scenes"].items():
        if scene_spec(spec["kind"]).needs_reference:
            extra = [key for key in spec if key not in ("kind", "N")]
            if extra:
                raise ConfigError(f"contact.scenes.{name}.{extra[0]}", f"a {spec['kind']} scene takes no such "
                                  "parameter (p, q, a belong to a scene with an exact solution)",
                                  got=spec[extra[0]], allowed="the keys kind, N")


def check_primary_scene(cfg) -> None:
    """contact.primary_scene is a scene of contact.scenes whose kind has an exact solution (the
    rates it leads with are claimed against the rate that solution allows)."""
    cc = cfg["contact"]
    name = cc["primary_scene"]
    exact = [s for s, spec in cc["scenes"].items() if scene_spec(spec["kind"]).energy_rate is not None]
    if name not in exact:
        raise ConfigError("contact.primary_scene", "not a scene of contact.scenes with an exact solution",
                          got=name, allowed="one of " + (", ".join(exact) or "(none: add a scene of kind "
                                                         + ", ".join(k for k in data_scene_ids()
                                                                     if scene_spec(k).energy_rate) + ")"))


def speed_accuracy_scene(cfg) -> str:
    """The scene the speed/accuracy benchmark times: benchmarks.speed_accuracy_scene, else
    contact.primary_scene."""
    return cfg["benchmarks"].get("speed_accuracy_scene", cfg["contact"]["primary_scene"])


def check_speed_accuracy_scene(cfg) -> None:
    """benchmarks.speed_accuracy_scene names a contact scene or a scene kind."""
    name = speed_accuracy_scene(cfg)
    allowed = [*cfg["contact"]["scenes"], *(k for k in data_scene_ids() if k not in cfg["contact"]["scenes"])]
    if name not in allowed:
        raise ConfigError("benchmarks.speed_accuracy_scene", "not a scene of contact.scenes nor a scene kind",
                          got=name, allowed="one of " + ", ".join(allowed))


def check_elastic_nonmatching(cfg) -> None:
    """An elastic study's non-matching pair (β_h table, patch test) has N1 ≠ N2."""
    for at, ec in study_entries(cfg, "elastic"):
        for key in ("nonmatching", "patch_pairs"):
            for i, pair in enumerate(ec[key]):
                if pair[0] == pair[1]:
                    raise ConfigError(f"{at}.{key}[{i}]", "a non-matching pair needs N1 != N2", got=pair,
                                      allowed=f"[N1, N2] with N1 != N2 (matching meshes go under {at}.N)")


def check_hertz_reference(cfg) -> None:
    """An elastic study's hertz.N_ref >= REFERENCE_MARGIN × its largest hertz.N (as the membranes)."""
    for at, ec in study_entries(cfg, "elastic"):
        hz = ec["hertz"]
        need = REFERENCE_MARGIN * max(hz["N"])
        if hz["N_ref"] < need:
            raise ConfigError(f"{at}.hertz.N_ref", f"the Hertz reference must be {REFERENCE_MARGIN}x finer than "
                              f"the finest mesh it measures (N up to {max(hz['N'])})", got=hz["N_ref"],
                              allowed=f"N_ref >= {need}")


from .elastic3d import check_elastic3d  # noqa: E402 (config/elastic3d.py)
from .membranes3d import check_membranes3d  # noqa: E402 (config/membranes3d.py)

CROSS_KEY_RULES = {
    # rule: the keys it relates (the error names the first; a change to any of them can trip it)
    check_cases: ("infsup.cases", "contact.cases", "spaces"),
    check_figures: ("figures", "contact.scenes", "spaces"),
    check_scene_names: ("contact.scenes",),
    check_reference: ("contact.reference_N", "contact.scenes", "contact.N"),
    check_rate_window: ("contact.rate_window", "contact.scenes", "contact.N"),
    check_nonmatching: ("infsup.nonmatching",),
    check_membranes_parameters: ("contact.scenes",),
    check_primary_scene: ("contact.primary_scene", "contact.scenes"),
    check_speed_accuracy_scene: ("benchmarks.speed_accuracy_scene", "contact.scenes", "contact.primary_scene"),
    check_required_studies: ("studies",),  # first of the table's rules: the others read its elastic entry
    check_models: ("studies", "spaces"),
    check_elastic_nonmatching: ("studies.elastic.nonmatching", "studies.elastic.patch_pairs"),
    check_hertz_reference: ("studies.elastic.hertz.N_ref", "studies.elastic.hertz.N"),
    check_membranes3d: ("studies.membranes3d.model", "studies.membranes3d.elements",
                        "studies.membranes3d.nonmatching", "studies.membranes3d.nonmatching_families",
                        "studies.membranes3d.cases", "studies.membranes3d.max_N", "studies.membranes3d.l2_max_N",
                        "studies.membranes3d.norms", "spaces"),
    check_elastic3d: ("studies.elastic3d.model", "studies.elastic3d.elements", "studies.elastic3d.nu",
                     "studies.elastic3d.nu_sweep", "studies.elastic3d.nonmatching",
                     "studies.elastic3d.cases", "studies.elastic3d.patch", "spaces"),
    check_space_meshes: ("infsup.N", "infsup.nonmatching", "infsup.nonmatching_families", "contact.N",
                         "contact.scenes", "studies.elastic.N", "studies.elastic.nonmatching",
                         "studies.elastic.patch_pairs", "studies.elastic.bench_N", "studies.elastic.hertz.N",
                         "studies.elastic.hertz.modeling_N", "benchmarks.beta_N",
                         "benchmarks.contact_N", "claims.rem55_N", "infsup.cases", "contact.cases",
                         "figures.contact_solutions", "figures.dual", "figures.elastic_profiles"),
}
"""The rules a schema cannot state, with the keys each relates; each raises a
:class:`ConfigError` naming one of them."""


def beta_series(cfg) -> dict:
    """The mesh series the claims ledger fits (per family, case, k and norm alike): matching
    even and odd N, and every non-matching series (discretization/gamma/mesh_series.py) by N2."""
    from ..discretization.gamma.mesh_series import beta_series as series, describe

    ic = cfg["infsup"]
    ns = sorted(ic["N"])
    out = {"even-N": [n for n in ns if n % 2 == 0], "odd-N": [n for n in ns if n % 2 == 1]}
    for name, pairs in series(ic).items():
        if name != "matching":
            out[f"non-matching {describe(name)} (N2)"] = sorted({p[1] for p in pairs})
    return out


def fit_window_notes(cfg) -> list:
    """claims.fit_window longer than a β series: that series is fitted on all its meshes (an
    explicit, logged shrink); a series with fewer than 3 meshes gives no slope claim."""
    win = cfg["claims"]["fit_window"]
    notes = []
    for name, ns in beta_series(cfg).items():
        if not ns:
            continue
        if len(ns) < MIN_FIT_POINTS:
            notes.append(f"config key claims.fit_window: the {name} β series has {len(ns)} meshes ({ns}): "
                         f"its slope claims are skipped (a slope interval needs {MIN_FIT_POINTS})")
        elif win > len(ns):
            notes.append(f"config key claims.fit_window = {win}: the {name} β series has {len(ns)} meshes "
                         f"({ns}); its fits use all {len(ns)} (shrunk explicitly)")
    return notes


# ------------------------------------------------------------------ all of it

def check_config(cfg, schema) -> tuple[list, list]:
    """Validate a loaded config (``schema``: dict or path of the YAML schema).

    Returns ``(user_space_files, notes)``; raises :class:`ConfigError` (one line) on the
    first bad value.
    """
    if not isinstance(schema, dict):
        schema = load_schema(schema)
    if not isinstance(cfg, dict):
        raise ConfigError("(top level)", "the config file must be a mapping of keys", got=type(cfg).__name__,
                          allowed=describe(schema))
    check_moved_sections(cfg)
    files = load_spaces(cfg)
    check_finite(cfg)
    err = schema_error(cfg, schema)
    if err is not None:
        raise err
    for rule in CROSS_KEY_RULES:  # check_cases (the registry) first: the others assume valid ids
        rule(cfg)
    return files, fit_window_notes(cfg)
