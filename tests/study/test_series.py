"""Mesh series of the β study (discretization/gamma/mesh_series.py) and seed pooling in the ledger."""
import math

import numpy as np
import pandas as pd
import pytest

from infsup_contact.discretization.gamma import mesh_series as S
from infsup_contact.criteria.claims import bounded_claim, finest

IC = {"N": [4, 8, 16], "nonmatching": [[6, 4], [12, 8], [16, 8], [6, 8]],
      "nonmatching_families": {"plus1": [8, 12, 16], "sqrt2": [8, 12, 16]},
      "families": ["structured", "perturbed"], "cases": {"T3": [1, 2], "T5": [2]}, "seed": [0, 3]}


def test_family_rules():
    for n1, n2 in S.family_pairs("plus1", range(1, 50)):
        assert n1 - n2 == 1
    pairs = S.family_pairs("sqrt2", range(2, 200))
    assert all(abs(n1 - math.sqrt(2) * n2) <= 0.5 for n1, n2 in pairs)
    # the ratio changes with every N2 (never equal for consecutive N2) and tends to √2
    ratios = [n1 / n2 for n1, n2 in pairs]
    assert all(a != b for a, b in zip(ratios, ratios[1:]))
    assert all(abs(r - math.sqrt(2)) <= 0.5 / n2 for r, (_, n2) in zip(ratios, pairs))


def test_series_and_ratio_labels():
    s = S.beta_series(IC)
    assert s["matching"] == [(4, 4), (8, 8), (16, 16)]
    assert s["ratio3-2"] == [(6, 4), (12, 8)] and s["ratio2-1"] == [(16, 8)] and s["ratio3-4"] == [(6, 8)]
    assert s["plus1"] == [(9, 8), (13, 12), (17, 16)] and s["sqrt2"] == [(11, 8), (17, 12), (23, 16)]
    assert S.series_of_pairs(IC)[(17, 16)] == ["plus1"]
    assert S.describe("ratio3-2") == "N1:N2 = 3:2" and S.describe("plus1") == "N1 = N2 + 1"


def test_seeds_accept_an_integer_or_a_list():
    assert S.seeds({"seed": 5}) == [5] and S.seeds({"seed": [0, 1]}) == [0, 1] and S.seeds({}) == [0]


def _series(seeds, ns, slope=0.0, noise=0.02, seed=0):
    rng = np.random.default_rng(seed)
    return pd.DataFrame([dict(N2=n, seed=s, beta=0.8 * n ** (-slope) * (1 + noise * rng.standard_normal()))
                         for s in seeds for n in ns])


def test_finest_takes_every_seed_of_the_finest_meshes():
    rows = _series([0, 1, 2], [4, 8, 16, 32, 64])
    f = finest(rows, 3)
    assert sorted(set(f.N2)) == [16, 32, 64] and len(f) == 9


def test_pooling_seeds_narrows_the_interval():
    # the same random family: more seeds, more points, a narrower interval around slope 0
    one = bounded_claim(_series([0], [8, 16, 32, 64, 128]), 0.15, 1e-3, 0.95)[1]
    many = bounded_claim(_series(range(6), [8, 16, 32, 64, 128]), 0.15, 1e-3, 0.95)[1]

    def width(text):
        lo, hi = text.split("CI [")[1].split("]")[0].split(", ")
        return float(hi) - float(lo)

    assert "6 seeds pooled, 30 points" in many
    assert width(many) < width(one)
