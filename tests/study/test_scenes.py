"""Mathematical checks of the load scenes (no stored numbers).

Every hand-derived quantity of the manufactured solution is compared against NGSolve's
symbolic differentiation (``CoefficientFunction.Diff``), and the contact conditions of
(3.12) with the sign-corrected (3.13), λ = −c_i ∂u_i/∂y on Γ, are checked pointwise.
"""
import math

import numpy as np
import pytest
import ngsolve
from ngsolve import x, y
from netgen.geom2d import SplineGeometry, unit_square

from infsup_contact.errors import InputError
from infsup_contact.study.contact.scenes import (ManufacturedSolution, MembraneScene, manufactured,
                                   membranes, scene)

VARIANTS = {
    "smooth": dict(p=3.0, q=3.0),
    "smooth-c": dict(p=3.0, q=3.0, c1=2.0, c2=0.5),
    "lowreg": dict(p=1.75, q=1.75),
    "lowreg-c": dict(p=1.75, q=1.75, c1=0.3, c2=4.0),
}
XS = np.linspace(0.0, 1.0, 201)  # includes x = 0, 1; never hits a = 1/√5 exactly
# Interior points avoiding the kink x = a: at x = a, λ'' is singular for p < 2.
XI = np.linspace(0.003, 0.997, 157)


@pytest.fixture(scope="module")
def meshes():
    """Fine meshes of Ω1 and Ω2 (Ω2 in global coordinates 1 < y < 2)."""
    m1 = ngsolve.Mesh(unit_square.GenerateMesh(maxh=0.05))
    geo = SplineGeometry()
    geo.AddRectangle((0, 1), (1, 2))
    m2 = ngsolve.Mesh(geo.GenerateMesh(maxh=0.05))
    return m1, m2


@pytest.fixture(scope="module", params=list(VARIANTS))
def sol(request):
    return manufactured(**VARIANTS[request.param])


def _l2_rel(cf_a, cf_b, mesh):
    """Relative L2 distance of two scalar (or vector) CFs on ``mesh``."""
    d = cf_a - cf_b
    num = ngsolve.Integrate(ngsolve.InnerProduct(d, d), mesh, order=10)
    den = ngsolve.Integrate(ngsolve.InnerProduct(cf_a, cf_a), mesh, order=10)
    return math.sqrt(abs(num) / max(den, 1e-300))


def _pt(cf, mesh, px, py):
    return cf(mesh(px, py))


def _sym_grad(u):
    return ngsolve.CoefficientFunction((u.Diff(x), u.Diff(y)))


def _sym_minus_c_lap(u, c):
    return -c * (u.Diff(x).Diff(x) + u.Diff(y).Diff(y))


def test_type(sol):
    assert isinstance(sol, ManufacturedSolution) and sol.has_exact
    assert sol.contact_set == (0.0, sol.a)
    assert sol.grad_u1.dim == 2 and sol.grad_u2.dim == 2


def test_gradients_match_symbolic_diff(sol, meshes):
    for u, grad, mesh in ((sol.u1, sol.grad_u1, meshes[0]), (sol.u2, sol.grad_u2, meshes[1])):
        assert _l2_rel(grad, _sym_grad(u), mesh) < 1e-12


def test_loads_are_minus_c_laplacian(sol, meshes):
    for u, f, c, mesh in ((sol.u1, sol.f1, sol.c1, meshes[0]),
                          (sol.u2, sol.f2, sol.c2, meshes[1])):
        assert _l2_rel(f, _sym_minus_c_lap(u, c), mesh) < 1e-10


def test_loads_are_not_trivially_zero(sol, meshes):
    # Guards the Diff comparison against comparing 0 with 0.
    for f, mesh in ((sol.f1, meshes[0]), (sol.f2, meshes[1])):
        assert ngsolve.Integrate(f * f, mesh, order=10) > 1.0


def test_dirichlet_boundaries(sol, meshes):
    m1, m2 = meshes
    for s in XS:
        # ∂Ω1∖Γ: y = 0, x = 0, x = 1 ; ∂Ω2∖Γ: y = 2, x = 0, x = 1.
        for px, py in ((s, 0.0), (0.0, s), (1.0, s)):
            assert abs(_pt(sol.u1, m1, px, py)) < 1e-13
        for px, py in ((s, 2.0), (0.0, 1 + s), (1.0, 1 + s)):
            assert abs(_pt(sol.u2, m2, px, py)) < 1e-13


def test_gamma_gap_and_multiplier(sol, meshes):
    m1, m2 = meshes
    lam, gap = sol.lam(XS), sol.gap(XS)
    for i, s in enumerate(XS):
        u1, u2 = _pt(sol.u1, m1, s, 1.0), _pt(sol.u2, m2, s, 1.0)
        assert abs((u2 - u1) - gap[i]) < 1e-13
        # y-component explicitly: λ = −c_i ∂_y u_i on Γ (sign-corrected (3.13)).
        dy1 = _pt(sol.grad_u1[1], m1, s, 1.0)
        dy2 = _pt(sol.grad_u2[1], m2, s, 1.0)
        assert abs(-sol.c1 * dy1 - lam[i]) < 1e-13
        assert abs(-sol.c2 * dy2 - lam[i]) < 1e-13
        # and the symbolic derivative agrees (not just the hand-derived gradient)
        assert abs(-sol.c1 * _pt(sol.u1.Diff(y), m1, s, 1.0) - lam[i]) < 1e-13


def test_gamma_complementarity(sol):
    lam, gap = sol.lam(XS), sol.gap(XS)
    assert np.all(lam >= 0) and np.all(gap >= 0)
    assert np.max(np.abs(lam * gap)) == 0.0
    inside = XI < sol.a
    assert np.all(sol.lam(XI[inside]) > 0) and np.all(sol.gap(XI[inside]) == 0)
    assert np.all(sol.gap(XI[~inside]) > 0) and np.all(sol.lam(XI[~inside]) == 0)


def test_numpy_gamma_data_match_cf_traces(sol, meshes):
    # lam(x), gap(x) are the traces of the CF fields, checked at interior points.
    m1, m2 = meshes
    for s in XI:
        assert abs(_pt(sol.u2, m2, s, 1.0) - _pt(sol.u1, m1, s, 1.0) - sol.gap(s)) < 1e-13


def test_low_regularity_load_is_unbounded_near_a():
    # p = 1.75: λ'' ~ p(p−1) x (a − x)^(−1/4) blows up as x → a⁻ (f stays in L², see the
    # finite integrals above); the smooth variant stays bounded there.  At y = 1/2 the
    # weight ψ1 = y² − y = −1/4, so the singular part drives f1 to −∞.
    m1 = ngsolve.Mesh(unit_square.GenerateMesh(maxh=0.2))
    a = 1 / math.sqrt(5)
    rough, smooth = manufactured(p=1.75, q=1.75), manufactured()
    vals = [_pt(rough.f1, m1, a - d, 0.5) for d in (1e-4, 1e-8, 1e-12)]
    assert vals[0] > vals[1] > vals[2] and vals[2] < -100
    assert abs(_pt(smooth.f1, m1, a - 1e-12, 0.5)) < 20


@pytest.mark.parametrize("kw", [dict(c1=0), dict(c2=-1.0), dict(c1="x"), dict(p=1.5),
                                dict(q=1.2), dict(p=float("nan")), dict(a=0.0),
                                dict(a=1.5), dict(q=None)])
def test_manufactured_bad_input(kw):
    with pytest.raises(InputError):
        manufactured(**kw)


def test_membranes_loads(meshes):
    m1, m2 = meshes
    sc = membranes(c1=2.0, c2=3.0)
    assert isinstance(sc, MembraneScene) and not sc.has_exact
    assert (sc.c1, sc.c2) == (2.0, 3.0)
    for s in XS:
        f0 = 4 * (1 - 2 * s)
        assert abs(_pt(sc.f1, m1, s, 0.5) - f0) < 1e-13
        assert abs(_pt(sc.f2, m2, s, 1.5) + f0) < 1e-13


@pytest.mark.parametrize("f0", [2.5, lambda t: t * t, ngsolve.sin(ngsolve.pi * x)])
def test_membranes_custom_profile(f0, meshes):
    m1, m2 = meshes
    sc = membranes(f0=f0)
    if isinstance(f0, float):
        want = lambda s: 2.5  # noqa: E731
    elif isinstance(f0, ngsolve.CoefficientFunction):
        want = lambda s: math.sin(math.pi * s)  # noqa: E731
    else:
        want = lambda s: s * s  # noqa: E731
    for s in (0.1, 0.5, 0.9):
        assert abs(_pt(sc.f1, m1, s, 0.3) - want(s)) < 1e-13
        assert abs(_pt(sc.f2, m2, s, 1.7) + want(s)) < 1e-13


@pytest.mark.parametrize("kw", [dict(c1=0.0), dict(c2=float("inf")), dict(f0="four"),
                                dict(f0=lambda t: "x"), dict(f0=True)])
def test_membranes_bad_input(kw):
    with pytest.raises(InputError):
        membranes(**kw)


def test_dispatcher():
    assert isinstance(scene("manufactured", p=1.75, q=1.75), ManufacturedSolution)
    assert isinstance(scene("membranes", c1=2.0), MembraneScene)
    with pytest.raises(InputError) as err:
        scene("cantilever")
    assert err.value.key == "scene" and err.value.got == "cantilever"
    assert err.value.allowed == "manufactured, membranes"
    with pytest.raises(InputError):
        scene("membranes", p=3.0)  # parameter of another scene
