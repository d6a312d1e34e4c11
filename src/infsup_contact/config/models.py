"""The config's model table (key ``studies``; :mod:`infsup_contact.plans`): reading it, and the
cross-key checks the schema cannot state.

Every study carries its scenes in its entry (:func:`scenes`). The studies the paper's sections and
figures read by name (``elastic``, ``membranes3d``, ``elastic3d``: :data:`NAMED`, each named by its
model) are entries of that name, and the table has an ``elastic`` one; a config that still has their
old top-level sections, old study names or the old table key ``models`` is told where they moved
(:func:`check_moved_sections`). A ``beta`` study names a model (registered, or ``FILE.py:NAME``
imported here once, so a wrong file stops the run before any job) and its scenes ``k``, ``N`` and ``cases``; each element is one of the model's ``element`` options
(none for a model without them); each case is a registered space defined for some k and built by
the model's Γ; a study's name does not shadow a folder the other stages write under
``results/tables/`` (:data:`RESERVED`). Each raises one
:class:`~infsup_contact.config.schema.ConfigError` naming the key.
"""
from __future__ import annotations

from ..errors import InputError
from .schema import ConfigError, naming_key

NAMED = ("elastic", "membranes3d", "elastic3d")
"""Studies whose files the paper's sections and figures read by the study's name
(``results/paper/<name>/``, ``results/tables/<name>_*.csv``): their entry has that name."""
TABLE_KEY, OLD_TABLE_KEY = "studies", "models"
"""The model table's config key, and the one it had (refused, naming the new)."""
RENAMED = {"face": "membranes3d", "face_elastic": "elastic3d"}
"""The studies' old names (``study:`` values and top-level sections) → their model's name."""
REQUIRED = ("elastic",)
"""Studies the table must have: the paper's elastic section, fig9 and the elastic benchmark read it."""
RESERVED = ("beta", "contact", "mesh_quality", "claims", "producers", "references", "rates")
"""Names the other stages' tables use (``results/tables/<name>/`` or ``<name>_*.csv``)."""
BETA_KEYS = ("model", "k", "N", "cases")
"""What a ``beta`` study's entry must state."""


def model_table(config: dict) -> dict:
    """``{name: entry}`` of the config's model table (key :data:`TABLE_KEY`) in its order."""
    return dict(config.get(TABLE_KEY) or {})


def scenes(entry: dict) -> dict:
    """A model-table entry's scenes: the entry without its ``study`` (what its jobs' provenance hashes)."""
    return {key: value for key, value in entry.items() if key != "study"}


def study_names(config: dict, study: str) -> list:
    """The names of the entries running ``study``, in the table's order."""
    return [name for name, e in model_table(config).items() if e.get("study") == study]


def study_entries(config: dict, study: str) -> list:
    """``[(key, scenes)]`` of every entry running ``study``, ``key`` = ``studies.<name>`` (what errors name)."""
    table = model_table(config)
    return [(f"{TABLE_KEY}.{name}", scenes(table[name])) for name in study_names(config, study)]


def scenes_of(config: dict, study: str) -> dict | None:
    """The scenes of the table's first entry running ``study`` (None: it has none), for the stages
    outside the table that draw or time that model (the elastic benchmark, the face figures)."""
    entries = study_entries(config, study)
    return entries[0][1] if entries else None


def check_moved_sections(cfg) -> None:
    """A config written before the wings joined the model table, or before each took its model's
    name: the table under its old key ``models`` is refused, naming ``studies`` (its entries are
    studies: some name a model, ``arc``, ``cylinder``, ``hex20`` a Γ shape or an element); a
    top-level section ``elastic``, ``face`` or ``face_elastic`` is refused, naming where its keys
    now live (unchanged, under the entry of the model's name, :data:`RENAMED`); so is an entry whose
    ``study`` is an old name. Run before the schema, whose message (an unknown top-level key, a
    value not in an enum) would not say where it went."""
    if not isinstance(cfg, dict):
        return
    if OLD_TABLE_KEY in cfg:
        raise ConfigError(OLD_TABLE_KEY, f"the model table is the key {TABLE_KEY!r} now (its entries unchanged: "
                          "each a study, named by its model or by its Γ shape)", got=f"<a `{OLD_TABLE_KEY}:` section>",
                          allowed=f"{TABLE_KEY}: {{<name>: {{study: ..., ...}}}} (config/config.yaml has one)")
    for old in ("elastic", *RENAMED):
        if old in cfg:
            new = RENAMED.get(old, old)
            raise ConfigError(old, f"the top-level section moved into the model table: its keys go, unchanged, "
                              f"under {TABLE_KEY}.{new} beside `study: {new}`", got=f"<a top-level `{old}:` section>",
                              allowed=f"{TABLE_KEY}: {{{new}: {{study: {new}, <the keys of the old section>}}}} "
                              "(config/config.yaml has one)")
    table = cfg.get(TABLE_KEY)
    for name, entry in (table.items() if isinstance(table, dict) else ()):
        study = entry.get("study") if isinstance(entry, dict) else None
        if isinstance(study, str) and study in RENAMED:
            new = RENAMED[study]
            raise ConfigError(f"{TABLE_KEY}.{name}.study", f"the study {study!r} is named by its model now: "
                              f"{new!r} (its keys unchanged, the entry named {new})", got=study,
                              allowed=f"{TABLE_KEY}: {{{new}: {{study: {new}, ...}}}}")


def check_required_studies(cfg) -> None:
    """The model table has the studies of :data:`REQUIRED` (the workflow's other stages read them)."""
    table = model_table(cfg)
    for study in REQUIRED:
        if not any(e["study"] == study for e in table.values()):
            raise ConfigError(TABLE_KEY, f"no {study} study (the paper's {study} section, its figure and benchmark "
                              "read it)", got=sorted(table), allowed=f"a model table with the entry "
                              f"{study}: {{study: {study}, ...}} (config/config.yaml has one)")


def check_models(cfg) -> None:
    """Check ``cfg["studies"]``: names, the named studies, each ``beta``/``arc``/``cylinder`` entry."""
    table = model_table(cfg)
    for name, entry in table.items():
        key = f"{TABLE_KEY}.{name}"
        if name in RESERVED:
            raise ConfigError(key, "a name the other stages' tables use", got=name,
                              allowed=f"any other name (not {', '.join(RESERVED)})")
        study = entry["study"]
        if study in NAMED and name != study:
            raise ConfigError(f"{key}.study", f"the paper and its figures read the {study} study's files by "
                              f"the name {study!r}: its entry must have that name", got=name,
                              allowed=f"{TABLE_KEY}: {{{study}: {{study: {study}, ...}}}}")
        if study in ("arc", "cylinder"):
            _check_arc(key, entry, 1 if study == "arc" else 2)
        elif study == "beta":
            _check_beta(key, entry)


def _check_beta(key: str, entry: dict) -> None:
    from ..discretization.spaces.registry import SPACES
    from ..models.user_models import model_named
    from ..solvers.request import check_mesh_option

    missing = [k for k in BETA_KEYS if k not in entry]
    if missing:
        raise ConfigError(f"{key}.{missing[0]}", "required by a beta study", got=None,
                          allowed=", ".join(BETA_KEYS) + " (elements, nonmatching, norms optional)")
    try:
        model = model_named(entry["model"])
    except InputError as err:
        raise ConfigError(f"{key}.model", err.allowed, got=entry["model"]) from None
    options = dict(model.mesh_options).get("element", ())
    elements = entry.get("elements")
    for i, element in enumerate(elements or []):  # the request's rule (solvers/request.py), named by key
        with naming_key(f"{key}.elements[{i}]", f"not an element of {model.name}",
                        allowed=None if options else "none: the model has no element option (drop the key)"):
            check_mesh_option(model, "element", element)
    if options and not elements:
        raise ConfigError(f"{key}.elements", f"{model.name} builds several elements: name them", got=None,
                          allowed=", ".join(options))
    for i, (n1, n2) in enumerate(entry.get("nonmatching", [])):
        if n1 == n2:
            raise ConfigError(f"{key}.nonmatching[{i}]", "a non-matching pair needs N1 != N2", got=[n1, n2],
                              allowed="[N1, N2] with N1 != N2 (matching meshes go under N)")
    gammas = [model.gamma(element=e) for e in elements] if elements else [model.gamma()]
    ks = [int(k) for k in entry["k"]]
    for i, gamma in enumerate(gammas):
        bad = [k for k in ks if not gamma.allows(k)]
        if bad:
            raise ConfigError(f"{key}.elements[{i}]" if elements else f"{key}.k", f"the model's bodies have no "
                              f"degree k = {bad[0]}", got=elements[i] if elements else bad[0],
                              allowed="degrees every listed element has (k)")
    for i, case in enumerate(entry["cases"]):
        spec = SPACES.get(case)
        if spec is None:
            raise ConfigError(f"{key}.cases[{i}]", "not a registered space", got=case, allowed=", ".join(SPACES))
        if not any(spec.valid_for(k) for k in ks) or not any(g.builds(spec) for g in gammas):
            raise ConfigError(f"{key}.cases[{i}]", f"not defined for k in {ks} on the model's Γ", got=case,
                              allowed=", ".join(c for c, s in SPACES.items()
                                                if any(s.valid_for(k) for k in ks) and any(g.builds(s) for g in gammas)))


ARC_KEYS = ("k", "radii", "couplings", "series", "cases")
"""What an ``arc`` study's entry must state."""
ARC_FOREIGN = ("model", "elements", "N", "nonmatching", "norms")
"""Keys of a ``beta`` study an arc entry does not read (its model is the 2D membranes)."""


def _check_arc(key: str, entry: dict, gamma_dim: int) -> None:
    from ..discretization.spaces.registry import SPACES

    missing = [k for k in ARC_KEYS if k not in entry]
    if missing:
        raise ConfigError(f"{key}.{missing[0]}", "required by an arc study", got=None, allowed=", ".join(ARC_KEYS))
    foreign = [k for k in ARC_FOREIGN if k in entry]
    if foreign:
        raise ConfigError(f"{key}.{foreign[0]}", "not read by an arc study (the 2D membranes, both norms)",
                          got=entry[foreign[0]], allowed=", ".join(ARC_KEYS))
    ks = [int(k) for k in entry["k"]]
    for name, pairs in entry["series"].items():
        if len({tuple(p) for p in pairs}) < 3:
            raise ConfigError(f"{key}.series.{name}", "a verdict fits a slope over at least 3 distinct pairs",
                              got=pairs, allowed="3 or more distinct [N1, N2] pairs")
    for i, case in enumerate(entry["cases"]):
        spec = SPACES.get(case)
        if spec is None or gamma_dim not in spec.gamma_dims or not any(spec.valid_for(k) for k in ks):
            raise ConfigError(f"{key}.cases[{i}]", f"not a space of the {'segment' if gamma_dim == 1 else 'face'} "
                              f"defined for k in {ks}", got=case,
                              allowed=", ".join(c for c, s in SPACES.items()
                                                if gamma_dim in s.gamma_dims and any(s.valid_for(k) for k in ks)))
    if gamma_dim == 2 and entry.get("patch"):
        raise ConfigError(f"{key}.patch", "a cylinder study has no patch test (contact scenes are not built on a "
                          "curved face)", got=entry["patch"], allowed="no patch key")
