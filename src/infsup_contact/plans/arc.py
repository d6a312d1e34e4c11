"""The curved segment: β_h of every registered space on the arc of radius R, both couplings.

The entry (config ``studies.<name>`` with ``study: arc``, :mod:`infsup_contact.config.models`) carries
its scenes: degrees ``k``, ``radii`` (finite R > 1; R = ∞ always runs too), the ``couplings``, the
mesh ``series`` (name → [N1, N2] pairs, each at least 3: a verdict fits a slope), the ``cases`` and
optionally the ``patch`` test (its ``k``, ``pairs`` refined by a common factor, prestresses ``c``).
Jobs: one per k, every radius × coupling × pair, plus the paper's own flat rows
(:func:`infsup_contact.study.beta.arc.arc_rows`); the patch test (:mod:`infsup_contact.study.patch.arc`).
Claims: :mod:`infsup_contact.study.claims.arc`.
Paper: one generated subsection (:func:`infsup_contact.report.sections.model_section.arc_section_tex`).
"""
from __future__ import annotations

import math

import pandas as pd

from .. import resources
from .protocol import Inputs, Job, Table, claims_path, table_path


FIGURE_STUDY = "arc"
"""The arc study the figures stage draws (fig12_curved, ``workflow/rules/figures.smk``) where it has a patch
test; its generated subsection includes the figure."""
FIGURE = "fig12_curved"
PATCH = "uniform_pressure"
"""The patch test's job and table (``results/tables/<name>_uniform_pressure.csv``)."""


class ArcStudy:
    """β_h, kernels, verdicts and their claims on the curved segment (module docstring)."""

    tex_source = None
    in_paper = True
    model_section = True

    def __init__(self, name: str, entry: dict):
        self.name, self.cfg = name, entry

    def series(self) -> dict:
        return {s: [tuple(int(n) for n in p) for p in pairs] for s, pairs in self.cfg["series"].items()}

    element = None
    """The 3D membranes' element (the cylinder), None for the 2D membranes (the arc)."""

    def _rows(self, k: int) -> pd.DataFrame:
        from ..discretization.spaces.registry import ids_valid_for
        from ..study.beta.arc import arc_rows

        radii = [float(r) for r in self.cfg["radii"]] + [math.inf]  # R = ∞: the reference of every claim
        cases = ids_valid_for(k, self.cfg["cases"])
        return arc_rows(radii, self.series(), k, cases, tuple(self.cfg["couplings"]), paper=True, element=self.element)

    def _mem_mb(self, k: int) -> int:
        pairs = {p for ps in self.series().values() for p in ps}
        return max(resources.job_mem_mb(resources.beta_estimate("structured", k, n1, n2, "omega2", ("H", "L2")))
                   for n1, n2 in pairs)

    def _patch(self) -> pd.DataFrame:
        from ..discretization.spaces.registry import ids_valid_for
        from ..study.beta.arc import curvature
        from ..study.patch.arc import arc_patch_rows

        p = self.cfg["patch"]
        radii = [float(r) for r in self.cfg["radii"]] + [math.inf]
        rows = pd.DataFrame(arc_patch_rows(sorted({c for k in p["k"] for c in ids_valid_for(int(k), self.cfg["cases"])}),
                                           [int(k) for k in p["k"]], [tuple(q) for q in p["pairs"]], radii,
                                           tuple(self.cfg["couplings"]), c=tuple(p["c"])))
        rows.insert(0, "curvature", [curvature(r) for r in rows.pop("radius")])  # a table holds no inf
        return rows

    def jobs(self) -> dict:
        shown = ("curvature", "coupling", "series", "case", "k", "N1", "N2", "norm", "beta", "kernel_dim")
        jobs = {f"arc_k{k}": Job(lambda k=int(k): self._rows(k), self.cfg, lambda k=int(k): self._mem_mb(k), shown)
                for k in self.cfg["k"]}
        if self.cfg.get("patch"):
            jobs[PATCH] = Job(self._patch, self.cfg, lambda: 1000, ("curvature", "coupling", "case", "k", "N1", "N2",
                                                                     "lambda_max_rel_error", "u_max_rel_error"))
        return jobs

    def tables(self) -> dict:
        out = {"beta": Table("arc_beta", tuple(j for j in self.jobs() if j != PATCH))}
        if self.cfg.get("patch"):
            out[PATCH] = Table("arc_patch", (PATCH,))
        return out

    def claim_inputs(self) -> Inputs:
        files = {"beta": (table_path(self.name, "beta"), "arc_beta")}
        if self.cfg.get("patch"):
            files[PATCH] = (table_path(self.name, PATCH), "arc_patch")
        return Inputs(files)

    def claims(self, frames: dict, claims_cfg: dict) -> pd.DataFrame:
        from ..study.claims.arc import arc_claims, arc_patch_claims

        out = arc_claims(frames["beta"], claims_cfg, self.name)
        return pd.concat([out, arc_patch_claims(frames[PATCH], self.name, claims_cfg["fit_window"])],
                         ignore_index=True) \
            if PATCH in frames else out

    def paper_inputs(self) -> Inputs:
        return Inputs({**self.claim_inputs().files, "claims": (claims_path(self.name), "claims")})

    def paper_files(self, frames: dict, params: dict) -> dict:
        from ..report.sections.model_section import arc_section_tex
        from ..study.beta.arc import arc_verdicts

        c = params["claims"]
        verdicts = arc_verdicts(frames["beta"], c["slope_tolerance"], c["beta_floor"], c["confidence"])
        figure = FIGURE if self.name == FIGURE_STUDY and self.element is None and self.cfg.get("patch") else None
        return {f"{self.name}.tex": arc_section_tex(self.name, frames["beta"], verdicts, frames["claims"],
                                                    frames.get(PATCH), self.element, figure)}

    def check_tex(self, tex: str, files: dict) -> None:
        """No hand-written source: the subsection is generated whole."""



class CylinderStudy(ArcStudy):
    """The same study one dimension up: the 3D membranes on hexahedra, Γ the part of the cylinder of
    radius R (:mod:`infsup_contact.discretization.face.shapes.cylinder`); no patch test (contact scenes are
    not built on a curved face)."""

    element = "hex"
