"""Cross-key checks of the model table's ``elastic3d`` studies (the 3D elastic bodies on the
contact face).

What the schema cannot state: the model is a registered 3D model whose stiffness takes the
Poisson ratio ``nu`` (a model parameter, :attr:`~infsup_contact.models.contract.Model.params`),
each element is one of its ``element`` mesh options, every ν lies in (−1, 1/2)
(:func:`~infsup_contact.models.plane_strain.check_nu`), at least 3 of the sweep's ν lie at or
above ``fit_nu_min`` (a slope fit), the sweep's meshes are among ``N``, non-matching pairs have
N1 ≠ N2, and each case is a registered space defined for some k of ``k`` and built by the face
of some listed element. Each raises one :class:`~infsup_contact.config.schema.ConfigError`
naming the key.
"""
from __future__ import annotations

from .membranes3d import check_element
from .schema import ConfigError, naming_key

MIN_FIT_POINTS = 3
"""A slope fit of the ν sweep needs this many ν >= fit_nu_min."""


def check_elastic3d(cfg) -> None:
    """Check every ``elastic3d`` study of the model table (none: nothing to check)."""
    from .models import study_entries

    for at, fe in study_entries(cfg, "elastic3d"):
        _check_elastic3d(cfg, fe, at)


def _check_elastic3d(cfg, fe: dict, at: str) -> None:
    """Check one elastic face study's scenes ``fe``, its errors naming the keys under ``at``."""
    from ..models import MODELS

    model = MODELS.get(fe["model"])
    taking = [m.name for m in MODELS.values() if getattr(m, "dim", 2) == 3 and _takes_nu(m)]
    if model is None or model.name not in taking:
        raise ConfigError(f"{at}.model", "not a registered 3D model taking the Poisson ratio nu",
                          got=fe["model"], allowed=", ".join(taking))
    for key, elements in ((f"{at}.elements", fe["elements"]),
                          (f"{at}.patch.elements", fe["patch"]["elements"])):
        for i, element in enumerate(elements):
            check_element(f"{key}[{i}]", model, element)
    _check_nus(fe, at)
    for key, pairs in ((f"{at}.nonmatching", fe["nonmatching"]), (f"{at}.patch.pairs",
                                                                         fe["patch"]["pairs"])):
        for i, pair in enumerate(pairs):
            if pair[0] == pair[1]:
                raise ConfigError(f"{key}[{i}]", "a non-matching pair needs N1 != N2", got=pair,
                                  allowed=f"[N1, N2] with N1 != N2 (matching meshes go under {at}.N)")
    for i, n in enumerate(fe["nu_sweep"]["N"]):
        if n not in fe["N"]:
            raise ConfigError(f"{at}.nu_sweep.N[{i}]", f"not a mesh of {at}.N", got=n,
                              allowed=", ".join(str(m) for m in fe["N"]))
    _check_cases(cfg, fe, model, at)


def _takes_nu(model) -> bool:
    return any(p.name == "nu" and p.side is None for p in model.params)


def _check_nus(fe, at: str) -> None:
    from ..models.plane_strain import check_nu

    sweep = fe["nu_sweep"]
    for key, value in [(f"{at}.nu", fe["nu"])] + [(f"{at}.nu_sweep.nu[{i}]", v)
                                                         for i, v in enumerate(sweep["nu"])]:
        with naming_key(key, "not a Poisson ratio", got=value, allowed="-1 < nu < 0.5"):
            check_nu(value, key)
    kept = sorted(v for v in sweep["nu"] if v >= sweep["fit_nu_min"])
    if len(kept) < MIN_FIT_POINTS:
        raise ConfigError(f"{at}.nu_sweep.fit_nu_min", f"keeps fewer than {MIN_FIT_POINTS} of "
                          f"{at}.nu_sweep.nu (a slope fit needs 3)", got=sweep["fit_nu_min"],
                          allowed=(f"<= {sorted(sweep['nu'])[-MIN_FIT_POINTS]}" if len(sweep["nu"]) >= MIN_FIT_POINTS
                                   else "more ν"))


def _check_cases(cfg, fe, model, at: str) -> None:
    from .membranes3d import check_face_case_ids
    from ..study.claims.membranes3d import element_interfaces

    faces = element_interfaces(model, sorted(set(fe["elements"]) | set(fe["patch"]["elements"])))
    check_face_case_ids(cfg, at, fe["cases"], fe["k"], list(faces.values()), need_builder=True)
