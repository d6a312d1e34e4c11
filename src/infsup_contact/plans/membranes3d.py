"""The membranes in 3D with a 2D contact face Γ = (0,1)²×{1} (model-table study ``membranes3d``).

Jobs: β_h of every (element, k) on its mesh pairs in both norms, the L²(Γ)-only rows of the finer
matching meshes where an element has them (``face.l2_max_N``), the 3D contact patch test, the
α sweep of the transformed duals and edge dropping (:mod:`infsup_contact.study.face.tables`).
Claims: :mod:`infsup_contact.study.claims.membranes3d` and its studies' claims; paper:
:mod:`infsup_contact.report.sections.face` against ``paper/face.tex``.
"""
from __future__ import annotations

import pandas as pd

from .. import resources
from ..config.membranes3d import face_pairs, l2_only_sizes
from .protocol import Inputs, Job, Table, claims_path, job_path, table_path

STUDIES = ("patch", "alpha", "edge_dropping")
"""The face studies: sub-mappings of the entry and jobs of their own."""


class Membranes3dStudy:
    """The membranes3d study ``name`` of the model table (the 3D membranes on the face), from its
    entry's scenes (module docstring)."""

    tex_source = "paper/face.tex"
    in_paper = True
    model_section = False

    def __init__(self, name: str, scenes: dict):
        self.name, self.cfg = name, scenes

    def _mem_mb(self, element: str, k: int, l2_only: bool) -> int:
        fc = self.cfg
        pairs = [(n, n) for n in l2_only_sizes(fc, element)] if l2_only else face_pairs(fc, element)
        norms = ("L2",) if l2_only else tuple(fc["norms"])
        return max(resources.job_mem_mb(resources.beta_estimate("structured", k, n1, n2, "omega2", norms, dim=3))
                   for n1, n2 in pairs)

    def _beta(self, element: str, k: int, l2_only: bool) -> pd.DataFrame:
        from ..discretization.spaces.registry import SPACES, ids_valid_for
        from ..solvers.request import MeshOptions
        from ..study.beta.batch_rows import beta_batch_rows
        from ..study.claims.membranes3d import element_interfaces

        fc = self.cfg
        pairs = [(n, n) for n in l2_only_sizes(fc, element)] if l2_only else face_pairs(fc, element)
        norms = ("L2",) if l2_only else tuple(fc["norms"])
        gamma = element_interfaces(fc["model"], [element])[element]
        cases = [c for c in ids_valid_for(k, fc["cases"]) if gamma.builds(SPACES[c])]  # QUAD9 spaces: rectangles
        frame = beta_batch_rows(fc["model"], "structured", k, pairs, cases, ("omega2",), norms=norms,
                                mesh=MeshOptions(element=element))
        frame = frame.drop(columns=[c for c in frame.columns if c.startswith("t_")])  # timings: benchmark tree
        frame.insert(0, "element", element)
        frame.insert(0, "model", fc["model"])
        return frame

    def _study(self, study: str) -> pd.DataFrame:
        from ..study.face.tables import FACE_STUDIES

        frame = FACE_STUDIES[study](self.cfg)
        return frame.drop(columns=[c for c in ("seconds",) if c in frame.columns])

    def jobs(self) -> dict:
        fc, shown = self.cfg, ("case", "N1", "N2", "norm", "beta", "kernel_dim", "structural_kernel_dim")
        jobs = {}
        for e in fc.get("elements", ()):
            for k in map(int, fc["k"]):
                jobs[f"beta_{e}_k{k}"] = Job(lambda e=e, k=k: self._beta(e, k, False), fc,
                                             lambda e=e, k=k: self._mem_mb(e, k, False), shown)
        for e in fc.get("elements", ()):
            for k in map(int, fc["k"]):
                if l2_only_sizes(fc, e):
                    jobs[f"l2_{e}_k{k}"] = Job(lambda e=e, k=k: self._beta(e, k, True), fc,
                                               lambda e=e, k=k: self._mem_mb(e, k, True), shown)
        jobs.update({s: Job(lambda s=s: self._study(s), fc[s]) for s in STUDIES if s in fc})
        return jobs

    def tables(self) -> dict:
        return {"beta": Table("face_beta", tuple(j for j in self.jobs() if j not in STUDIES))}

    def claim_inputs(self) -> Inputs:
        return Inputs({"beta": (table_path(self.name, "beta"), "face_beta"),
                       "patch": (job_path(self.name, "patch"), "face_patch"),
                       "alpha": (job_path(self.name, "alpha"), "face_alpha"),
                       "edge": (job_path(self.name, "edge_dropping"), "face_edge")})

    def claims(self, frames: dict, claims_cfg: dict) -> pd.DataFrame:
        from ..study.claims.membranes3d import element_interfaces, face_claims
        from ..study.claims.membranes3d_studies import face_study_claims

        fc = self.cfg
        beta = face_claims(frames["beta"], claims_cfg, element_interfaces(fc["model"], fc["elements"]))
        studies = face_study_claims(frames["patch"], frames["alpha"], frames["edge"], claims_cfg,
                                    element_interfaces(fc["model"], fc["patch"]["elements"]),
                                    fc["edge_dropping"]["fit_theta_max"])
        return pd.concat([beta, studies], ignore_index=True)

    def paper_inputs(self) -> Inputs:
        return Inputs({**self.claim_inputs().files, "claims": (claims_path(self.name), "claims")})

    def paper_files(self, frames: dict, params: dict) -> dict:
        from ..report.sections.face import face_paper_files
        from ..study.claims.membranes3d_studies import STUDY_CLAIM_PREFIXES

        claims = frames["claims"]
        of_studies = claims.claim_id.str.startswith(STUDY_CLAIM_PREFIXES)
        return face_paper_files(frames["beta"], claims[~of_studies], frames["patch"], frames["alpha"], frames["edge"],
                                claims[of_studies])

    def check_tex(self, tex: str, files: dict) -> None:
        from ..report.sections.face import check_face_tex

        check_face_tex(tex, files)
