"""The face element spaces of the registry (issue 28): QUAD9 / QUAD8 dual, transformed dual and
4C pwlin multipliers on the face Γ = (0,1)²×{1}. The non-tensor Gram route against the tensor one
where a space is both, the H Gram's bounds, the kernel against the dimension argument, β_h against
the full saddle-point pencil, the refusals (DUAL-Q8's weights, the segment), and the α sweep."""
import numpy as np
import pandas as pd
import pytest

from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.segment.dual import dual_space
from infsup_contact.discretization.face.spaces.cellwise import CellwiseFaceSpace
from infsup_contact.discretization.face.spaces.dual_bases import weights
from infsup_contact.discretization.face.spaces.tensor import FaceSpace
from infsup_contact.discretization.segment.multipliers import make_space
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError
from infsup_contact.models import make_model
from infsup_contact.solvers.side_cache import SideCache
from infsup_contact.solvers.infsup import beta_rows, saddle_point_beta
from infsup_contact.contact.contact import contact_qp
from infsup_contact.solvers.request import MeshOptions

MODEL = make_model("membranes3d")
FACE_IDS = [c for c in registry.space_ids(None) if not registry.SPACES[c].defined_on(1)]
BUILDABLE = [c for c in FACE_IDS if c != "DUAL-Q8" and SQUARE.builds(registry.SPACES[c])]  # rectangles (TRI6: test_face_tri6)
GRID = TensorPartition(np.array([0.0, 0.3, 0.55, 1.0]), np.array([0.0, 0.45, 1.0]))  # non-uniform 3 × 2


def change_of_basis(tensor, cellwise):
    """T with cellwise basis = tensor basis · T, from values at points (checked to round-off)."""
    x, _ = SQUARE.quadrature(GRID, 6)
    Et, Ec = tensor.evaluate(x), cellwise.evaluate(x)
    T = np.linalg.lstsq(Et, Ec, rcond=None)[0]
    assert np.max(np.abs(Et @ T - Ec)) < 1e-12
    return T


@pytest.mark.parametrize("basis,vanish,factor", [
    ("standard", False, lambda g: make_space(g, 1, True, False)),   # QUAD4 nodal = Q1 ⊗ Q1
    ("dual", True, lambda g: dual_space(g, 1, True)),               # QUAD4 dual = 1D DUAL ⊗ 1D DUAL
])
def test_cellwise_gram_equals_the_tensor_route(basis, vanish, factor):
    cellwise = CellwiseFaceSpace(GRID, "QUAD4", basis, vanish_on_boundary=vanish)
    tensor = FaceSpace(factor(GRID.xs), factor(GRID.ys), GRID)
    assert cellwise.dim == tensor.dim
    T = change_of_basis(tensor, cellwise)
    for norm in ("L2", "H"):
        Gc = SQUARE.gram(cellwise, norm, rtol=1e-9)[0]
        Gt = SQUARE.gram(tensor, norm, rtol=1e-9)[0]
        assert np.linalg.norm(Gc - T.T @ Gt @ T, 2) <= 1e-7 * np.linalg.norm(Gc, 2), norm


@pytest.mark.parametrize("case", BUILDABLE)
def test_h_gram_is_spd_and_below_l2_over_pi_sqrt2(case):
    """‖μ‖²_M = Σ μ_mn² / (π√(m²+n²)) ≤ Σ μ_mn² / (π√2) = ‖μ‖²_L² / (π√2) (Parseval)."""
    space = SQUARE.space(registry.SPACES[case], 2, GRID)
    GH, info = SQUARE.gram(space, "H")
    GL = SQUARE.gram(space, "L2")[0]
    assert np.linalg.eigvalsh(GH).min() > 0
    assert np.linalg.eigvalsh(GL / (np.pi * np.sqrt(2)) - GH).min() >= -1e-5 * np.linalg.norm(GH, 2)
    assert info["nmax_rel_error"] <= 1e-6


def test_dimensions_kernel_and_beta_on_matching_meshes():
    """dim M_h is the registry's count and kernel_dim the dimension argument max(dim M − dim W, 0)."""
    for n in (2, 3):
        frame = pd.DataFrame(beta_rows("structured", 2, n, n, cases=BUILDABLE, norms=("H",), model=MODEL,
                                       mesh=MeshOptions(element="hex")))
        for _, row in frame.iterrows():
            spec = registry.SPACES[row.case]
            assert row.dim_M == spec.dimension(2, n), row.case
            assert row.kernel_dim == row.structural_kernel_dim == spec.structural_kernel(2, n), row.case
            assert row.kernel_decision == "clear", row.case
            assert (row.beta > 0) == (row.kernel_dim == 0), row.case


@pytest.mark.parametrize("case,n1,n2", [("TDUAL-Q8", 2, 3), ("PWLIN-Q9", 2, 2)])
def test_beta_agrees_with_the_saddle_point_pencil(case, n1, n2):
    k = 2
    sides = SideCache().pair(MODEL, "structured", k, n1, n2, MeshOptions(element="hex"))
    gamma = sides[0].trace.gamma
    space = registry.case_space(case, k, gamma.multiplier_partition(*(s.trace.partition for s in sides)), gamma)
    Bs = [coupling_matrix(s.trace, space, k) for s in sides]
    A, B, _ = contact_qp(sides, Bs, [np.zeros(s.ndof) for s in sides])  # the assembled pencil's blocks
    B = B.toarray()
    frame = pd.DataFrame(beta_rows("structured", k, n1, n2, cases=[case], model=MODEL, mesh=MeshOptions(element="hex")))
    for norm, row in frame.set_index("norm").iterrows():
        assert saddle_point_beta(A, B, gamma.gram(space, norm)[0]) == pytest.approx(row.beta, rel=1e-8)


def test_dual_q8_is_refused_with_its_weights_and_the_remedy():
    corner = weights("QUAD8")[0]
    assert corner < 0
    with pytest.raises(InputError) as err:
        registry.case_space("DUAL-Q8", 2, GRID, SQUARE)
    text = str(err.value)
    assert "QUAD8" in text and "TDUAL-Q8" in text and f"{round(corner, 12)}" in text
    assert registry.space_dim("TDUAL-Q8", 2, 3) == registry.SPACES["TDUAL-Q8"].dimension(2, 3)


def test_an_empty_face_space_is_refused_before_any_computation():
    """TDUAL-Q8 on one cell: QUAD8 has no node inside (0, 1)², dim M_h = 0 = the count."""
    from infsup_contact.models import MODELS
    from infsup_contact.solvers.request import BetaRequest, MeshOptions

    assert registry.SPACES["TDUAL-Q8"].dimension(2, 1) == 0
    model = MODELS["membranes3d"]  # the request's Γ is the face (the 2D model's segment refuses the id)
    with pytest.raises(InputError, match="dim M_h = 0"):
        BetaRequest("structured", 2, 1, 1, ("TDUAL-Q8",), norms=("H",), model=model,
                    mesh=MeshOptions(element="hex"))


def test_face_spaces_stay_off_the_segment():
    """The 2D listings are the segment's; a face id on the segment is refused in one line."""
    assert all(registry.SPACES[c].defined_on(1) for c in registry.common_ids())
    assert set(registry.PAPER_CASES) <= set(registry.common_ids())
    assert not set(FACE_IDS) & set(registry.common_ids(2))
    assert set(BUILDABLE) <= set(registry.ids_valid_for(2, registry.space_ids(2)))
    for case in FACE_IDS:
        with pytest.raises(InputError, match="face of a 3D model") as err:
            registry.case_space(case, 2, np.linspace(0, 1, 4), SEGMENT)
        assert "\n" not in str(err.value)


def test_alpha_sweep_refuses_nonpositive_weights():
    """QUAD8: ∫Ñ_corner = (8α − 1)/3 ≤ 0 for α ≤ 1/8 — refused rows carry no β."""
    from infsup_contact.study.face.alpha import sweep

    rows = pd.DataFrame(sweep(ns=(2,), alphas=(0.1, 0.125, 0.2), elements=("QUAD8",)))
    assert list(rows.refused) == [True, True, False]
    assert rows.beta.isna().tolist() == [True, True, False]
    assert rows.min_weight.iloc[2] == pytest.approx(weights("QUAD8", 0.2).min() / 4)


@pytest.mark.parametrize("case", ["PWLIN-Q9", "TDUAL-Q9"])
def test_coupling_is_exact_on_the_pieces(case):
    """B_ij = ∫ μ_i φ_j against a rule on the grid refined 4× per direction (every piece of pwlin
    a union of its rectangles), exact per variable to degree 9."""
    k = 2
    side = SideCache().pair(MODEL, "structured", k, 2, 3, MeshOptions(element="hex"))[0]
    part = side.trace.partition
    space = registry.case_space(case, k, part, SQUARE)
    fine = [np.linspace(0, 1, 4 * (len(g) - 1) + 1) for g in (part.xs, part.ys)]
    x, w = SQUARE.quadrature(TensorPartition(*fine), 9)
    ref = (space.evaluate(x) * w[:, None]).T @ SQUARE.trace_basis(side.trace, x)
    assert np.max(np.abs(coupling_matrix(side.trace, space, k) - ref)) < 1e-13
