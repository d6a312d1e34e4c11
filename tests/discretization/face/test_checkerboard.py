"""The checkerboard mode of P_0 multipliers against P_2 traces on the same triangles
(Square.checkerboard_modes): proven, found numerically, and carried into the face predictions."""
import numpy as np
import pytest

from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.models import MODELS
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.solvers import infsup
from infsup_contact.solvers.side_cache import SideCache
from infsup_contact.study.claims.membranes3d import checkerboard, face_predictions
from infsup_contact.solvers.request import MeshOptions


def _grid(n):
    x = np.linspace(0.0, 1.0, n + 1)
    return TensorPartition(x, x)


@pytest.mark.parametrize("case, k, gamma, expected", [
    ("T4", 2, SQUARE_TRIG, 1), ("R5.4", 1, SQUARE_TRIG, 0), ("R5.4", 2, SQUARE_TRIG, 0),
    ("T4", 3, SQUARE_TRIG, 0), ("T4", 2, SQUARE, 0)])
def test_the_rule_holds_only_for_p0_against_p2_on_triangles(case, k, gamma, expected):
    space = gamma.space(SPACES[case], k, _grid(3))
    assert gamma.checkerboard_modes(space, k, [_grid(3)] * 2) == expected
    assert gamma.checkerboard_modes(space, k, [_grid(3), _grid(4)]) == 0  # non-matching traces


def test_the_checkerboard_is_in_the_kernel_of_the_couplings():
    """μ = ±1/|T| (lower +, upper −) is orthogonal to both sides' P_2 traces, and the numerical
    kernel of T4 at k = 2 on matching tetrahedral meshes is exactly that one mode."""
    rows = infsup.beta_rows("structured", 2, 3, 3, ["T4"], model=MODELS["membranes3d"], mesh=MeshOptions(element="tet"),
                            norms=("L2",))
    assert (rows[0]["kernel_dim"], rows[0]["structural_kernel_dim"], rows[0]["kernel_check"]) == (1, 1, "agree")
    sides = SideCache().pair(MODELS["membranes3d"], "structured", 2, 3, 3, MeshOptions(element="tet"))
    gamma = sides[0].trace.gamma
    space = gamma.space(SPACES["T4"], 2, sides[1].trace.partition)
    tri = space.triangles()
    (ax, ay), (bx, by) = (tri[:, 1] - tri[:, 0]).T, (tri[:, 2] - tri[:, 0]).T
    area = 0.5 * np.abs(ax * by - ay * bx)
    mu = np.where(np.arange(len(tri)) % 2 == 0, 1.0, -1.0) / area  # (i, j, lower/upper) order
    nodes = np.mean(tri, axis=1)  # one point per triangle: P_0 basis index = triangle index
    assert np.allclose(space.evaluate(nodes), np.eye(len(tri)))
    for side in sides:
        B = coupling_matrix(side.trace, space, 2)
        assert np.linalg.norm(B.T @ mu) <= 1e-12 * np.linalg.norm(B, 2) * np.linalg.norm(mu)
    rows = infsup.beta_rows("structured", 2, 3, 4, ["T4"], model=MODELS["membranes3d"], mesh=MeshOptions(element="tet"), norms=("L2",))
    assert rows[0]["structural_kernel_dim"] == 0  # non-matching: no proof (and no mode)


def test_the_face_predictions_follow_the_proof():
    tri = face_predictions(SPACES["T4"], 2, [], False, SQUARE_TRIG)
    quad = face_predictions(SPACES["T4"], 2, [], True, SQUARE)
    assert (tri["kernel"], tri["bounded"], tri["l2"]) == ("FAIL", "FAIL", "FAIL")
    assert (quad["kernel"], quad["bounded"], quad["l2"]) == ("PASS", "PASS", "PASS")
    assert checkerboard(SPACES["T4"], 2, SQUARE_TRIG) and not checkerboard(SPACES["T4"], 1 + 2, SQUARE_TRIG)
