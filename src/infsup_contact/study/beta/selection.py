"""Which rows of a β_h table a figure or a single number shows (the ledger uses them all)."""
from __future__ import annotations


def primary_rows(beta):
    """The rows a figure or a single number shows: the smallest seed of the perturbed family
    (the deterministic families have no seed) and each mesh pair once (a pair of two series
    is written once per series). The ledger uses every seed (:mod:`infsup_contact.criteria.claims`)."""
    b = beta
    if "seed" in b.columns and b.seed.notna().any():
        b = b[b.seed.isna() | (b.seed == b.seed.min())]
    if "series" in b.columns:
        b = b.drop_duplicates(subset=[c for c in b.columns if c != "series"])
    return b
