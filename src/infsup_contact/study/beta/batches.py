"""The β_h jobs of the workflow: a cost model of one mesh pair and the batches it cuts.

The series themselves (which pairs a claim is decided on) are
:mod:`infsup_contact.discretization.gamma.mesh_series`; this module only decides how the workflow
groups those pairs into processes. Pure Python (the workflow imports it while building the DAG).
"""
from __future__ import annotations

import math

from ...discretization.gamma.mesh_series import seeds, series_of_pairs


def pair_cost(family: str, k: int, n1: int, n2: int) -> float:
    """Rough seconds of one pair's β_h rows (every case, multiplier mesh, c pair and norm,
    :func:`~infsup_contact.solvers.infsup.beta_rows_all`) on one core, N = max(N1, N2):
    0.026 + 6.8e-4 (1 + 2 [N1 ≠ N2]) N k + 2.4e-5 (N k)² s, unstructured meshes × 1.3.
    Least squares over the 64 pairs of the full config, perturbed, k = 2 and 4 (AMD EPYC,
    one BLAS thread; the total exact). A non-matching pair has
    three multiplier partitions, a matching one one (their rows are shared)."""
    n = max(n1, n2)
    t = 0.026 + 6.8e-4 * (1 + 2 * (n1 != n2)) * n * k + 2.4e-5 * (n * k) ** 2
    return t * (1.3 if family == "unstructured" else 1.0)


def beta_batches(ic: dict, budget: float = 25.0) -> dict:
    """Batch id → dict(family, k, pairs): the β_h jobs of the workflow.

    All pairs of every series of one (family, k), each pair once, cheapest first, cut into
    the fewest consecutive chunks of about equal estimated seconds that keep each near
    ``budget`` (:func:`pair_cost`, × the number of seeds on perturbed meshes), so that
    NGSolve's start-up (once per process) is paid once per batch and not once per pair.
    Batch id ``{family}_k{k}_{chunk}``.
    """
    ks = sorted({k for klist in ic["cases"].values() for k in klist})
    pairs = sorted(series_of_pairs(ic), key=lambda p: (max(p), p))
    out = {}
    for fam in ic["families"]:
        mult = len(seeds(ic)) if fam == "perturbed" else 1
        for k in ks:
            costs = [pair_cost(fam, k, *p) * mult for p in pairs]
            # as few chunks as the budget allows, of about equal cost (no short straggler)
            n_chunks = max(1, math.ceil(sum(costs) / budget))
            target = sum(costs) / n_chunks
            chunks, cur, t = [], [], 0.0
            for p, c in zip(pairs, costs):
                if cur and t + c > target and len(chunks) < n_chunks - 1:
                    chunks.append(cur)
                    cur, t = [], 0.0
                cur.append(p)
                t += c
            chunks.append(cur)
            for i, chunk in enumerate(chunks):
                out[f"{fam}_k{k}_{i}"] = dict(family=fam, k=k, pairs=chunk)
    return out
