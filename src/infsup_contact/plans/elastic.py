"""The plane-strain elastic bodies on the paper's geometry (model-table study ``elastic``).

Jobs: β_h of every (family, k) next to the membranes on the same meshes, the ν → 1/2 sweep of
each k (:mod:`infsup_contact.study.beta.elastic`), the Hertz scene's discretization study per k and its modeling
study (:mod:`infsup_contact.study.contact.hertz`) and the contact patch test (:mod:`infsup_contact.study.patch.segment`); the spaces
are the ``infsup.cases`` (one list for the membranes' and this study). Claims:
:mod:`infsup_contact.study.claims.elastic`; paper: :mod:`infsup_contact.report.sections.elastic` against
``paper/elastic.tex``.
"""
from __future__ import annotations

import pandas as pd

from .. import resources
from .protocol import Inputs, Job, Table, claims_path, table_path


HERTZ_MEM_MB = 2100
"""mem_mb of a Hertz job (no estimate of its own: twice the measured RSS of the full config's largest)."""


def _drop_seconds(rows) -> pd.DataFrame:
    frame = pd.DataFrame(rows)
    return frame.drop(columns=["seconds"], errors="ignore")  # timings: benchmark files, not tables


class ElasticStudy:
    """The elastic study ``name`` of the model table: its entry's scenes and the spaces it runs
    (``infsup.cases``; module docstring)."""

    tex_source = "paper/elastic.tex"
    in_paper = True
    model_section = False

    def __init__(self, name: str, scenes: dict, cases: list):
        self.name, self.cfg, self.cases = name, scenes, list(cases)

    def _mem_mb(self, family: str, k: int) -> int:
        """The β estimate of the largest pair, two displacement components per node (+25 %)."""
        ec = self.cfg
        pairs = [(n, n) for n in ec["N"]] + [tuple(p) for p in ec["nonmatching"]]
        n1, n2 = max(pairs, key=lambda p: p[0] * p[0] + p[1] * p[1])
        return resources.job_mem_mb(resources.beta_estimate(family, k, n1, n2, "omega2", ("H",), components=2))

    def _beta(self, family: str, k: int) -> pd.DataFrame:
        from ..discretization.spaces.registry import ids_valid_for
        from ..study.beta.elastic import elastic_beta_rows

        ec = self.cfg
        pairs = [(n, n) for n in ec["N"]] + [tuple(p) for p in ec["nonmatching"]]
        return elastic_beta_rows(family, k, list(dict.fromkeys(pairs)), ec["nu"], tuple(ec["E"]),
                                 cases=ids_valid_for(k, self.cases))

    def _sweep(self, k: int) -> pd.DataFrame:
        from ..discretization.spaces.registry import ids_valid_for
        from ..study.beta.elastic import nu_sweep_rows

        return nu_sweep_rows(k, self.cfg["N"], self.cfg["nu_sweep"], cases=ids_valid_for(k, self.cases))

    def _hertz(self, k: int | None) -> pd.DataFrame:
        from ..discretization.spaces.registry import REFERENCE_SPACE
        from ..study.contact.hertz import discretization_rows, modeling_rows

        ec = self.cfg
        hz, E = ec["hertz"], tuple(ec["E"])
        if k is None:
            return _drop_seconds(modeling_rows(REFERENCE_SPACE, 2, hz["modeling_N"], hz["R"], hz["modeling_d"],
                                               ec["nu"], E))
        return _drop_seconds(discretization_rows(self.cases, [k], hz["N"], hz["N_ref"], hz["R"], hz["d"], ec["nu"], E))

    def _patch(self) -> pd.DataFrame:
        from ..study.patch.segment import patch_rows

        ec = self.cfg
        return _drop_seconds(patch_rows(self.cases, ec["patch_k"], [tuple(p) for p in ec["patch_pairs"]], ec["nu"],
                                        tuple(ec["E"])))

    def jobs(self) -> dict:
        ec, beta_cols = self.cfg, ("case", "N1", "N2", "nu", "beta", "kernel_dim", "beta_membranes")
        jobs = {f"beta_{f}_k{k}": Job(lambda f=f, k=int(k): self._beta(f, k), ec,
                                      lambda f=f, k=int(k): self._mem_mb(f, k), beta_cols)
                for f in ec["families"] for k in ec["k"]}
        jobs.update({f"nu_sweep_k{k}": Job(lambda k=int(k): self._sweep(k), ec,
                                           lambda k=int(k): self._mem_mb("structured", k), beta_cols)
                     for k in ec["nu_sweep_k"]})
        # measured: max RSS 1003 MB (k = 2, N_ref = 64), wall 21 s: twice that asked for
        jobs.update({f"hertz_k{k}": Job(lambda k=int(k): self._hertz(k), ec, lambda: HERTZ_MEM_MB)
                     for k in ec["hertz"]["k"]})
        jobs["hertz_modeling"] = Job(lambda: self._hertz(None), ec, lambda: HERTZ_MEM_MB)
        jobs["patch"] = Job(self._patch, ec, shown=("case", "k", "N1", "N2", "lambda_max_rel_error",
                                                    "u_max_rel_error", "passes"))
        return jobs

    def tables(self) -> dict:
        names = list(self.jobs())
        pick = lambda prefix: tuple(j for j in names if j.startswith(prefix))  # noqa: E731
        return {"beta": Table("elastic_beta", pick("beta_")), "nu_sweep": Table("elastic_beta", pick("nu_sweep_")),
                "hertz": Table("elastic_hertz", pick("hertz_")), "patch": Table("elastic_patch", ("patch",))}

    def _table_files(self) -> dict:
        return {"beta": (table_path(self.name, "beta"), "elastic_beta"),
                "sweep": (table_path(self.name, "nu_sweep"), "elastic_beta"),
                "patch": (table_path(self.name, "patch"), "elastic_patch"),
                "hertz": (table_path(self.name, "hertz"), "elastic_hertz")}

    def claim_inputs(self) -> Inputs:
        return Inputs(self._table_files())

    def claims(self, frames: dict, claims_cfg: dict) -> pd.DataFrame:
        from ..study.claims.elastic import elastic_claims, hertz_claims, patch_claims

        return pd.concat([elastic_claims(frames["beta"], frames["sweep"], claims_cfg), patch_claims(frames["patch"]),
                          hertz_claims(frames["hertz"])], ignore_index=True)

    def paper_inputs(self) -> Inputs:
        return Inputs({**self._table_files(), "claims": (claims_path(self.name), "claims"),
                       "speed": ("results/benchmarks/elastic_beta.csv", "bench")})

    def paper_files(self, frames: dict, params: dict) -> dict:
        from ..report.sections.elastic import elastic_paper_files

        return elastic_paper_files(frames["beta"], frames["sweep"], frames["patch"], frames["hertz"], frames["claims"],
                                   frames["speed"], nu_slope_cases=params["nu_slope_cases"])

    def check_tex(self, tex: str, files: dict) -> None:
        from ..report.sections.elastic import check_elastic_tex

        check_elastic_tex(tex, files)
