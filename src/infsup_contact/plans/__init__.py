"""The model table: each model study's jobs, tables, claims and paper files (:mod:`.protocol`).

The config key ``models`` lists the studies by name with the study each runs (:data:`STUDIES`);
:func:`model_table` reads it and :func:`study_of` builds one. The workflow's stages take the
study's name as their ``{model}`` wildcard and ask this package everything else.
"""
from __future__ import annotations

from .arc import ArcStudy, CylinderStudy
from .beta import BetaStudy
from .elastic import ElasticStudy
from .face import FaceStudy
from .face_elastic import FaceElasticStudy
from .protocol import Inputs, Job, ModelStudy, Table, claims_path, job_path, table_path

STUDIES = {"elastic": ElasticStudy, "face": FaceStudy, "face_elastic": FaceElasticStudy, "beta": BetaStudy,
           "arc": ArcStudy, "cylinder": CylinderStudy}
"""What a model-table entry's ``study`` may be. The first three read the config section named like
the entry (their scenes predate the table); ``beta``, ``arc`` and ``cylinder`` read their scenes from the entry
itself."""
SECTION_STUDIES = ("elastic", "face", "face_elastic")
"""Built-in studies whose scenes live in the config section of the entry's name."""


def model_table(config: dict) -> dict:
    """``{name: entry}`` of the config's model table in its order; without a ``models`` key, one
    entry per built-in study whose section the config has (the sections' own order)."""
    if config.get("models") is not None:
        return dict(config["models"])
    return {s: {"study": s} for s in SECTION_STUDIES if config.get(s) is not None}


def study_of(config: dict, name: str) -> ModelStudy:
    """The study ``name`` of the config's model table."""
    table = model_table(config)
    entry = table[name]
    kind = entry["study"]
    if kind in ("beta", "arc", "cylinder"):
        return STUDIES[kind](name, entry)
    if kind == "face_elastic":  # its kernel claims compare with a face study's table, when there is one
        membranes = next((n for n, e in table.items() if e["study"] == "face"), None)
        return FaceElasticStudy(name, config, membranes)
    return STUDIES[kind](name, config)


__all__ = ["Inputs", "Job", "ModelStudy", "Table", "STUDIES", "claims_path", "job_path", "model_table", "study_of",
           "table_path"]
