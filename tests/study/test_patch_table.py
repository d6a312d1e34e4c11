"""study/patch/table.py: the patch test's loop and kernel count every model shares."""
import numpy as np
import pytest

from infsup_contact.discretization.spaces import registry
from infsup_contact.study.patch import table


def test_one_pair_per_mesh_pair_and_k_shared_by_every_case_defined_for_k():
    built, solved = [], []

    def pair_of(k, n1, n2):
        built.append((k, n1, n2))
        return object()

    def solve(case, k, n1, n2, pair):
        solved.append((case, k, n1, n2, pair))
        return dict(case=case, k=k)

    cases, ks, pairs = list(registry.PAPER_CASES), [1, 2], [(4, 3), (6, 5)]
    rows = table.patch_rows(pair_of, solve, cases, ks, pairs)
    assert sorted(built) == sorted((k, n1, n2) for n1, n2 in pairs for k in ks)
    for k, n1, n2 in built:
        mine = [s for s in solved if s[1:4] == (k, n1, n2)]
        assert sorted(s[0] for s in mine) == sorted(registry.ids_valid_for(k, cases))
        assert len({id(s[4]) for s in mine}) == 1  # one factorized pair for all its cases
    assert len(rows) == len(solved)


@pytest.mark.parametrize("zeros", [0, 1, 3])
def test_kernel_dim_counts_the_zero_eigenvalues_against_the_gram_matrix(zeros):
    rng = np.random.default_rng(zeros)
    n = 6
    Q = np.linalg.qr(rng.standard_normal((n, n)))[0]
    K = Q @ np.diag([0.0] * zeros + list(np.linspace(1.0, 2.0, n - zeros))) @ Q.T
    A = rng.standard_normal((n, n))
    G = A @ A.T + n * np.eye(n)  # SPD: the kernel of K x = θ G x is K's own kernel
    assert table.kernel_dim(K, G) == zeros
