"""The rows a figure or a single number shows (study/beta/selection.py)."""
import numpy as np
import pandas as pd

from infsup_contact.study.beta.selection import primary_rows


def test_primary_rows_keep_the_smallest_seed_and_each_pair_once():
    b = pd.DataFrame(dict(family=["perturbed"] * 3 + ["structured"] * 2, seed=[0, 1, 0, np.nan, np.nan],
                          series=["matching", "matching", "plus1", "ratio3-2", "sqrt2"],
                          N1=[8, 8, 9, 6, 6], N2=[8, 8, 8, 4, 4], beta=[1, 2, 3, 4, 4]))
    p = primary_rows(b)
    assert sorted(p.beta) == [1, 3, 4]
