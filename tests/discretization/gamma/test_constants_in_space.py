"""1 ∈ M_h computed on the space a solver uses (discretization/gamma/constants.py): on the segment it
agrees with the registry's rule for every space and degree; on the six-tetrahedra face the TRI3
dual loses the constants at its two corner triangles (all three vertices on ∂Γ), and the patch
test fails exactly there."""
import numpy as np
import pytest

from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.gamma.constants import interior_samples, spans_constants
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.study.patch import face as face_patch


@pytest.mark.parametrize("k", [1, 2, 3])
def test_segment_spaces_agree_with_the_registry_rule(k):
    for case in registry.common_ids(k):
        spec = registry.space_spec(case)
        if not spec.defined_on(1):
            continue
        space = spec.build(k, np.linspace(0.0, 1.0, 8))
        assert spans_constants(space) == spec.contains_constants(k), case


def test_samples_avoid_cell_boundaries_and_diagonals():
    xs, ys = np.linspace(0, 1, 4), np.array([0.0, 0.3, 1.0])
    p = interior_samples(TensorPartition(xs, ys))
    assert len(p) == 3 * 2 * 25
    assert not np.isin(p[:, 0], xs).any() and not np.isin(p[:, 1], ys).any()
    ix, iy = np.searchsorted(xs, p[:, 0]) - 1, np.searchsorted(ys, p[:, 1]) - 1
    u = (p[:, 0] - xs[ix]) / np.diff(xs)[ix]
    v = (p[:, 1] - ys[iy]) / np.diff(ys)[iy]
    assert np.min(np.abs(u - v)) > 1e-3                 # off the diagonal of every cell


def test_tri3_dual_on_tetrahedra_loses_the_constants_at_the_corners():
    """DUAL at k = 1: the quads' tensor dual keeps 1, the triangles' does not; the patch test
    agrees with the computed property and not with the segment's rule."""
    for gamma, expected in ((SQUARE, True), (SQUARE_TRIG, False)):
        rows = face_patch.face_patch_rows(["DUAL", "R5.2"], [1], [(4, 5)],
                                          element="hex" if gamma is SQUARE else "tet")
        by = {r["case"]: r for r in rows}
        assert by["DUAL"]["predicted"] is expected and by["DUAL"]["segment_rule"] is True
        assert by["DUAL"]["passes"] is expected
        assert by["R5.2"]["predicted"] and by["R5.2"]["passes"]
