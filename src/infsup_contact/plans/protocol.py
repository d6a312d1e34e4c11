"""What a model study is to the workflow: its jobs, its tables, its claims and its paper files.

The model is an axis of the data. The config's model table (key ``studies``;
:mod:`infsup_contact.config.models`) names each study; one rule per stage takes the study's name
as its ``{model}`` wildcard (``workflow/rules/models.smk``: jobs and tables; ``claims.smk``;
``paper.smk``) and asks the study object, never the model, what to do. A study object answers four questions:

* :meth:`ModelStudy.jobs` — the tables computed in one process each, by name: the job ``j``
  of the study ``s`` writes ``results/tables/s/j.csv`` (:func:`job_path`);
* :meth:`ModelStudy.tables` — the study's tables, each the concatenation of some of its jobs
  (``results/tables/s_t.csv``, :func:`table_path`), read under a schema of
  :data:`infsup_contact.table_schemas.SCHEMAS`;
* :meth:`ModelStudy.claims` — its ledger claims (``results/tables/s_claims.csv``, appended to the
  ledger in the model table's order) from the files of :meth:`ModelStudy.claim_inputs`;
* :meth:`ModelStudy.paper_files` — its generated LaTeX (``results/paper/s/*.tex``) from the
  files of :meth:`ModelStudy.paper_inputs`, checked against its paper source if it has one.

Everything model-specific stays in the study's own module (:mod:`.elastic`, :mod:`.membranes3d`,
:mod:`.elastic3d`, :mod:`.beta`, :mod:`.arc`), each reading its scenes from its entry; the stages are shared.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Protocol


def job_path(study: str, job: str) -> str:
    """The table one job of ``study`` writes."""
    return f"results/tables/{study}/{job}.csv"


def table_path(study: str, table: str) -> str:
    """One of the study's joined tables."""
    return f"results/tables/{study}_{table}.csv"


def claims_path(study: str) -> str:
    """The study's ledger claims."""
    return f"results/tables/{study}_claims.csv"


@dataclass(frozen=True)
class Job:
    """One job: a table computed in one process.

    Attributes
    ----------
    run : callable
        ``run() -> DataFrame`` (timing columns dropped: timings belong to the benchmark tree).
    provenance : dict
        The config subtree whose hash the table's ``config_hash`` column records.
    mem_mb : callable
        ``mem_mb() -> int``: the job's memory estimate (``resources``), what a cluster job asks for
        (evaluated when asked: a job's own keys suffice to run it).
    shown : tuple of str
        Columns printed to the job's log (all when empty).
    """

    run: Callable
    provenance: dict
    mem_mb: Callable = lambda: 1000
    shown: tuple = ()


@dataclass(frozen=True)
class Table:
    """A joined table: the jobs it concatenates, in order, and the schema they are read under."""

    kind: str
    jobs: tuple


@dataclass(frozen=True)
class Inputs:
    """Files a stage reads, by name: ``{name: (path, schema kind)}``; ``optional`` names may be absent
    (a study that compares with another study's table when the config computes it)."""

    files: dict
    optional: frozenset = field(default_factory=frozenset)


class ModelStudy(Protocol):
    """A study of one model over the config's scenes of it (module docstring)."""

    name: str
    """The study's name: the ``{model}`` wildcard, its entry in the model table and its tables' prefix."""
    tex_source: str | None
    """The hand-written paper section its generated files are checked against (or None)."""
    in_paper: bool
    """Whether the paper reads its generated files (``results/paper/<name>/``)."""
    model_section: bool
    """Whether its files are one generated subsection listed in ``model_sections.tex``."""

    def jobs(self) -> dict: ...

    def tables(self) -> dict: ...

    def claim_inputs(self) -> Inputs: ...

    def claims(self, frames: dict, claims_cfg: dict): ...

    def paper_inputs(self) -> Inputs: ...

    def paper_files(self, frames: dict, params: dict) -> dict: ...
