"""The curved bodies against an independent isoparametric discretization (tests/helpers/arc_reference.py):
the stiffness on curved cells is integrated until more quadrature changes nothing, each side's S_i is the
reference's, the arc's β_h rows are the reference's, and the projection coupling is the documented
mortar integral computed by adaptive quadrature (issue 51, item 6)."""
from __future__ import annotations

import numpy as np
import ngsolve
import pandas as pd
import pytest

from helpers import arc_reference as ar

import infsup_contact.models.membranes as membranes
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.spaces import registry
from infsup_contact.models import MODELS
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.request import resolve_gamma
from infsup_contact.solvers.side_cache import SideCache

MEMBRANES, MEMBRANES3D = MODELS["membranes"], MODELS["membranes3d"]


def arc(radius=2.0, coupling="exact"):
    """The request's Γ: the arc (an Interface, not a mesh option)."""
    return resolve_gamma(MEMBRANES, gamma="arc", radius=float(radius), coupling=coupling)


def curved_space(model, n, k, **options):
    body = model.subdomain_mesh("structured", n, 2, **options)
    body.interface.curve(body.mesh, k)
    return ngsolve.H1(body.mesh, order=k)


def stiffness_with_margin(fes, margin, monkeypatch):
    monkeypatch.setattr(membranes, "CURVED_MARGIN", margin)
    return membranes.laplace_stiffness(fes)


@pytest.mark.parametrize("model,k,options", [
    (MEMBRANES, 2, dict(gamma=arc())), (MEMBRANES, 3, dict(gamma=arc())),
    (MEMBRANES3D, 1, dict(element="hex", gamma=resolve_gamma(MEMBRANES3D, element="hex", gamma="cylinder", radius=2.0))),
    (MEMBRANES3D, 2, dict(element="tet", gamma=resolve_gamma(MEMBRANES3D, element="tet", gamma="cylinder", radius=2.0)))])
def test_curved_stiffness_is_converged_in_its_quadrature(model, k, options, monkeypatch):
    """The integrand on a curved cell is rational, no rule is exact: the Gauss error falls
    geometrically with the order, so K at the library's order, 4 and 8 orders more agree to round-off
    (1e-12 relative: ~100 ulps of the entries' sums), while NGSolve's default order is 1e-6..1e-4 off."""
    fes = curved_space(model, 3, k, **options)
    K = membranes.laplace_stiffness(fes)
    scale = abs(K).max()
    base = membranes.CURVED_MARGIN
    for more in (4, 8):
        assert abs(stiffness_with_margin(fes, base + more, monkeypatch) - K).max() <= 1e-12 * scale
    monkeypatch.setattr(membranes, "curved_bonus_intorder", lambda mesh, k: 0)
    assert abs(membranes.laplace_stiffness(fes) - K).max() > 1e-7 * scale  # the fault this guards


def test_arc_beta_is_unchanged_by_finer_quadrature(monkeypatch):
    """β_h at the library's quadrature, 4 and 8 orders more: equal to 1e-9 relative (the β rows follow
    S_i continuously, and S_i is converged to round-off: previous test); NGSolve's default order moved
    T3's β_H by 2.5e-3 at 16:17 and moves it by > 1e-4 here."""
    def betas(margin=None, default=False):
        with monkeypatch.context() as m:
            if margin is not None:
                m.setattr(membranes, "CURVED_MARGIN", margin)
            if default:
                m.setattr(membranes, "curved_bonus_intorder", lambda mesh, k: 0)
            return pd.DataFrame(beta_rows("structured", 2, 8, 9, cases=["T3", "R5.2", "T5"], model=MEMBRANES,
                                          gamma=arc())).beta.to_numpy()
    beta = betas()
    for more in (4, 8):
        assert np.abs(betas(membranes.CURVED_MARGIN + more) - beta).max() <= 1e-9 * beta.max()
    assert np.abs(betas(default=True) - beta).max() > 1e-4 * beta.max()


@pytest.mark.parametrize("k", [1, 2, 3])
def test_each_curved_side_is_the_reference_isoparametric_body(k):
    """S_i of both sides equals the reference's (its own element maps, nodes and quadrature; the
    documented interpolant of Φ) to 1e-12 relative: the same discrete problem, each to round-off. The
    reference's own quadrature is converged (8 and 14 Gauss points per direction agree)."""
    sides = SideCache().pair(MEMBRANES, "structured", k, 4, 5, gamma=arc())
    for side, n, which in zip(sides, (4, 5), (1, 2)):
        square = MEMBRANES.subdomain_mesh("structured", n, which, gamma=arc()).mesh
        body = ar.Body(*ar.library_square(square), 2.0, k)
        reference = ar.reference_schur(side, body)
        scale = np.abs(reference).max()
        assert np.abs(ar.reference_schur(side, body, points=8) - reference).max() <= 1e-12 * scale
        assert np.abs(side.schur - reference).max() <= 1e-12 * scale


@pytest.mark.parametrize("k,n1,n2,coupling", [(1, 4, 5, "exact"), (2, 4, 5, "exact"), (2, 8, 9, "exact"),
                                              (2, 8, 9, "projection")])
def test_arc_rows_agree_with_the_exactly_integrated_reference(k, n1, n2, coupling):
    """Every segment space, both norms: β_h with the library's sides and with the reference's S_i in
    the same pencil (the coupling the library's: the projection's is checked below) agree to 1e-9
    (the issue's acceptance: 1e-6), and so do the kernels."""
    gamma = arc(coupling=coupling)
    library = pd.DataFrame(beta_rows("structured", k, n1, n2, model=MEMBRANES, gamma=gamma))
    sides = ar.reference_sides(MEMBRANES, "structured", k, n1, n2, gamma)
    reference = pd.DataFrame(beta_rows("structured", k, n1, n2, model=MEMBRANES, gamma=gamma,
                                       side_cache=ar.reference_cache(sides)))
    assert (library.kernel_dim == reference.kernel_dim).all()
    assert np.abs(library.beta - reference.beta).max() <= 1e-9


@pytest.mark.parametrize("k,n1,n2,choice", [(1, 4, 5, "omega2"), (2, 4, 5, "omega2"), (2, 4, 5, "omega1"),
                                            (2, 5, 8, "union")])
def test_projection_coupling_is_the_adaptively_integrated_mortar_integral(k, n1, n2, choice):
    """B_i of the projection coupling (slave and master) against the documented integral computed
    independently — the reference's curves and averaged normals, the projection a bracketed root,
    adaptive Gauss–Kronrod on the pieces — entrywise to 1e-12 of max |B| (the library's rule is
    documented accurate to 1e-13)."""
    arc_15 = arc(1.5, "projection")
    sides = SideCache().pair(MEMBRANES, "structured", k, n1, n2, gamma=arc_15)
    bodies = [ar.Body(*ar.library_square(MEMBRANES.subdomain_mesh("structured", n, w, gamma=arc_15).mesh),
                      1.5, k) for n, w in ((n1, 1), (n2, 2))]
    curves = [ar.Curve(b) for b in bodies]
    gamma = sides[0].trace.gamma
    g_h = gamma.multiplier_partition(*(s.trace.partition for s in sides), choice)
    space = registry.case_space("T3", k, g_h, gamma)
    slave = gamma.slave_of(g_h)
    B_slave, B_master = ar.projection_coupling(curves[slave], curves[1 - slave],
                                               lambda x: space.evaluate(np.array([x]))[0], g_h)
    for i, nodal in ((slave, B_slave), (1 - slave, B_master)):
        T = np.asarray(gamma.trace_basis(sides[i].trace, bodies[i].gamma_abscissae()))  # nodal values of the Γ dofs
        B = coupling_matrix(sides[i].trace, space, k)
        assert np.abs(B - nodal @ T).max() <= 1e-12 * np.abs(B).max()
