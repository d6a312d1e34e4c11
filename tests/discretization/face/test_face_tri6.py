"""The TRI6 multipliers of tetrahedral faces (issue 28, item 3; discretization/face/spaces/tri6.py): exact
weights in rationals, biorthogonality and span of the transformed dual, the pwlin split against P1
and against the global space, the refusals, DUAL = TDUAL-T6 at k = 2, and β_H bounded in N."""
from fractions import Fraction
from math import factorial

import numpy as np
import pandas as pd
import pytest

from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.face.spaces.dual_bases import ZERO_WEIGHT_RTOL, dual_coefficients, transformation, weights
from infsup_contact.discretization.face.spaces.reference_elements import (cell_quadrature, pwlin_shapes, pwlin_subelements,
                                                         reference_element)
from infsup_contact.discretization.face.spaces.tri6 import halved, tri6_space
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.discretization.face.shapes.square import SQUARE, SQUARE_TRIG
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError
from infsup_contact.solvers.request import MeshOptions

TRI6 = reference_element("TRI6")
ALPHAS = (Fraction(0), Fraction(1, 10), Fraction(1, 5), Fraction(1, 4), Fraction(1, 3), Fraction(9, 20))
GRID = TensorPartition(np.array([0.0, 0.3, 0.55, 1.0]), np.array([0.0, 0.45, 1.0]))  # non-uniform 3 × 2
TRI6_IDS = [c for c, s in registry.SPACES.items() if s.face_cells == ("trig",)]
RNG = np.random.default_rng(6)


def _solve_fractions(A, B):
    """X with A X = B over the rationals (Gauss–Jordan; A square, invertible)."""
    n = len(A)
    M = [list(A[i]) + list(B[i]) for i in range(n)]
    for c in range(n):
        p = next(r for r in range(c, n) if M[r][c] != 0)
        M[c], M[p] = M[p], M[c]
        M[c] = [v / M[c][c] for v in M[c]]
        for r in range(n):
            if r != c and M[r][c] != 0:
                M[r] = [a - M[r][c] * b for a, b in zip(M[r], M[c])]
    return [row[n:] for row in M]


def exact_weights(alpha: Fraction) -> list:
    """∫Ñ_k over the unit triangle in rationals, independently of the library's quadrature: N = P V⁻¹
    with V the Vandermonde of the monomials at the nodes, ∫ξ^a η^b = a! b! / (a + b + 2)!, Ñ = T(α) N
    with T built from the element's corners and edges."""
    nodes = [[Fraction(str(v)) for v in p] for p in TRI6.nodes]
    V = [[x ** a * y ** b for a, b in TRI6.exponents] for x, y in nodes]
    Vinv = _solve_fractions(V, [[Fraction(int(i == j)) for j in range(6)] for i in range(6)])
    mono = [Fraction(factorial(a) * factorial(b), factorial(a + b + 2)) for a, b in TRI6.exponents]
    d = [sum(mono[m] * Vinv[m][k] for m in range(6)) for k in range(6)]
    T = [[Fraction(int(i == j)) for j in range(6)] for i in range(6)]
    for a, b, m in TRI6.edges:
        T[a][m] += alpha
        T[b][m] += alpha
        T[m][m] = 1 - 2 * alpha
    return [sum(T[i][j] * d[j] for j in range(6)) for i in range(6)]


@pytest.mark.parametrize("alpha", ALPHAS)
def test_transformed_weights_are_the_exact_rationals(alpha):
    """∫Ñ_vertex = α/3, ∫Ñ_edge = (1 − 2α)/6 (α = 0: the plain weights 0 and 1/6; α = 1/5: 1/15, 1/10)."""
    exact = exact_weights(alpha)
    assert exact == [alpha / 3] * 3 + [(1 - 2 * alpha) / 6] * 3
    assert sum(exact) == Fraction(1, 2)                                    # Σ Ñ = 1: the area
    assert np.max(np.abs(weights("TRI6", float(alpha)) - np.array(exact, float))) < 1e-15


def test_pwlin_weights_are_the_sub_triangle_counts():
    """A pwlin function is the hat of its node on each of the 4 sub-triangles (area 1/8) holding it:
    ∫ = (sub-triangles holding the node) · (1/8) / 3, i.e. 1/24 at a vertex, 1/8 at an edge node."""
    count = [sum(k in nodes for _, nodes in pwlin_subelements("TRI6")) for k in range(6)]
    exact = [Fraction(c, 24) for c in count]
    assert exact == [Fraction(1, 24)] * 3 + [Fraction(1, 8)] * 3 and sum(exact) == Fraction(1, 2)
    pts, w = [], []
    for _, nodes in pwlin_subelements("TRI6"):                           # a rule exact on each piece
        v = TRI6.nodes[list(nodes)]
        x, wx = cell_quadrature("tri", 2)
        pts.append(v[0] + x @ np.array([v[1] - v[0], v[2] - v[0]]))
        w.append(wx / 4)
    integral = np.concatenate(w) @ pwlin_shapes("TRI6", np.vstack(pts))
    assert np.max(np.abs(integral - np.array(exact, float))) < 1e-15


def test_pwlin_reproduces_p1_on_the_reference_triangle():
    x = RNG.random((200, 2))
    x = x[x.sum(1) <= 1.0]
    phi = pwlin_shapes("TRI6", x)
    for p in (lambda z: np.ones(len(z)), lambda z: z[:, 0], lambda z: z[:, 1], lambda z: 2 - 3 * z[:, 0] + 5 * z[:, 1]):
        assert np.max(np.abs(phi @ p(TRI6.nodes) - p(x))) < 1e-14
    assert not np.allclose(phi @ (TRI6.nodes[:, 0] ** 2), x[:, 0] ** 2)   # linear pieces: not P2


def test_pwlin_space_is_the_pwlin_split_of_every_triangle():
    """Two routes: PWLIN-T6 (P1 on the diagonal-cut halved grid) = pwlin_shapes on each triangle of G_h
    mapped affinely, the TRI6 nodes matched to the space's nodes (∂Γ nodes: no dof)."""
    space = registry.case_space("PWLIN-T6", 2, GRID, SQUARE_TRIG)
    assert space.dim == (2 * 3 - 1) * (2 * 2 - 1)
    x = np.column_stack([RNG.random(400), RNG.random(400)])
    ref = np.zeros((len(x), space.dim))
    nodes = space.nodes()
    for tri in tri6_space(GRID, "transformed_dual").triangles():
        A, J = tri[0], np.column_stack([tri[1] - tri[0], tri[2] - tri[0]])
        xi = np.linalg.solve(J, (x - A).T).T
        inside = (xi >= -1e-12).all(1) & (xi.sum(1) <= 1 + 1e-12) & ~ref.any(1)
        vals = pwlin_shapes("TRI6", xi[inside])
        for k, p in enumerate(A + TRI6.nodes @ J.T):
            hit = np.flatnonzero(np.linalg.norm(nodes - p, axis=1) < 1e-12)
            if len(hit):
                ref[np.flatnonzero(inside), hit[0]] = vals[:, k]
    assert np.max(np.abs(space.evaluate(x) - ref)) < 1e-12
    assert space.breakpoints.cells == 4 * GRID.cells and halved(GRID).cells == 4 * GRID.cells


@pytest.mark.parametrize("alpha", [0.05, 0.2, 1 / 3, 0.45])
def test_transformed_dual_is_biorthogonal_and_sums_to_one(alpha):
    """∫ψ̃_i Ñ_j = δ_ij d̃_j on the reference triangle (ψ̃ = Ã Ñ), Σ ψ̃ = 1."""
    x, w = cell_quadrature("tri", 4)
    N = TRI6.shapes(x)
    Nt = N @ transformation("TRI6", alpha).T
    psi = N @ dual_coefficients("TRI6", transformed=True, alpha=alpha).T
    assert np.max(np.abs(psi.T @ (w[:, None] * Nt) - np.diag(weights("TRI6", alpha)))) < 1e-14
    assert np.max(np.abs(psi.sum(1) - 1.0)) < 1e-13


@pytest.mark.parametrize("alpha", [0.0, 0.1, 0.2, 0.4, 0.49])
def test_transformation_keeps_the_span(alpha):
    """det T = (1 − 2α)^(edge nodes) ≠ 0 for α < 1/2: span Ñ = span N = P2; α = 1/2 is refused."""
    T = transformation("TRI6", alpha)
    assert np.linalg.det(T) == pytest.approx((1 - 2 * alpha) ** len(TRI6.edges), rel=1e-12)
    x = RNG.random((40, 2)) * 0.5
    assert np.linalg.matrix_rank(np.hstack([TRI6.shapes(x), TRI6.shapes(x) @ T.T]), tol=1e-10) == 6
    with pytest.raises(InputError) as err:
        transformation("TRI6", 0.5)
    assert err.value.key == "alpha"


def test_the_tri6_entries_are_face_only_and_triangle_only():
    assert set(TRI6_IDS) >= {"DUAL-T6", "TDUAL-T6", "PWLIN-T6"}
    for case in TRI6_IDS:
        spec = registry.SPACES[case]
        assert spec.min_k == 2 and spec.degree(2) == 2 and not spec.defined_on(1)
        for gamma, part in ((SQUARE, GRID), (SEGMENT, np.linspace(0, 1, 4))):
            with pytest.raises(InputError) as err:
                registry.case_space(case, 2, part, gamma)
            assert err.value.key == "case" and case in str(err.value) and "\n" not in str(err.value)


def test_plain_tri6_dual_is_refused_naming_the_weight_and_the_remedy():
    with pytest.raises(InputError) as err:
        registry.case_space("DUAL-T6", 2, GRID, SQUARE_TRIG)
    text = str(err.value)
    assert err.value.key == "case" and "\n" not in text
    assert "TRI6" in text and "∫N = 0" in text and "TDUAL-T6" in text
    # the reason, computed: the vertex weights are 0 to the refusal's own threshold (their digits,
    # 0 or 1e-18, are the CPU's round-off of a quadrature sum), the transformed ones are not
    zero = ZERO_WEIGHT_RTOL * TRI6.area
    assert abs(min(weights("TRI6"))) <= zero < min(weights("TRI6", 0.2))


@pytest.mark.parametrize("case", ["TDUAL-T6", "PWLIN-T6"])
def test_dimension_count_and_constants(case):
    spec = registry.SPACES[case]
    for n in (1, 2, 3):
        assert registry.space_dim(case, 2, n) == spec.dimension(2, n) == SQUARE_TRIG.trace_dimension(2, n)
        assert spec.structural_kernel(2, n) == 0
    assert spec.contains_constants(2) == ("dual" in spec.definition)          # the dual keeps 1; pwlin vanishes on ∂Γ


def test_dual_at_k2_on_triangles_is_the_transformed_tri6_dual():
    a = registry.case_space("DUAL", 2, GRID, SQUARE_TRIG)
    b = registry.case_space("TDUAL-T6", 2, GRID, SQUARE_TRIG)
    x = np.column_stack([RNG.random(300), RNG.random(300)])
    assert a.dim == b.dim and np.array_equal(a.evaluate(x), b.evaluate(x))


def test_beta_h_is_bounded_in_n_on_tetrahedra(monkeypatch):
    """k = 2 tets, matching N = 4, 6, 8: no kernel and β_H(8)/β_H(4) ≥ 0.9 for TDUAL-T6 and PWLIN-T6,
    while the L² β of the same spaces falls by about √(4/8) (Remark 3.1), a check that N matters.
    The H Grams to rtol 1e-4 (a ratio test does not need the default 1e-6: 4 s instead of 22 s at N = 8)."""
    from functools import partial

    from infsup_contact.discretization.face.norms import triangles as face_triangle_norms
    from infsup_contact.models import make_model
    from infsup_contact.solvers.side_cache import SideCache
    from infsup_contact.solvers.infsup import beta_rows_all

    monkeypatch.setattr(face_triangle_norms, "gram_h_tri", partial(face_triangle_norms.gram_h_tri, rtol=1e-4))
    model, cache, rows = make_model("membranes3d"), SideCache(), []
    for n in (4, 6, 8):
        rows += beta_rows_all("structured", 2, n, n, ["TDUAL-T6", "PWLIN-T6"], norms=("H", "L2"), model=model,
                              side_cache=cache, mesh=MeshOptions(element="tet"))
    frame = pd.DataFrame(rows)
    assert (frame.kernel_dim == 0).all() and (frame.kernel_decision == "clear").all()
    for (case, norm), r in frame.groupby(["case", "norm"]):
        beta = r.set_index("N2").beta
        if norm == "H":
            assert beta[8] / beta[4] >= 0.9 and beta.min() > 0, case
        else:
            assert beta[8] / beta[4] == pytest.approx(np.sqrt(4 / 8), rel=0.2), case


def test_alpha_sweep_runs_tri6_on_tetrahedra():
    """The TRI6 sweep picks the model's element whose faces are triangles (asked of the faces, not
    named) and reports the exact smallest weight fraction min(2α/3, (1 − 2α)/3) of the area."""
    from infsup_contact.study.face.alpha import element_of, sweep

    assert SQUARE_TRIG.cell == "trig" and element_of("membranes3d", "TRI6") != element_of("membranes3d", "QUAD9")
    alphas = (Fraction(1, 10), Fraction(1, 4), Fraction(2, 5))
    rows = pd.DataFrame(sweep(ns=(2,), alphas=tuple(float(a) for a in alphas), elements=("TRI6",)))
    exact = [min(2 * a / 3, (1 - 2 * a) / 3) for a in alphas]
    assert np.allclose(rows.min_weight, [float(e) for e in exact], rtol=1e-14, atol=0)
    assert not rows.refused.any() and (rows.kernel_dim == 0).all() and (rows.beta > 0).all()
    assert (rows.dim_M == rows.dim_W).all()


def test_patch_test_passes_iff_the_space_holds_the_constants():
    """The 3D patch test (study/face_patch.py) on non-matching tetrahedra 3:4, k = 2: TDUAL-T6 keeps the
    constants and reproduces the uniform pressure; PWLIN-T6 vanishes on ∂Γ and does not, as predicted."""
    from infsup_contact.study.patch import face as face_patch

    rows = face_patch.face_patch_rows(["TDUAL-T6", "PWLIN-T6"], [2], [(3, 4)], element="tet")
    assert len(rows) == 2
    for r in rows:
        assert r["passes"] == r["predicted"] == registry.SPACES[r["case"]].contains_constants(2), r["case"]
