"""b(v, μ) = ∫_Γ (v2 − v1) μ: exactness and agreement with NGSolve's own assembly."""
import ngsolve
import numpy as np
import pytest

from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.models.membranes import displacement_space
from infsup_contact.discretization.segment.meshes import mesh_pair
from infsup_contact.discretization.segment.multipliers import make_space


def _gauss_reference(space, f, n=40):
    """∫ μ_j f on each interval by dense Gauss (independent of the union partition)."""
    t, w = np.polynomial.legendre.leggauss(n)
    x = space.breakpoints
    out = np.zeros(space.dim)
    for a, b in zip(x[:-1], x[1:]):
        xq = 0.5 * (a + b) + 0.5 * (b - a) * t
        out += space.evaluate(xq).T @ (0.5 * (b - a) * w * f(xq))
    return out


@pytest.mark.parametrize("family,n1,n2", [("structured", 4, 4), ("perturbed", 5, 3), ("unstructured", 6, 4)])
@pytest.mark.parametrize("k,s,cont", [(1, 0, False), (2, 1, True), (3, 2, False), (2, 2, True)])
def test_b_exact_for_polynomial_traces(family, n1, n2, k, s, cont):
    """A polynomial of degree k vanishing at Γ's ends is in every trace space: B u is exact."""
    for mesh in mesh_pair(family, n1, n2):
        fes = displacement_space(mesh, k)
        trace = SEGMENT.trace(fes)
        p = lambda x: x * (1 - x) * (1 + 2 * x) ** (k - 2) if k >= 2 else 0 * x
        if k == 1:
            continue  # only the zero polynomial vanishes at both ends with degree 1 on all meshes
        gf = ngsolve.GridFunction(fes)
        gf.Set(ngsolve.x * (1 - ngsolve.x) * (1 + 2 * ngsolve.x) ** (k - 2), definedon=mesh.Boundaries("gamma"))
        u = gf.vec.FV().NumPy()[trace.gamma_dofs]
        # a non-matching multiplier partition, so three partitions meet in the union
        space = make_space(np.linspace(0, 1, 8) ** 1.3, s, cont, False)
        B = coupling_matrix(trace, space, k)
        assert np.allclose(B @ u, _gauss_reference(space, p), atol=1e-13, rtol=1e-12)


@pytest.mark.parametrize("k,s", [(1, 1), (2, 1), (2, 2), (3, 2)])
def test_b_matches_ngsolve_assembly(k, s):
    """Matching meshes: our B against NGSolve's mixed form ∫_Γ u q ds on the same partition."""
    for mesh in mesh_pair("perturbed", 5, 5):
        fes = displacement_space(mesh, k)
        trace = SEGMENT.trace(fes)
        Q = ngsolve.H1(mesh, order=s, definedon=mesh.Boundaries("gamma"))
        u, q = fes.TrialFunction(), Q.TestFunction()
        bf = ngsolve.BilinearForm(trialspace=fes, testspace=Q)
        bf += u * q * ngsolve.ds("gamma")
        bf.Assemble()
        rng = np.random.default_rng(k + s)
        ug, qg = ngsolve.GridFunction(fes), ngsolve.GridFunction(Q)
        ug.vec.FV().NumPy()[:] = rng.standard_normal(fes.ndof) * np.array(fes.FreeDofs())
        qg.vec.FV().NumPy()[:] = rng.standard_normal(Q.ndof)
        expected = ngsolve.InnerProduct(qg.vec, bf.mat * ug.vec)
        # the same multiplier in our Lagrange basis: its nodal values on the trace partition
        space = make_space(trace.breakpoints, s, True, False)
        # point evaluation goes through a volume extension (boundary-only spaces evaluate
        # to 0 at volume points); Set on Γ reproduces the trace exactly (same P_s space)
        ext = ngsolve.GridFunction(ngsolve.H1(mesh, order=s))
        ext.Set(qg, ngsolve.BND, definedon=mesh.Boundaries("gamma"))
        c = np.array([ext(mesh(xn, 1.0)) for xn in space.nodes()])
        ours = c @ coupling_matrix(trace, space, k) @ ug.vec.FV().NumPy()[trace.gamma_dofs]
        assert ours == pytest.approx(expected, rel=1e-11, abs=1e-13)


def test_cached_trace_values_match_a_fresh_evaluation():
    """B from the trace's cached basis values equals B from a fresh trace, for several spaces
    asked for in turn (same and different quadrature points)."""
    mesh = mesh_pair("perturbed", 7, 5)[0]
    cached = SEGMENT.trace(displacement_space(mesh, 3))
    for s, cont, bp in [(3, True, np.linspace(0, 1, 6)), (2, False, np.linspace(0, 1, 6)),
                        (3, True, np.linspace(0, 1, 6)), (1, True, np.linspace(0, 1, 9) ** 1.2)]:
        space = make_space(bp, s, cont, False)
        fresh = SEGMENT.trace(displacement_space(mesh, 3))
        assert np.array_equal(coupling_matrix(cached, space, 3), coupling_matrix(fresh, space, 3))
