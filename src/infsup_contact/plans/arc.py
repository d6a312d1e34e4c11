"""The curved segment: β_h of every registered space on the arc of radius R, both couplings.

The entry (config ``models.<name>`` with ``study: arc``, :mod:`infsup_contact.config.models`) carries
its scenes: degrees ``k``, ``radii`` (finite R > 1; R = ∞ always runs too), the ``couplings``, the
mesh ``series`` (name → [N1, N2] pairs, each at least 3: a verdict fits a slope) and the ``cases``.
Jobs: one per k, every radius × coupling × pair, plus the paper's own flat rows
(:func:`infsup_contact.study.beta.arc.arc_rows`). Claims: :mod:`infsup_contact.study.claims.arc`.
Paper: one generated subsection (:func:`infsup_contact.report.model_section.arc_section_tex`).
"""
from __future__ import annotations

import math

import pandas as pd

from .. import resources
from .protocol import Inputs, Job, Table, claims_path, table_path


class ArcStudy:
    """β_h, kernels, verdicts and their claims on the curved segment (module docstring)."""

    tex_source = None
    in_paper = True
    model_section = True

    def __init__(self, name: str, entry: dict):
        self.name, self.cfg = name, entry

    def series(self) -> dict:
        return {s: [tuple(int(n) for n in p) for p in pairs] for s, pairs in self.cfg["series"].items()}

    def _rows(self, k: int) -> pd.DataFrame:
        from ..discretization.spaces.registry import ids_valid_for
        from ..study.beta.arc import arc_rows

        radii = [float(r) for r in self.cfg["radii"]] + [math.inf]  # R = ∞: the reference of every claim
        return arc_rows(radii, self.series(), k, ids_valid_for(k, self.cfg["cases"]),
                        tuple(self.cfg["couplings"]), paper=True)

    def _mem_mb(self, k: int) -> int:
        pairs = {p for ps in self.series().values() for p in ps}
        return max(resources.job_mem_mb(resources.beta_estimate("structured", k, n1, n2, "omega2", ("H", "L2")))
                   for n1, n2 in pairs)

    def jobs(self) -> dict:
        shown = ("curvature", "coupling", "series", "case", "k", "N1", "N2", "norm", "beta", "kernel_dim")
        return {f"arc_k{k}": Job(lambda k=int(k): self._rows(k), self.cfg, lambda k=int(k): self._mem_mb(k), shown)
                for k in self.cfg["k"]}

    def tables(self) -> dict:
        return {"beta": Table("arc_beta", tuple(self.jobs()))}

    def claim_inputs(self) -> Inputs:
        return Inputs({"beta": (table_path(self.name, "beta"), "arc_beta")})

    def claims(self, frames: dict, claims_cfg: dict) -> pd.DataFrame:
        from ..study.claims.arc import arc_claims

        return arc_claims(frames["beta"], claims_cfg, self.name)

    def paper_inputs(self) -> Inputs:
        return Inputs({"beta": (table_path(self.name, "beta"), "arc_beta"),
                       "claims": (claims_path(self.name), "claims")})

    def paper_files(self, frames: dict, params: dict) -> dict:
        from ..report.model_section import arc_section_tex
        from ..study.beta.arc import arc_verdicts

        c = params["claims"]
        verdicts = arc_verdicts(frames["beta"], c["slope_tolerance"], c["beta_floor"], c["confidence"])
        return {f"{self.name}.tex": arc_section_tex(self.name, frames["beta"], verdicts, frames["claims"])}

    def check_tex(self, tex: str, files: dict) -> None:
        """No hand-written source: the subsection is generated whole."""

