"""induced_permutation keeps a reflection's π per space and point set: a second call returns the
kept π (read-only, equal to a fresh computation), another point set or transform is computed again,
a transform without a ``key`` is never kept, and the entry goes with its space."""
import gc

import numpy as np
import pytest

from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.gamma import symmetry
from infsup_contact.discretization.spaces import registry


@pytest.mark.parametrize("case", ["T3", "R5.4", "DUAL-Q9"])
def test_a_reflections_permutation_is_kept_per_space_and_points(case, monkeypatch):
    xs = np.linspace(0.0, 1.0, 5)
    space = registry.case_space(case, 2, TensorPartition(xs, xs), SQUARE)
    x = SQUARE.quadrature(TensorPartition(xs, xs), 4)[0]
    calls = []
    real = symmetry._induced_permutation
    monkeypatch.setattr(symmetry, "_induced_permutation", lambda *a: calls.append(1) or real(*a))
    first = symmetry.induced_permutation(space, x, symmetry.reflect(0))
    again = symmetry.induced_permutation(space, x.copy(), symmetry.reflect(0))
    assert len(calls) == 1 and again is first and not first.flags.writeable
    assert np.array_equal(first, real(space, x, symmetry.reflect(0)))
    symmetry.induced_permutation(space, x, symmetry.reflect(1))
    symmetry.induced_permutation(space, x[:-1], symmetry.reflect(0))
    assert len(calls) == 3
    plain = lambda y: 1.0 - y  # noqa: E731 (no key: computed every time)
    symmetry.induced_permutation(space, x, plain)
    symmetry.induced_permutation(space, x, plain)
    assert len(calls) == 5
    key = id(space)
    assert key in symmetry._CACHE
    del space
    gc.collect()
    assert key not in symmetry._CACHE
