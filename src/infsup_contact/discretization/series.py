"""Mesh series of the β_h study: which (N1, N2) pairs belong together in one claim.

A claim about h → 0 is decided on a *series* of mesh pairs. Besides matching meshes
(N1 = N2 = N) there are two kinds of non-matching series:

fixed-ratio series (config ``infsup.nonmatching``)
    the listed pairs grouped by their reduced ratio N1 : N2 (3:2, 2:1, 3:4, …). A fixed
    rational ratio makes the pattern of the two traces on Γ periodic, the same pattern at
    every N, so it can hide a failure that appears as soon as the ratio changes.
families (config ``infsup.nonmatching_families``: name → N2 list)
    ``plus1``: N1 = N2 + 1, the ratio tends to 1 and the overlap pattern of the two traces
    changes with every N; ``sqrt2``: N1 = round(√2 N2), a non-commensurate ratio (the
    traces share only Γ's ends).

Perturbed meshes come in several seeds (config ``infsup.seed``: one integer or a list);
every seed of every pair is a mesh of the series. Pure Python (the workflow imports it
while building the DAG).
"""
from __future__ import annotations

import math

FAMILY_RULES = {
    "plus1": (lambda n2: n2 + 1, "N1 = N2 + 1"),
    "sqrt2": (lambda n2: int(round(math.sqrt(2.0) * n2)), "N1 = round(√2·N2)"),
}
"""Non-matching family → (N1 as a function of N2, its description)."""
MATCHING = "matching"


def ratio_series(n1: int, n2: int) -> str:
    """Series id of a fixed-ratio pair: ``ratio3-2`` for (6, 4) and (12, 8)."""
    g = math.gcd(int(n1), int(n2))
    return f"ratio{n1 // g}-{n2 // g}"


def family_pairs(name: str, n2s) -> list:
    """(N1, N2) of a non-matching family; N1 = N2 (possible for tiny N) is dropped."""
    rule = FAMILY_RULES[name][0]
    return [(rule(int(n2)), int(n2)) for n2 in n2s if rule(int(n2)) != int(n2)]


def beta_series(ic: dict) -> dict:
    """Series id → list of (N1, N2) pairs, from the ``infsup`` section of a config.

    ``matching`` first, then the fixed-ratio series in the order of their first pair, then
    the families. A pair may belong to two series (e.g. (17, 16) is plus1 and …); it is then
    computed in each (rows carry their ``series``).
    """
    out = {MATCHING: [(int(n), int(n)) for n in ic["N"]]}
    for n1, n2 in ic.get("nonmatching", []):
        out.setdefault(ratio_series(n1, n2), []).append((int(n1), int(n2)))
    for name, n2s in ic.get("nonmatching_families", {}).items():
        out[name] = family_pairs(name, n2s)
    return {name: list(dict.fromkeys(pairs)) for name, pairs in out.items() if pairs}


def describe(series: str) -> str:
    """Human text of a series id: ``N1 = N2 + 1``, ``N1:N2 = 3:2``, ``matching``."""
    if series in FAMILY_RULES:
        return FAMILY_RULES[series][1]
    if series.startswith("ratio"):
        p, q = series[len("ratio"):].split("-")
        return f"N1:N2 = {p}:{q}"
    return series


def seeds(ic: dict) -> list:
    """The perturbed family's seeds: ``infsup.seed`` as a list (one integer is one seed)."""
    s = ic.get("seed", 0)
    return [int(v) for v in (s if isinstance(s, (list, tuple)) else [s])]


def pair_cost(family: str, k: int, n1: int, n2: int) -> float:
    """Rough seconds of one pair's β_h rows (every case, multiplier mesh, c pair and norm,
    :func:`~infsup_contact.solvers.infsup.beta_rows_all`) on one core, N = max(N1, N2):
    0.026 + 6.8e-4 (1 + 2 [N1 ≠ N2]) N k + 2.4e-5 (N k)² s, unstructured meshes × 1.3.
    Least squares over the 64 pairs of the full config, perturbed, k = 2 and 4 (2026-11-23,
    AMD EPYC, one BLAS thread; largest error 0.32 s, total exact). A non-matching pair has
    three multiplier partitions, a matching one one (their rows are shared)."""
    n = max(n1, n2)
    t = 0.026 + 6.8e-4 * (1 + 2 * (n1 != n2)) * n * k + 2.4e-5 * (n * k) ** 2
    return t * (1.3 if family == "unstructured" else 1.0)


def series_of_pairs(ic: dict) -> dict:
    """(N1, N2) → the series ids it belongs to (in :func:`beta_series` order)."""
    out = {}
    for name, pairs in beta_series(ic).items():
        for p in pairs:
            out.setdefault(p, []).append(name)
    return out


def beta_batches(ic: dict, budget: float = 25.0) -> dict:
    """Batch id → dict(family, k, pairs): the β_h jobs of the workflow.

    All pairs of every series of one (family, k), each pair once, cheapest first, cut into
    the fewest consecutive chunks of about equal estimated seconds that keep each near
    ``budget`` (:func:`pair_cost`, × the number of seeds on perturbed meshes), so that
    NGSolve's start-up (~1 s a process) is paid once per batch and not once per pair.
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


def primary_rows(beta):
    """The rows a figure or a single number shows: the smallest seed of the perturbed family
    (the deterministic families have no seed) and each mesh pair once (a pair of two series
    is written once per series). The ledger uses every seed (:mod:`infsup_contact.study.claims`)."""
    b = beta
    if "seed" in b.columns and b.seed.notna().any():
        b = b[b.seed.isna() | (b.seed == b.seed.min())]
    if "series" in b.columns:
        b = b.drop_duplicates(subset=[c for c in b.columns if c != "series"])
    return b
