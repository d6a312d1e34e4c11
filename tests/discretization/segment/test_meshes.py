"""Mesh families: geometry, boundary names, conventions and reproducibility."""
import ngsolve
import numpy as np
import pytest

from infsup_contact.errors import InputError
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.discretization.segment.meshes import FAMILIES, mesh_pair, mesh_quality, multiplier_breakpoints

gamma_breakpoints = SEGMENT.partition_of


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("n1,n2", [(4, 4), (5, 3)])
def test_areas_boundaries_and_gamma(family, n1, n2):
    for n, mesh, y0 in zip((n1, n2), mesh_pair(family, n1, n2), (0.0, 1.0)):
        assert set(mesh.GetBoundaries()) == {"gamma", "dir"}
        assert ngsolve.Integrate(1, mesh) == pytest.approx(1.0, abs=1e-12)
        assert ngsolve.Integrate(1, mesh, definedon=mesh.Boundaries("gamma")) == pytest.approx(1.0, abs=1e-12)
        assert ngsolve.Integrate(1, mesh, definedon=mesh.Boundaries("dir")) == pytest.approx(3.0, abs=1e-12)
        assert ngsolve.Integrate(ngsolve.y, mesh) == pytest.approx(y0 + 0.5, abs=1e-12)
        x = gamma_breakpoints(mesh)
        assert len(x) == n + 1 and x[0] == 0.0 and x[-1] == 1.0


def test_structured_diagonal_convention_and_quality():
    """Each square split lower-left → upper-right: every triangle has a (1,1)-direction edge."""
    mesh, _ = mesh_pair("structured", 3, 3)
    pts = np.array([v.point for v in mesh.vertices])
    for el in mesh.Elements(ngsolve.VOL):
        p = pts[[v.nr for v in el.vertices]]
        d = [p[j] - p[i] for i, j in ((0, 1), (1, 2), (0, 2))]
        assert any(abs(v[0] - v[1]) < 1e-12 and abs(v[0]) > 0 for v in d)
    q = mesh_quality(mesh)
    assert q["n_elements"] == 2 * 9 and q["min_angle"] == pytest.approx(45) and q["max_angle"] == pytest.approx(90)


def test_perturbed_matching_gamma_and_seeds():
    m1, m2 = mesh_pair("perturbed", 7, 7)
    np.testing.assert_array_equal(gamma_breakpoints(m1), gamma_breakpoints(m2))
    again = mesh_pair("perturbed", 7, 7)[0]
    other = mesh_pair("perturbed", 7, 7, seed=1)[0]
    pts = lambda m: np.array([v.point for v in m.vertices])
    np.testing.assert_array_equal(pts(m1), pts(again))
    assert not np.allclose(pts(m1), pts(other))
    assert mesh_quality(m1)["min_angle"] > 10


def test_unstructured_is_reproducible():
    a, b = mesh_pair("unstructured", 6, 6)[0], mesh_pair("unstructured", 6, 6)[0]
    np.testing.assert_array_equal([v.point for v in a.vertices], [v.point for v in b.vertices])


def test_multiplier_partitions():
    m1, m2 = mesh_pair("structured", 6, 4)
    assert len(multiplier_breakpoints(m1, m2, "omega2")) == 5
    assert len(multiplier_breakpoints(m1, m2, "omega1")) == 7
    assert len(multiplier_breakpoints(m1, m2, "union")) == 9  # {i/6} ∪ {j/4}
    with pytest.raises(InputError):
        multiplier_breakpoints(m1, m2, "omega3")


@pytest.mark.parametrize("family,n", [("hexagonal", 4), ("structured", 0), ("structured", -2)])
def test_bad_mesh_input(family, n):
    with pytest.raises(InputError):
        mesh_pair(family, n, 4)
