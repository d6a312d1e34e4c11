"""β_h of any model: the study a new model gets from a model file and one model-table entry.

The entry (config ``studies.<name>``, :mod:`infsup_contact.config.models`) names the model (a
registered name or ``FILE.py:NAME``, :mod:`infsup_contact.models.user_models`) and its scenes:
degrees ``k``, matching meshes ``N``, non-matching pairs ``nonmatching``, the model's ``elements``
(its mesh option, where it has one), the ``cases`` and the ``norms``. Jobs: one per (element, k),
every pair, every case the element's Γ builds, G_h = trace of Ω2, through the one β batch path of
every model. Claims: :mod:`infsup_contact.study.claims.any_model` (predictions from the registry
and the dimension count alone). Paper: one generated subsection ``<name>.tex`` (the β table),
listed in ``model_sections.tex`` that ``paper/paper.tex`` reads.
"""
from __future__ import annotations

import pandas as pd

from .. import resources
from .protocol import Inputs, Job, Table, claims_path, table_path

NO_ELEMENT = "-"
"""The ``element`` cell of a model without an element option (its one element)."""


def pairs_of(entry: dict) -> list:
    """Every matching N and non-matching pair of the entry, each once, in that order."""
    pairs = [(int(n), int(n)) for n in entry["N"]] + [tuple(int(x) for x in p) for p in entry.get("nonmatching", [])]
    return list(dict.fromkeys(pairs))


class BetaStudy:
    """β_h, kernels and their claims for the model of one model-table entry (module docstring)."""

    tex_source = None
    in_paper = True
    model_section = True

    def __init__(self, name: str, entry: dict):
        self.name, self.cfg = name, entry

    @property
    def elements(self) -> list:
        return list(self.cfg.get("elements") or [NO_ELEMENT])

    def model(self):
        from ..models.user_models import model_named

        return model_named(self.cfg["model"])

    @staticmethod
    def options(element: str):
        """The :class:`~infsup_contact.solvers.request.MeshOptions` of an element of the table
        (none set for the model's one element)."""
        from ..solvers.request import MeshOptions

        return MeshOptions() if element == NO_ELEMENT else MeshOptions(element=element)

    def _beta(self, element: str, k: int) -> pd.DataFrame:
        from ..discretization.spaces.registry import SPACES, ids_valid_for
        from ..study.beta.batch_rows import beta_batch_rows

        model, mesh = self.model(), self.options(element)
        gamma = model.gamma(**mesh.kwargs())  # the model contract takes keywords
        cases = [c for c in ids_valid_for(k, self.cfg["cases"]) if gamma.builds(SPACES[c])]
        frame = beta_batch_rows(model, "structured", k, pairs_of(self.cfg), cases, ("omega2",),
                                norms=tuple(self.cfg.get("norms", ("H", "L2"))), mesh=mesh)
        frame = frame.drop(columns=[c for c in frame.columns if c.startswith("t_")])  # timings: benchmark tree
        frame.insert(0, "element", element)
        frame.insert(0, "model", model.name)
        return frame

    def _mem_mb(self, k: int) -> int:
        model = self.model()
        return max(resources.job_mem_mb(resources.beta_estimate(
            "structured", k, n1, n2, "omega2", tuple(self.cfg.get("norms", ("H", "L2"))),
            components=model.components, dim=model.dim)) for n1, n2 in pairs_of(self.cfg))

    def jobs(self) -> dict:
        shown = ("element", "case", "k", "N1", "N2", "norm", "beta", "kernel_dim", "structural_kernel_dim")
        return {f"beta_{e}_k{k}".replace(f"_{NO_ELEMENT}_", "_"): Job(lambda e=e, k=int(k): self._beta(e, k), self.cfg,
                                                                   lambda k=int(k): self._mem_mb(k), shown)
                for e in self.elements for k in self.cfg["k"]}

    def tables(self) -> dict:
        return {"beta": Table("model_beta", tuple(self.jobs()))}

    def claim_inputs(self) -> Inputs:
        return Inputs({"beta": (table_path(self.name, "beta"), "model_beta")})

    def claims(self, frames: dict, claims_cfg: dict) -> pd.DataFrame:
        from ..study.claims.any_model import model_claims

        return model_claims(frames["beta"], claims_cfg, self.name, self.model().dim)

    def paper_inputs(self) -> Inputs:
        return Inputs({"beta": (table_path(self.name, "beta"), "model_beta"),
                       "claims": (claims_path(self.name), "claims")})

    def paper_files(self, frames: dict, params: dict) -> dict:
        from ..report.sections.model_section import model_section_tex

        return {f"{self.name}.tex": model_section_tex(self.name, self.cfg, frames["beta"], frames["claims"])}

    def check_tex(self, tex: str, files: dict) -> None:
        """No hand-written source: the subsection is generated whole."""
