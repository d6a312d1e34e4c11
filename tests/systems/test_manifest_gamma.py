"""A manifest's ``gamma`` names its Γ: the Interface its multipliers are checked on comes from the
Γ table by that name (the pull-back of a segment is the unit segment, of a rectangle the unit
square), never from a default."""
from __future__ import annotations

import pytest

from infsup_contact.discretization.spaces.gammas import gamma_of
from infsup_contact.systems.multiplier_basis import GAMMA_SHAPES, parse_gamma

GIVEN = {"segment": {"shape": "segment", "length": 2.0}, "rectangle": {"shape": "rectangle", "size": [1.0, 3.0]}}


def test_every_manifest_shape_has_a_pull_back_in_the_gamma_table():
    assert set(GAMMA_SHAPES) == set(GIVEN)


@pytest.mark.parametrize("shape", GAMMA_SHAPES)
def test_the_interface_is_the_tables_and_has_the_manifests_dimension(shape):
    gamma = parse_gamma("levels.yaml", GIVEN[shape])
    assert gamma.interface is gamma_of(GAMMA_SHAPES[shape])
    assert gamma.interface.dim == len(gamma.size)
