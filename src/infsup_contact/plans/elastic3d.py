"""The linear-elastic bodies on the 3D contact face (model-table study ``elastic3d``).

Jobs: β_H of every element (every k; the table's ν on every mesh pair and the ν → 1/2 sweep,
:func:`infsup_contact.study.face.elastic3d.beta_frame`) and the elastic face patch test
(:func:`~infsup_contact.study.face.elastic3d.patch_frame`). Claims:
:mod:`infsup_contact.study.claims.elastic3d`, whose kernel comparison reads the membranes' face
table when the model table has a membranes3d study; paper: the generated subsection ``elastic3d.tex``
of the face section (:mod:`infsup_contact.report.sections.elastic3d`), read by ``paper/face.tex``.
"""
from __future__ import annotations

import pandas as pd

from .protocol import Inputs, Job, Table, claims_path, job_path, table_path


class Elastic3dStudy:
    """The elastic3d study ``name`` of the model table, from its entry's scenes (module docstring)."""

    tex_source = None
    model_section = False  # its subsection is read by the face section (paper/face.tex), not listed

    def __init__(self, name: str, scenes: dict, membranes: str | None = None):
        self.name, self.cfg, self.membranes = name, scenes, membranes
        self.in_paper = membranes is not None  # a subsection of the face section: only with one

    def jobs(self) -> dict:
        from ..study.face.elastic3d import beta_frame, patch_frame

        fe = self.cfg
        jobs = {f"beta_{e}": Job(lambda e=e: beta_frame(fe, e), fe, lambda: 1500,
                                 ("k", "case", "N1", "N2", "nu", "beta", "kernel_dim", "structural_kernel_dim"))
                for e in fe["elements"]}
        jobs["patch"] = Job(lambda: patch_frame(fe), fe, lambda: 1000, ("element", "case", "k", "N1", "N2",
                                                                "lambda_max_rel_error", "u_max_rel_error",
                                                                "kernel_dim", "passes"))
        return jobs

    def tables(self) -> dict:
        return {"beta": Table("elastic3d_beta", tuple(f"beta_{e}" for e in self.cfg["elements"]))}

    def claim_inputs(self) -> Inputs:
        files = {"beta": (table_path(self.name, "beta"), "elastic3d_beta"),
                 "patch": (job_path(self.name, "patch"), "elastic3d_patch")}
        if self.membranes:  # the kernel comparison, when the membranes' face table is computed
            files["membranes"] = (table_path(self.membranes, "beta"), "face_beta")
        return Inputs(files)

    def claims(self, frames: dict, claims_cfg: dict) -> pd.DataFrame:
        from ..study.claims.elastic3d import face_elastic_claims
        from ..study.claims.membranes3d import element_interfaces

        fe = self.cfg
        elements = sorted(set(fe["elements"]) | set(fe["patch"]["elements"]))
        return face_elastic_claims(frames["beta"], frames["patch"], claims_cfg, fe,
                                   element_interfaces(fe["model"], elements), frames.get("membranes"))

    def paper_inputs(self) -> Inputs:
        files = self.claim_inputs().files
        return Inputs({"beta": files["beta"], "patch": files["patch"], "claims": (claims_path(self.name), "claims")})

    def paper_files(self, frames: dict, params: dict) -> dict:
        from ..report.sections.elastic3d import elastic3d_tex

        return {"elastic3d.tex": elastic3d_tex(frames["beta"], frames["patch"], frames["claims"], self.cfg)}

    def check_tex(self, tex: str, files: dict) -> None:
        """No hand-written source: the subsection is generated whole."""
