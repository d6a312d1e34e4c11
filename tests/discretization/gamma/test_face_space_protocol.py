"""A new face space is one class behind the MultiplierSpace protocol plus one registry entry.

The space here exists only in this file: Q_0 on the rectangles of G_h (one indicator per
rectangle). It states the protocol's required attributes, inherits the optional ones from
SpaceDefaults, and is registered for the face only (no segment build). The registry, the
face interface, the constants check and the exact L² Gram then serve it like a built-in space.
"""
from dataclasses import dataclass

import numpy as np
import pytest

from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.discretization.gamma.constants import spans_constants
from infsup_contact.discretization.gamma.protocol import MultiplierSpace, SpaceDefaults
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.spaces.spec import SpaceSpec
from infsup_contact.errors import InputError


@dataclass(frozen=True)
class CellIndicators(SpaceDefaults):
    """Q_0 on the rectangles of a tensor partition: μ_(i, j) = 1 on [x_i, x_i+1] × [y_j, y_j+1]."""

    breakpoints: TensorPartition
    degree = 0
    continuous = False

    @property
    def dim(self) -> int:
        return self.breakpoints.cells

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        xs, ys = np.asarray(self.breakpoints.xs), np.asarray(self.breakpoints.ys)
        i = np.clip(np.searchsorted(xs, x[:, 0], side="right") - 1, 0, len(xs) - 2)
        j = np.clip(np.searchsorted(ys, x[:, 1], side="right") - 1, 0, len(ys) - 2)
        out = np.zeros((len(x), self.dim))
        out[np.arange(len(x)), i * (len(ys) - 1) + j] = 1.0
        return out


ENTRY = SpaceSpec("Q0-CELLS", "test", "Q_0 on the rectangles of G_h", None, lambda k: 0,
                  dimension=lambda k, n: n * n, gamma_dims=(2,), face_cells=("quad",),
                  face_build=lambda k, partition: CellIndicators(partition))


@pytest.fixture
def registered(monkeypatch):
    monkeypatch.setitem(registry.SPACES, ENTRY.id, ENTRY)
    return ENTRY.id


def grid(n, graded=False):
    x = np.linspace(0.0, 1.0, n + 1)
    return TensorPartition(x ** 2 if graded else x, x)


@pytest.mark.parametrize("n", [1, 2, 5])
@pytest.mark.parametrize("k", [1, 2, 3])
def test_built_by_the_registry_with_the_dimension_it_states(registered, k, n):
    space = registry.case_space(registered, k, grid(n), SQUARE)
    assert isinstance(space, MultiplierSpace)
    assert space.dim == ENTRY.dimension(k, n) == registry.space_dim(registered, k, n)
    assert space.evaluate(SQUARE.sample(space.breakpoints, 2)).shape[1] == space.dim


def test_listed_for_the_face_only(registered):
    assert registered in registry.space_ids(2) and registered not in registry.space_ids(1)
    assert registered in registry.ids_built_on(1, SQUARE, grid(3))
    assert registered not in registry.ids_built_on(1, SQUARE_TRIG, grid(3))  # its cells are rectangles
    with pytest.raises(InputError) as err:
        registry.case_space(registered, 1, np.linspace(0.0, 1.0, 4), SEGMENT)
    assert err.value.key == "case"


def test_contains_the_constants_and_its_l2_gram_is_the_cell_areas(registered):
    """Σ_j μ_j = 1, so 1 ∈ M_h; the indicators are L²-orthogonal with ‖μ_j‖² = |cell j|."""
    assert ENTRY.contains_constants(1)
    space = registry.case_space(registered, 1, grid(4, graded=True), SQUARE)
    assert spans_constants(space)
    G, _ = SQUARE.gram(space, "L2")
    xs, ys = space.breakpoints.xs, space.breakpoints.ys
    areas = np.outer(np.diff(xs), np.diff(ys)).ravel()
    assert np.allclose(G, np.diag(areas), rtol=0, atol=1e-14)


def test_a_segment_entry_needs_a_build():
    with pytest.raises(InputError) as err:
        SpaceSpec("NO-BUILD", "test", "", None, lambda k: 0)
    assert err.value.key == "space"
