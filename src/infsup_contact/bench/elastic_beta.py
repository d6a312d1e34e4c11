"""Speed of the elastic β_h (issue 12, item 6): the Γ-reduced route against the same limit as
for the membranes (:mod:`infsup_contact.bench.beta_routes`) — one sparse factorization per
body (SuperLU's best order, symmetric mode) + one dense generalized ``eigh`` of multiplier
size per case, the interface operators and Gram matrices given. Every registered space
valid for k, H norm, the structured N × N pair, ν = 0.3.

Routes (``includes`` column):

``ours``
    End to end, ``beta_rows(..., model=elastic)``: meshes, NGSolve assembly of the vector
    stiffness, one Γ-last factorization per body + Schur complement of the normal Γ dofs,
    per case couplings, interface operator, Gram, ``eigh`` (and β with v1 = 0).
``ours_core``
    Given the assembled stiffness (free dofs ordered interior, Γ tangential, Γ normal):
    factorization + Schur complement per body, couplings, interface operator, Gram and one
    ``eigh`` per case.
``limit``
    One ``splu`` of each body's stiffness + one ``eigh`` per case on precomputed operators.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from ..discretization.segment import meshes
from ..discretization.spaces import registry
from ..discretization.gamma.coupling import coupling_matrix
from ..models.elastic import elastic_model
from ..models.contract import factorized_side
from ..solvers.interface_operator import interface_operator
from ..solvers.infsup import beta_rows
from .harness import _row, run_interleaved

INCLUDES = {"ours": "meshes, assembly, factorization + Schur per body, couplings, interface operator, Gram, eigh "
                    "(+ β with v1 = 0), every case",
            "ours_core": "factorization + Schur per body, couplings, interface operator, Gram, eigh, every case",
            "limit": "one splu per body (MMD_AT_PLUS_A) + one eigh per case on given operators"}


def bench_elastic_beta(ns, ks, repeats: int = 3, nu: float = 0.3, cases=None) -> list:
    """Rows ``what, route, k, N, seconds_median, …, ratio_to_ours, ratio_to_limit, max_abs_diff``;
    ``cases``: the space ids to run (each where defined for k; default every registered one)."""
    model = elastic_model(nu)
    rows = []
    for k in ks:
        ids = registry.ids_valid_for(k, cases)
        for n in ns:
            m1, m2 = meshes.mesh_pair("structured", n, n)
            sides = [model.side_operator(m, k) for m in (m1, m2)]
            gamma = sides[0].trace.gamma
            g_h = gamma.multiplier_partition(*(s.trace.partition for s in sides))
            spaces = {c: registry.case_space(c, k, g_h, gamma) for c in ids}
            ops = {}
            for c in ids:
                S = interface_operator([coupling_matrix(s.trace, spaces[c], k) for s in sides], sides)
                ops[c] = (S, gamma.gram(spaces[c], "H")[0])

            def ours():
                return {r["case"]: r["beta"] for r in beta_rows("structured", k, n, n, ids, norms=("H",),
                                                                model=model)}

            def core():
                fs = [factorized_side(s.trace, s.free, s.stiffness) for s in sides]
                out = {}
                for c in ids:
                    S = interface_operator([coupling_matrix(s.trace, spaces[c], k) for s in fs], fs)
                    out[c] = float(np.sqrt(max(sla.eigh(S, gamma.gram(spaces[c], "H")[0], eigvals_only=True,
                                                        check_finite=False)[0], 0.0)))
                return out

            def limit():
                for s in sides:
                    spla.splu(s.stiffness, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                              options=dict(SymmetricMode=True))
                return {c: float(np.sqrt(max(sla.eigh(S, G, eigvals_only=True, check_finite=False)[0], 0.0)))
                        for c, (S, G) in ops.items()}

            res = run_interleaved({"ours": ours, "ours_core": core, "limit": limit}, repeats)
            ref = res["ours"][0]
            t_ours, t_limit = np.median(res["ours"][1]), np.median(res["limit"][1])
            for name in ("ours", "ours_core", "limit"):
                got = res[name][0]
                diff = max(abs(got[c] - ref[c]) for c in ids)
                rows.append(_row("elastic_beta", name, k, n, res[name][1], t_ours, t_limit, other="ratio_to_limit",
                                 max_abs_diff=float(diff), n_problems=len(ids),
                                 ndof=sum(s.ndof for s in sides), includes=INCLUDES[name]))
    return rows
