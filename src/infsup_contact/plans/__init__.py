"""The model table: each model study's jobs, tables, claims and paper files (:mod:`.protocol`).

The config key ``studies`` lists the studies by name with the study each runs (:data:`STUDIES`);
:func:`model_table` reads it and :func:`study_of` builds one. The workflow's stages take the
study's name as their ``{model}`` wildcard and ask this package everything else.
"""
from __future__ import annotations

from ..config.models import model_table, scenes, scenes_of, study_names
from .arc import ArcStudy, CylinderStudy
from .beta import BetaStudy
from .elastic import ElasticStudy
from .elastic3d import Elastic3dStudy
from .membranes3d import Membranes3dStudy
from .protocol import Inputs, Job, ModelStudy, Table, claims_path, job_path, table_path


def _elastic(name: str, entry: dict, config: dict) -> ElasticStudy:
    """Its spaces are the membranes' (``infsup.cases``): one list for both."""
    return ElasticStudy(name, scenes(entry), list(config["infsup"]["cases"]))


def _elastic3d(name: str, entry: dict, config: dict) -> Elastic3dStudy:
    """Its kernel claims compare with a membranes3d study's table, when the table has one."""
    membranes = next(iter(study_names(config, "membranes3d")), None)
    return Elastic3dStudy(name, scenes(entry), membranes)


STUDIES = {"elastic": _elastic, "membranes3d": lambda name, entry, config: Membranes3dStudy(name, scenes(entry)),
           "elastic3d": _elastic3d, "beta": lambda name, entry, config: BetaStudy(name, entry),
           "arc": lambda name, entry, config: ArcStudy(name, entry),
           "cylinder": lambda name, entry, config: CylinderStudy(name, entry)}
"""What a model-table entry's ``study`` may be, each ``(name, entry, config) -> study``: every study
reads its scenes from its entry (:func:`scenes`)."""


def study_of(config: dict, name: str) -> ModelStudy:
    """The study ``name`` of the config's model table."""
    entry = model_table(config)[name]
    return STUDIES[entry["study"]](name, entry, config)


__all__ = ["Inputs", "Job", "ModelStudy", "Table", "STUDIES", "claims_path", "job_path", "model_table", "scenes",
           "scenes_of", "study_of", "table_path"]
