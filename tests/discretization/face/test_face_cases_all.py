"""``--case all`` on a 3D model: the paper's spaces, the duals and every space the face builds
(:func:`~infsup_contact.discretization.spaces.registry.ids_built_on`)."""
import io

import numpy as np
import pandas as pd
import pytest

from helpers.cli import run_in_process
from infsup_contact.discretization.spaces.registry import common_ids, ids_built_on, ids_valid_for, space_ids, SPACES
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition

GRID = TensorPartition(np.linspace(0, 1, 3), np.linspace(0, 1, 3))


@pytest.mark.parametrize("gamma,cell", [(SQUARE, "quad"), (SQUARE_TRIG, "trig")])
def test_the_face_builds_its_cells_spaces_and_leaves_out_the_refused(gamma, cell):
    built = ids_built_on(2, gamma, GRID)
    assert set(common_ids(2)) <= set(built)                     # the paper's five and the duals
    face_only = [c for c in ids_valid_for(2, space_ids(2)) if not SPACES[c].defined_on(1)]
    on_cells = [c for c in face_only if cell in SPACES[c].face_cells]
    assert on_cells and set(built) - set(common_ids(2)) <= set(on_cells)
    refused = set(on_cells) - set(built)                             # e.g. a dual basis with weights ≤ 0
    for case in refused:
        with pytest.raises(Exception, match="use case"):
            gamma.space(SPACES[case], 2, GRID)
    assert not set(built) & {c for c in face_only if cell not in SPACES[c].face_cells}


def test_the_face_builds_k_1_spaces_only_if_valid_for_k_1_and_the_segment_no_face_space():
    built = ids_built_on(1, SQUARE, GRID)
    assert set(common_ids(1)) <= set(built) and all(SPACES[c].valid_for(1) for c in built)
    assert ids_built_on(2, SEGMENT, np.linspace(0, 1, 5)) == common_ids(2)


def test_case_all_on_the_3d_model_computes_every_built_space():
    code, out, err = run_in_process(["beta", "--model", "membranes3d", "--k", "2", "--N1", "2", "--N2", "2",
                                     "--element", "hex", "--norm", "L2"])
    assert code == 0, err
    frame = pd.read_csv(io.StringIO(out))
    assert list(frame.case) == ids_built_on(2, SQUARE, GRID)
    assert (frame.kernel_dim == frame.structural_kernel_dim).all()
