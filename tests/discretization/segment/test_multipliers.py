"""Multiplier spaces: dimension counts of the paper and basic Lagrange properties."""
import numpy as np
import pytest

from infsup_contact.errors import InputError
from infsup_contact.discretization.segment.multipliers import make_space
from infsup_contact.discretization.spaces.registry import (PAPER_CASES as CASE_IDS, SPACES, case_space,
                                                    structural_kernel_dim)
from infsup_contact.discretization.segment.interface import SEGMENT

VALID = [(c, k) for c in CASE_IDS for k in range(1, 5) if k >= SPACES[c].min_k]


@pytest.mark.parametrize("case,k", VALID)
@pytest.mark.parametrize("n", [1, 2, 5, 8])
def test_dimension_matches_paper(case, k, n):
    if case == "T3" and k == 1 and n == 1:
        pytest.skip("M^1_{0,1} on one interval is {0}")
    x = np.sort(np.r_[0.0, np.random.default_rng(n).uniform(0.05, 0.95, n - 1), 1.0])
    assert case_space(case, k, x, SEGMENT).dim == SPACES[case].dimension(k, n)  # the registry's count (Rem 5.2, Rem 5.4, Thm 5)


def test_structural_kernel_counts():
    for k in range(1, 5):
        assert structural_kernel_dim("R5.2", k, 7) == 2  # Rem 5.2
        assert structural_kernel_dim("R5.4", k, 7) == 1  # Rem 5.4
        assert structural_kernel_dim("T3", k, 7) == 0


@pytest.mark.parametrize("s,continuous", [(0, False), (1, False), (2, False), (1, True), (3, True)])
def test_partition_of_unity_and_nodal_basis(s, continuous):
    space = make_space(np.linspace(0, 1, 6) ** 1.5, s, continuous, False)
    x = np.random.default_rng(0).uniform(0, 1, 200)
    assert np.allclose(space.evaluate(x).sum(axis=1), 1.0)
    if s >= 1:
        nodes = space.nodes()
        inner = (nodes > 0) & (nodes < 1)  # breakpoints of discontinuous spaces are one-sided
        if continuous:
            assert np.allclose(space.evaluate(nodes[inner])[:, inner], np.eye(space.dim)[inner][:, inner])


def test_vanishing_spaces_vanish_at_ends():
    space = case_space("T3", 3, np.linspace(0, 1, 5), SEGMENT)
    assert np.allclose(space.evaluate(np.array([0.0, 1.0])), 0.0)


@pytest.mark.parametrize("case,k,key", [("T4", 1, "k"), ("T5", 1, "k"), ("X", 2, "case")])
def test_bad_case_degree(case, k, key):
    with pytest.raises(InputError) as err:
        case_space(case, k, np.linspace(0, 1, 3), SEGMENT)
    assert err.value.key == key
