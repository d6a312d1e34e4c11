"""The QUAD8 face of HEX20 bodies (:class:`SerendipitySquare`): the spaces it builds, its dimension
counts against numerical ranks, and ``beta --element hex20 --case all`` against kernels predicted
from the dimension argument (and, for the tensor spaces below the count, the serendipity structure
W = P2_0 ⊗ P1_0 + P1_0 ⊗ P2_0, :func:`~infsup_contact.discretization.face.shapes.serendipity.tensor_modes`)."""
import io

import numpy as np
import pandas as pd
import pytest

from helpers.cli import run_in_process
from infsup_contact.discretization.face.shapes.serendipity import SERENDIPITY, interior_dimension, product_modes, tensor_modes
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.discretization.spaces.registry import common_ids, ids_built_on, SPACES
from infsup_contact.models import hex20
from infsup_contact.models.membranes3d import MEMBRANES3D

QUAD8_SPACES = ["TDUAL-Q8", "Q8", "Q8-ALL", "LIN0-Q8", "DISC-P1", "LINDUAL0-Q8", "LINDUAL-Q8", "PGLIN0-Q8", "PGLIN-Q8"]


def grid(n):
    return TensorPartition(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))


def predicted_kernel(case, n):
    """Kernel of Bᵀ on matching n × n meshes, k = 2: dim M − dim W, dim W = (3n − 1)(n − 1), written
    before the runs (QUAD9-type spaces: M ⊃ W, so exactly the count); T4 / T5, whose count is 0, showed
    modes in the first run, since proven from the tensor structure (the checkerboard, the four
    corner products a ⊗ b; :func:`~infsup_contact.discretization.face.shapes.serendipity.tensor_modes`). The linear
    dual on all vertices (LINDUAL-Q8) and its Petrov–Galerkin pair PGLIN-Q8: the four corner products of the
    1D end duals, orthogonal to every interior hat (predicted before the run, from tensor_modes)."""
    dim_w = (3 * n - 1) * (n - 1)
    count = {"T3": (2 * n - 1) ** 2, "DUAL": (2 * n - 1) ** 2, "R5.2": (2 * n + 1) ** 2,
             "DUAL-ALL": (2 * n + 1) ** 2, "R5.4": 4 * n * n, "Q8": dim_w, "TDUAL-Q8": dim_w,
             "Q8-ALL": 3 * n * n + 4 * n + 1, "DISC-P1": 3 * n * n,
             "LIN0-Q8": (n - 1) ** 2, "LINDUAL0-Q8": (n - 1) ** 2, "PGLIN0-Q8": (n - 1) ** 2}
    return {"T4": 1, "T5": 4, "LINDUAL-Q8": 4, "PGLIN-Q8": 4}.get(case, max(count.get(case, 0) - dim_w, 0))


def test_the_quad8_face_builds_the_tensor_spaces_and_the_quad8_ones_only():
    built = ids_built_on(2, SERENDIPITY, grid(2))
    assert built == common_ids(2) + QUAD8_SPACES
    assert "DUAL-Q8" not in built and "DUAL-Q9" not in built               # refused / a QUAD9 space
    assert "Q8" not in ids_built_on(2, MEMBRANES3D.subdomain_mesh("structured", 1, 1).interface, grid(2))


@pytest.mark.parametrize("n1,n2", [(3, 3), (2, 4), (3, 4), (4, 5)])
def test_trace_sum_dimension_is_the_rank_of_both_traces(n1, n2):
    traces = [SERENDIPITY.trace(hex20.displacement_space(
        MEMBRANES3D.subdomain_mesh("structured", n, s, element="hex20"))[1]) for n, s in ((n1, 1), (n2, 2))]
    for t, n in zip(traces, (n1, n2)):
        assert len(t.gamma_dofs) == interior_dimension(n, n) == SERENDIPITY.trace_dimension(2, n)
    xy = np.random.default_rng(3).random((3000, 2))
    phi = np.hstack([SERENDIPITY.trace_basis(t, xy) for t in traces])
    s = np.linalg.svd(phi, compute_uv=False)
    rank = int(np.sum(s > 1e-10 * s[0]))
    assert SERENDIPITY.trace_sum_dimension(2, *[t.partition for t in traces]) == rank


def test_quad8_space_dimensions_are_the_registry_counts():
    for case in QUAD8_SPACES:
        for n in (2, 3, 5):
            assert SERENDIPITY.space(SPACES[case], 2, grid(n)).dim == SPACES[case].dimension(2, n)


def test_beta_case_all_on_hex20_kernels_are_the_predicted_counts():
    n = 8
    code, out, err = run_in_process(["beta", "--model", "membranes3d", "--element", "hex20", "--case", "all",
                                     "--k", "2", "--N1", str(n), "--N2", str(n)])
    assert code == 0, err
    frame = pd.read_csv(io.StringIO(out))
    assert list(dict.fromkeys(frame.case)) == common_ids(2) + QUAD8_SPACES
    assert (frame.dim_W == (3 * n - 1) * (n - 1)).all()
    for case, rows in frame.groupby("case"):
        assert (rows.kernel_dim == predicted_kernel(case, n)).all(), case
        assert (rows.kernel_dim == rows.structural_kernel_dim).all() and (rows.kernel_decision == "clear").all()
        assert ((rows.beta > 0) == (rows.kernel_dim == 0)).all(), case
    # the spaces without a kernel: β_H bounded away from 0 (Q8: the trace space itself)
    assert (frame[(frame.kernel_dim == 0) & (frame.norm == "H")].beta > 0.5).all()


@pytest.mark.parametrize("k", ["1", "3"])
def test_hex20_refuses_other_degrees_in_one_line(k):
    code, out, err = run_in_process(["beta", "--model", "membranes3d", "--element", "hex20", "--case", "T3",
                                     "--k", k, "--N1", "2", "--N2", "2"])
    assert code == 2 and "k" in err and "expected 2" in err and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("n", [3, 4])
def test_product_modes_on_matching_grids_are_the_closed_form(n):
    """Two routes to the same number: the rank of Σ Π_A ⊗ Π_B and the formula from the 1D ranks."""
    for case in common_ids(2):
        space = SERENDIPITY.space(SPACES[case], 2, grid(n))
        assert product_modes(*space.factors, [grid(n)] * 2) == tensor_modes(*space.factors), case


def test_non_matching_kernels_of_the_tensor_spaces_are_the_product_modes():
    """4:5 (no common interior line): the measured kernel equals the span of the orthogonal products
    for every tensor space (T3, DUAL: 4 beyond a count of 0); Q8-ALL, not a product, has one mode
    beyond its count (8 against 7), decided clearly."""
    code, out, err = run_in_process(["beta", "--model", "membranes3d", "--element", "hex20", "--case", "all",
                                     "--k", "2", "--N1", "4", "--N2", "5", "--norm", "L2"])
    assert code == 0, err
    frame = pd.read_csv(io.StringIO(out)).set_index("case")
    tensor = [c for c in frame.index if SPACES[c].defined_on(1)]
    assert (frame.loc[tensor, "kernel_dim"] == frame.loc[tensor, "structural_kernel_dim"]).all()
    assert frame.loc["T3", "kernel_dim"] == 4 and frame.loc["T3", "dim_M"] - frame.loc["T3", "dim_W"] < 0
    assert (frame.kernel_decision == "clear").all()
