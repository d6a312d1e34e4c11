"""Γ as an object (issue 27, item 3): the interface's partitions, quadrature, Gram matrices and
dimension counts, and the seam — no solver takes a breakpoint array apart itself."""
import inspect
import pathlib
import re

import numpy as np
import pytest

import infsup_contact
from infsup_contact.discretization.segment import meshes, norms
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.gamma.interface import Interface
from infsup_contact.discretization.segment.interface import SEGMENT, Segment
from infsup_contact.discretization.spaces.registry import case_space
from infsup_contact.errors import InputError
from infsup_contact.models import make_model
from infsup_contact.solvers.side_cache import SideCache
from infsup_contact.solvers.request import MeshOptions

SRC = pathlib.Path(infsup_contact.__file__).parent


@pytest.fixture(scope="module")
def perturbed_sides():
    return SideCache().pair(make_model("membranes"), "perturbed", 2, 5, 3, MeshOptions(seed=3, alpha=0.2))


def test_the_segment_is_an_interface_and_the_abc_is_abstract():
    assert isinstance(SEGMENT, Interface) and SEGMENT.dim == 1
    with pytest.raises(TypeError):
        Interface()
    abstract = Interface.__abstractmethods__
    assert {"partition_of", "common_refinement", "multiplier_partition", "trace", "trace_basis", "quadrature",
            "gram", "trace_dimension", "trace_sum_dimension", "embed", "dim"} <= abstract
    for name in abstract:  # every method a 2D face must implement is documented (numpy style)
        doc = inspect.getdoc(getattr(Interface, name))
        assert doc, name
        if name != "dim":
            assert "Returns" in doc, name
    assert SEGMENT.boundary == meshes.GAMMA


@pytest.mark.parametrize("model", ["membranes", "elastic"])
def test_sides_carry_their_interface(model):
    m1, m2 = meshes.mesh_pair("structured", 4, 3)
    sides = [make_model(model).side_operator(m, 2) for m in (m1, m2)]
    for s, m in zip(sides, (m1, m2)):
        assert s.trace.gamma is SEGMENT
        np.testing.assert_array_equal(s.trace.partition, SEGMENT.partition_of(m))
        # dim W_h = N k − 1 free Γ dofs per side
        assert len(s.trace.gamma_dofs) == SEGMENT.trace_dimension(2, SEGMENT.cells(s.trace.partition))


def test_union_is_the_common_refinement_of_both_traces(perturbed_sides):
    p1, p2 = (s.trace.partition for s in perturbed_sides)
    union = SEGMENT.multiplier_partition(p1, p2, "union")
    np.testing.assert_array_equal(union, SEGMENT.common_refinement(p1, p2))
    for p in (p1, p2):  # contains both traces: every vertex of a trace is a vertex of the union
        assert np.all(np.min(np.abs(union[:, None] - p[None, :]), axis=0) < 1e-12)
    # and nothing else: every vertex of the union is a vertex of a trace
    both = np.concatenate([p1, p2])
    assert np.all(np.min(np.abs(both[:, None] - union[None, :]), axis=0) < 1e-12)
    assert np.all(np.diff(union) > 0) and union[0] == 0.0 and union[-1] == 1.0
    np.testing.assert_array_equal(SEGMENT.multiplier_partition(p1, p2, "omega1"), p1)
    np.testing.assert_array_equal(SEGMENT.multiplier_partition(p1, p2, "omega2"), p2)
    assert SEGMENT.cells(union) == len(union) - 1
    assert SEGMENT.multiplier_cells(5, 3, "union") == 5 + 3 - 1  # uniform traces: only the ends shared
    with pytest.raises(InputError, match="omega2, omega1, union"):
        SEGMENT.multiplier_partition(p1, p2, "both")


@pytest.mark.parametrize("degree", range(0, 9))
def test_quadrature_is_exact_for_its_degree(degree):
    p = np.array([0.0, 0.1, 0.35, 0.4, 0.8, 1.0])
    x, w = SEGMENT.quadrature(p, degree)
    for q in range(degree + 1):
        assert w @ x ** q == pytest.approx(1.0 / (q + 1), rel=1e-13, abs=1e-15)
    # piecewise polynomials with kinks at the breakpoints, too
    f = np.where(x < 0.35, (x - 0.1) ** degree, -(x - 0.8) ** degree)
    a, b = (0.35 - 0.1) ** (degree + 1) - (-0.1) ** (degree + 1), -((0.2) ** (degree + 1) - (-0.45) ** (degree + 1))
    assert w @ f == pytest.approx((a + b) / (degree + 1), rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("case,k", [("T3", 1), ("T3", 2), ("R5.2", 2), ("R5.4", 2), ("T5", 3), ("DUAL", 2)])
@pytest.mark.parametrize("norm", ["L2", "H"])
def test_gram_is_spd_and_the_previous_route(case, k, norm):
    p = np.array([0.0, 0.15, 0.3, 0.55, 0.7, 0.85, 1.0])
    space = case_space(case, k, p, SEGMENT)
    G, info = SEGMENT.gram(space, norm)
    G0, info0 = norms.gram(space, norm)
    np.testing.assert_array_equal(G, G0)
    assert info == info0
    np.testing.assert_allclose(G, G.T, rtol=0, atol=1e-14 * np.abs(G).max())
    assert np.linalg.eigvalsh(G).min() > 0


def test_coupling_uses_the_common_refinement(perturbed_sides):
    """B_i from the interface's rule on the trace ∪ G_h equals a much longer rule there."""
    s = perturbed_sides[0]
    g_h = SEGMENT.multiplier_partition(*(t.trace.partition for t in perturbed_sides), "omega2")
    space = case_space("T3", 2, g_h, SEGMENT)
    B = coupling_matrix(s.trace, space, 2)
    x, w = SEGMENT.quadrature(SEGMENT.common_refinement(s.trace.partition, g_h), 20)
    ref = (space.evaluate(x) * w[:, None]).T @ SEGMENT.trace_basis(s.trace, x)
    np.testing.assert_allclose(B, ref, rtol=0, atol=1e-14)


def test_trace_sum_dimension():
    # matching traces: W1 = W2; disjoint interiors (5 vs 3): only the ends are shared
    x5, x3 = np.linspace(0, 1, 6), np.linspace(0, 1, 4)
    assert SEGMENT.trace_sum_dimension(2, x5, x5) == SEGMENT.trace_dimension(2, 5)
    assert SEGMENT.trace_sum_dimension(2, x5, x3) == (5 * 2 - 1) + (3 * 2 - 1) - (1 * 2 - 1)


def test_sampling_and_boundary_cells():
    p = np.array([0.0, 0.25, 0.5, 1.0])
    x = SEGMENT.sample(p, 4)
    assert x[0] == 0.0 and x[-1] == 1.0 and len(x) == 3 * 4 + 1
    assert SEGMENT.sample(p, 4, upper=1.0 - 1e-15)[-1] < 1.0
    np.testing.assert_array_equal(SEGMENT.at_boundary(p, np.array([0.1, 0.3, 0.6])), [True, False, True])
    X, Y = SEGMENT.embed(np.array([0.2, 0.7]))
    np.testing.assert_array_equal(Y, 1.0)


def test_a_second_segment_is_a_separate_interface():
    other = Segment(boundary="gamma", y=1.0)
    assert other == SEGMENT and isinstance(other, Interface)


PARTITION_FUNCTIONS = ("union_breakpoints", "partition_choice", "gamma_breakpoints", "multiplier_breakpoints",
                       "quadrature_on", "np.union1d", "searchsorted")


@pytest.mark.parametrize("folder", ["solvers", "study"])
def test_no_solver_or_study_takes_partitions_apart(folder):
    """Consumers ask Γ (``trace.gamma``): no module of solvers/ or study/ builds a partition,
    a quadrature or a space from breakpoint arrays itself."""
    offenders = []
    checked = PARTITION_FUNCTIONS if folder == "solvers" else PARTITION_FUNCTIONS[:5]
    for path in sorted((SRC / folder).glob("*.py")):
        text = path.read_text()
        for name in checked:
            if re.search(rf"\b{re.escape(name)}\b", text):
                offenders.append(f"{path.name}: {name}")
    assert not offenders, offenders


def test_the_old_free_functions_are_gone():
    from infsup_contact.discretization.gamma import coupling

    for mod, names in ((coupling, ("union_breakpoints", "quadrature_on", "gamma_trace", "trace_basis_at")),
                       (meshes, ("gamma_breakpoints", "partition_choice"))):
        for name in names:
            assert not hasattr(mod, name), f"{mod.__name__}.{name}"
