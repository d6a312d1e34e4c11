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
while building the DAG). How the pairs are cut into jobs is :mod:`infsup_contact.study.beta.batches`;
which rows a figure shows is :func:`infsup_contact.study.beta.selection.primary_rows`.
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


def series_of_pairs(ic: dict) -> dict:
    """(N1, N2) → the series ids it belongs to (in :func:`beta_series` order)."""
    out = {}
    for name, pairs in beta_series(ic).items():
        for p in pairs:
            out.setdefault(p, []).append(name)
    return out
