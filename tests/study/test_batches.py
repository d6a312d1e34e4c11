"""The β_h jobs of the workflow (study/beta/batches.py): every pair of every series once per (family, k)."""
from infsup_contact.discretization.gamma.mesh_series import series_of_pairs
from infsup_contact.study.beta.batches import beta_batches

IC = {"N": [4, 8, 16], "nonmatching": [[6, 4], [12, 8], [16, 8], [6, 8]],
      "nonmatching_families": {"plus1": [8, 12, 16], "sqrt2": [8, 12, 16]},
      "families": ["structured", "perturbed"], "cases": {"T3": [1, 2], "T5": [2]}, "seed": [0, 3]}


def test_batches_cover_every_pair_once_per_family_and_k():
    batches = beta_batches(IC, budget=0.5)
    pairs = set(series_of_pairs(IC))
    for fam in IC["families"]:
        for k in (1, 2):
            got = [p for b in batches.values() if b["family"] == fam and b["k"] == k for p in b["pairs"]]
            assert sorted(got) == sorted(pairs)
    assert len(batches) > 4  # the small budget cuts batches
