"""Serendipity HEX20 bodies (``membranes3d`` with ``element="hex20"``, scikit-fem's ElementHexS2):
dimension counts, the QUAD8 trace against scikit-fem's own evaluation, exactness on P2, the side
operator against the reference Schur route, and against the NGSolve Q2 hexahedra (W_HEX20 ⊂ W_Q2)."""
from types import SimpleNamespace

import numpy as np
import pytest

from infsup_contact.discretization.face.shapes.serendipity import SERENDIPITY
from infsup_contact.errors import InputError
from infsup_contact.models import hex20
from infsup_contact.models.contract import schur_by_solves
from infsup_contact.models.membranes3d import MEMBRANES3D, subdomain_mesh

ROUNDOFF = 1e-11
"""Relative bound of round-off in a stiffness or Schur entry at N ≤ 4 (condition numbers ≤ 1e3)."""


def body(n, side=1):
    return subdomain_mesh("structured", n, side, element="hex20")


@pytest.mark.parametrize("n", [1, 2, 3, 4])
@pytest.mark.parametrize("side", [1, 2])
def test_dimension_counts(n, side):
    b = body(n, side)
    basis, dofs = hex20.displacement_space(b)
    assert basis.N == (n + 1) ** 3 + 3 * n * (n + 1) ** 2                 # vertices + edge midpoints
    # free: the nodes off the five clamped faces (x, y inside, 0 < z <= 1): vertices, x- and y-edge
    # midpoints on the n vertex levels, z-edge midpoints on the n midpoint levels
    assert dofs.free.sum() == (n - 1) ** 2 * n + 2 * n * (n - 1) * n + (n - 1) ** 2 * n
    trace = SERENDIPITY.trace(dofs)
    assert len(trace.gamma_dofs) == (3 * n - 1) * (n - 1) == SERENDIPITY.trace_dimension(2, n)
    on_gamma = np.abs(dofs.points[:, 2] - 1.0) < 1e-12
    assert on_gamma.sum() == 3 * n * n + 4 * n + 1 == SERENDIPITY.trace_nodes(2, n)


def test_the_quad8_trace_is_scikit_fems_function_on_gamma():
    b = body(3)
    basis, dofs = hex20.displacement_space(b)
    trace = SERENDIPITY.trace(dofs)
    rng = np.random.default_rng(5)
    u = np.where(dofs.free, rng.standard_normal(basis.N), 0.0)
    xy = rng.random((200, 2))
    pts = np.column_stack([xy, np.ones(len(xy)) - 1e-14]).T                 # inside Ω1, on Γ to round-off
    exact = basis.probes(pts) @ u
    ours = SERENDIPITY.trace_basis(trace, xy) @ u[trace.gamma_dofs]
    np.testing.assert_allclose(ours, exact, atol=1e-10 * np.abs(exact).max())


def test_the_stiffness_is_exact_on_quadratic_polynomials():
    """P2 ⊂ serendipity Q2: the nodal interpolant of u is u, and uᵀ K u = ∫ |∇u|² (here 1 + 1/3 + 4/3 + ... exact)."""
    basis, dofs = hex20.displacement_space(body(2))
    x, y, z = dofs.points.T
    u = x ** 2 + x * y - z ** 2 + 3 * y * z + x                             # ∇u = (2x + y + 1, x + 3z, −2z + 3y)
    energy = u @ hex20.stiffness(basis) @ u
    # ∫_(0,1)²×(0,1) |∇u|² by the 3-point Gauss rule per direction (exact for degree 2 integrands)
    t = (np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)]) + 1) / 2
    w = np.array([5, 8, 5]) / 18
    X, Y, Z = np.meshgrid(t, t, t, indexing="ij")
    W = np.einsum("i,j,k->ijk", w, w, w)
    exact = np.sum(W * ((2 * X + Y + 1) ** 2 + (X + 3 * Z) ** 2 + (3 * Y - 2 * Z) ** 2))
    assert abs(energy - exact) <= ROUNDOFF * exact


@pytest.mark.parametrize("side", [1, 2])
def test_the_side_operator_is_spd_and_the_schur_complement_of_k(side):
    op = MEMBRANES3D.side_operator(body(3, side), 2)
    S = op.schur
    assert np.abs(S - S.T).max() <= ROUNDOFF * np.abs(S).max()
    assert np.linalg.eigvalsh(0.5 * (S + S.T)).min() > 0
    np.testing.assert_allclose(S, schur_by_solves(op), atol=ROUNDOFF * np.abs(S).max())
    assert list(op.free[-len(op.trace.gamma_dofs):]) == list(op.trace.gamma_dofs)    # Γ dofs last


def test_hex20_energy_is_at_least_q2s_for_the_same_trace():
    """HEX20 ⊂ Q2 in the body and QUAD8 ⊂ Q2 on Γ, so for a trace g of both spaces the discrete
    harmonic extension of HEX20 minimizes over fewer functions: gᵀ S_HEX20 g ≥ cᵀ S_Q2 c (c = g in the
    Q2 trace basis), for any g; for a smooth g (the interpolant of sin πx sin πy) both approximate
    the same Steklov energy, and their gap shrinks under refinement."""
    rng = np.random.default_rng(11)
    gaps = []
    for n in (2, 4):
        s20 = MEMBRANES3D.side_operator(body(n), 2)
        sq2 = MEMBRANES3D.side_operator(subdomain_mesh("structured", n, 1, element="hex"), 2)
        xy = rng.random((4 * len(sq2.trace.gamma_dofs), 2))
        phi20 = s20.trace.gamma.trace_basis(s20.trace, xy)
        phiq2 = sq2.trace.gamma.trace_basis(sq2.trace, xy)
        nodes = s20.trace.fes.points[s20.trace.gamma_dofs]
        smooth = np.sin(np.pi * nodes[:, 0]) * np.sin(np.pi * nodes[:, 1])
        for g in [smooth] + [rng.standard_normal(phi20.shape[1]) for _ in range(4)]:
            c, *_ = np.linalg.lstsq(phiq2, phi20 @ g, rcond=None)
            assert np.abs(phiq2 @ c - phi20 @ g).max() <= 1e-10 * np.abs(phi20 @ g).max()   # g ∈ W_Q2
            e20, eq2 = g @ s20.schur @ g, c @ sq2.schur @ c
            assert eq2 <= e20 * (1 + ROUNDOFF)
        c, *_ = np.linalg.lstsq(phiq2, phi20 @ smooth, rcond=None)
        gaps.append(smooth @ s20.schur @ smooth / (c @ sq2.schur @ c) - 1)
    assert gaps[1] < gaps[0] / 2 and gaps[1] < 0.05, gaps


@pytest.mark.parametrize("k", [1, 3])
def test_other_degrees_are_refused_naming_k(k):
    with pytest.raises(InputError, match=r"invalid k \(got %d\): expected 2" % k):
        MEMBRANES3D.side_operator(body(2), k)


def test_hex20_meshes_are_structured_and_refuse_supports_they_do_not_have():
    with pytest.raises(InputError, match="family"):
        subdomain_mesh("perturbed", 2, 1, element="hex20")
    with pytest.raises(InputError, match="element"):  # rollers on the lateral faces only: not a HEX20 scene
        MEMBRANES3D.scene_side(SimpleNamespace(supports="side"), body(2), 2)
