"""Γ a part of a cylinder (``membranes3d --gamma cylinder``): the flat face at R = inf, the
isoparametric bodies' geometric convergence, the product structure of the discrete surfaces, the
projection coupling against the exact one, kernel counts, and one-line refusals."""
import math
from types import SimpleNamespace

import ngsolve
import numpy as np
import pytest

from infsup_contact.cli import main as cli_main
from infsup_contact.discretization.face.shapes.cylinder import Cylinder
from infsup_contact.discretization.face.shapes.cylinder_projection import ProjectedCylinder, face_curve
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.spaces import registry
from infsup_contact.errors import InputError
from infsup_contact.models.membranes3d import MEMBRANES3D, subdomain_mesh
from infsup_contact.contact.contact import check_flat_gamma
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.request import MeshOptions, options_of
from infsup_contact.solvers.side_cache import SideCache

ROUNDOFF = 1e-12
"""Relative bound of round-off in β_h and in B's entries on these small pairs (N ≤ 5)."""
FLAT = MeshOptions(element="hex")


def Flags(gamma=None, radius=None, coupling=None):
    """The contact command's curving flags as parsed."""
    return SimpleNamespace(gamma=gamma, radius=radius, coupling=coupling)


def cylinder(radius, coupling="exact", element="hex"):
    """(mesh options, Γ) of a request on the cylinder: Γ the request's own, not a mesh option."""
    return options_of(MEMBRANES3D, element=element, gamma="cylinder", radius=float(radius), coupling=coupling)


def rows(k, n1, n2, where, cases=None):
    """``where``: the flat face's mesh options, or (mesh options, Γ) of :func:`cylinder`."""
    mesh, gamma = where if isinstance(where, tuple) else (where, None)
    return beta_rows("structured", k, n1, n2, cases, model=MEMBRANES3D, mesh=mesh, gamma=gamma)


def slope(ns, errors) -> float:
    """The rate p of errors ~ h^p, h = 1/N (least squares in log-log)."""
    return float(np.polyfit(np.log(1.0 / np.asarray(ns, float)), np.log(np.abs(errors)), 1)[0])


# ------------------------------------------------------------------ R = inf: the flat face
@pytest.mark.parametrize("k, n1, n2, element, cases", [(1, 3, 4, "hex", None), (2, 2, 3, "hex", None),
                                                       (1, 3, 4, "tet", ["T3", "R5.2"])])
def test_exact_coupling_at_radius_inf_is_the_flat_face_bit_for_bit(k, n1, n2, element, cases):
    flat = rows(k, n1, n2, MeshOptions(element=element), cases)
    curved = rows(k, n1, n2, cylinder(math.inf, element=element), cases)
    assert [r["case"] for r in flat] == [r["case"] for r in curved]
    for a, b in zip(flat, curved):
        assert (a["beta"], a["kernel_dim"], a["smallest_nonzero"]) == (b["beta"], b["kernel_dim"], b["smallest_nonzero"])


def test_projection_on_the_flat_face_is_the_identity():
    """Flat curves, normals e_z: P(x) = x, so β_h and the kernels are the flat face's to round-off."""
    sides = SideCache().pair(MEMBRANES3D, "structured", 2, 3, 4, *cylinder(math.inf, "projection"))
    g = sides[0].trace.gamma
    space = registry.case_space("T3", 2, sides[1].trace.partition, g)
    x, x_master, w = g.coupling_points(sides[0].trace, space, 4)  # Ω1 is the master of G_h = Ω2's trace
    assert isinstance(g, ProjectedCylinder) and np.abs(x_master - x).max() <= 4 * np.finfo(float).eps
    flat, projected = rows(2, 3, 4, FLAT), rows(2, 3, 4, cylinder(math.inf, "projection"))
    for a, b in zip(flat, projected):
        assert a["kernel_dim"] == b["kernel_dim"]
        assert abs(a["beta"] - b["beta"]) <= ROUNDOFF * max(a["smallest_nonzero"], 1.0), a["case"]


# ------------------------------------------------------------------ the curved bodies
def curved_body(n, side, k, radius=2.0):
    body = subdomain_mesh("structured", n, side, element="hex", gamma=MEMBRANES3D.gamma(gamma="cylinder", radius=radius))
    MEMBRANES3D.side_operator(body, k)  # curves the mesh at the body's degree
    return body


def measures(body, k):
    order = 2 * k + 4
    volume = ngsolve.Integrate(ngsolve.CF(1.0), body.mesh, order=order)
    area = ngsolve.Integrate(ngsolve.CF(1.0), body.mesh, definedon=body.mesh.Boundaries("gamma"), order=order)
    return volume, area


@pytest.mark.parametrize("k", [1, 2])
@pytest.mark.parametrize("side", [1, 2])
def test_volume_and_area_converge_at_the_interpolants_rate(k, side):
    """Φ interpolated in Q_k: the volume and Γ's area (exactly (2R ∓ 1)/(2R) and 1) converge as h^{2k}."""
    R, ns = 2.0, (2, 4, 8)
    exact = (2 * R - 1) / (2 * R) if side == 1 else (2 * R + 1) / (2 * R)
    volume, area = zip(*(measures(curved_body(n, side, k, R), k) for n in ns))
    assert slope(ns, np.array(volume) - exact) >= 2 * k - 0.1
    assert slope(ns, np.array(area) - 1.0) >= 2 * k - 0.1


def test_curving_again_starts_from_the_box():
    body = curved_body(3, 1, 1)
    MEMBRANES3D.side_operator(body, 2)
    assert measures(body, 2) == measures(curved_body(3, 1, 2), 2)


@pytest.mark.parametrize("k", [1, 2])
def test_the_discrete_face_is_a_curve_in_x_times_a_line_in_y(k):
    """Every row of face elements gives the same x-curve, its vertices on the cylinder r = R."""
    R, n = 2.0, 3
    body = curved_body(n, 2, k, R)
    trace = MEMBRANES3D.side_operator(body, k).trace
    curve = face_curve(trace, k)
    xs = np.asarray(trace.partition.xs)
    p, _ = curve.point(xs)
    np.testing.assert_allclose(p, np.column_stack([R * np.sin(xs / R), R * np.cos(xs / R) - R + 1]), atol=1e-14)
    mesh = trace.fes.mesh
    x = np.linspace(0.0, 1.0, 13)
    for verts, _, el in trace.elements:  # every element, at points of its own x-interval
        lo, hi = verts.min(axis=0), verts.max(axis=0)
        pts = np.column_stack([x * (hi[0] - lo[0]) + lo[0], np.full(len(x), 0.3 * lo[1] + 0.7 * hi[1])])
        ref = trace.gamma._reference(verts, pts)
        trafo = mesh.GetTrafo(el)  # kept: a mapped point refers to its transformation
        mapped = np.array([np.asarray(trafo(a, b).point) for a, b in ref])
        np.testing.assert_allclose(mapped[:, [0, 2]], curve.point(pts[:, 0])[0], atol=1e-14)
        np.testing.assert_allclose(mapped[:, 1], pts[:, 1], atol=1e-14)


# ------------------------------------------------------------------ projection against exact
@pytest.mark.parametrize("k", [1, 2])
def test_projection_on_matching_meshes_is_exact_up_to_the_geometric_error(k):
    """Matching meshes: the same surface, P = id; B differs from the exact one only by the
    surface Jacobian |p'| − 1 of the discrete surface, O(h^{max(k, 2)}) (k = 1: the chords)."""
    errors, ns = [], (2, 4, 8)
    for n in ns:
        B = {}
        for coupling in ("exact", "projection"):
            sides = SideCache().pair(MEMBRANES3D, "structured", k, n, n, *cylinder(2.0, coupling))
            g = sides[0].trace.gamma
            space = registry.case_space("T3", k, sides[1].trace.partition, g)
            B[coupling] = [coupling_matrix(s.trace, space, k) for s in sides]
            if coupling == "projection":
                x, x_master, _ = g.coupling_points(sides[0].trace, space, k + space.degree)
                assert np.abs(x_master - x).max() <= 4 * np.finfo(float).eps
        errors.append(max(np.abs(p - e).max() / np.abs(e).max() for p, e in zip(B["projection"], B["exact"])))
    assert errors[-1] < errors[0] and slope(ns, errors) >= max(k, 2) - 0.15


@pytest.mark.parametrize("coupling, element", [("exact", "hex"), ("projection", "hex"), ("exact", "tet")])
@pytest.mark.parametrize("k", [1, 2])
def test_kernel_counts_on_matching_meshes_are_the_flat_ones(k, coupling, element):
    cases = ["T3", "R5.2"]
    flat = {(r["case"], r["norm"]): r["kernel_dim"] for r in rows(k, 4, 4, MeshOptions(element=element), cases)}
    curved = {(r["case"], r["norm"]): r["kernel_dim"]
              for r in rows(k, 4, 4, cylinder(2.0, coupling, element), cases)}
    assert curved == flat
    assert flat[("R5.2", "H")] > 0 == flat[("T3", "H")]  # the counts compared are the spurious modes and none


@pytest.mark.parametrize("radius", [8.0, 2.0, 1.25])
def test_nonmatching_projection_gives_a_finite_beta_near_the_exact_couplings(radius):
    """N : N + 1 by projection: β_h finite and positive, within the geometric error of the exact coupling's."""
    exact = rows(1, 4, 5, cylinder(radius), ["T3"])
    projected = rows(1, 4, 5, cylinder(radius, "projection"), ["T3"])
    for a, b in zip(exact, projected):
        assert np.isfinite(b["beta"]) and b["beta"] > 0 and b["kernel_dim"] == 0
        assert abs(a["beta"] - b["beta"]) < 1e-2 * a["beta"]


def test_the_exact_coupling_is_the_flat_faces_in_parameters():
    """(arc length, y) parametrize the cylinder isometrically: the exact coupling's points and
    weights are the flat face's, the curvature enters through the bodies' Schur complements only."""
    sides = SideCache().pair(MEMBRANES3D, "structured", 1, 3, 4, *cylinder(2.0))
    g = sides[0].trace.gamma
    assert type(g) is Cylinder
    space = registry.case_space("T3", 1, sides[1].trace.partition, g)
    x, x_trace, w = g.coupling_points(sides[0].trace, space, 2)
    flat = SideCache().pair(MEMBRANES3D, "structured", 1, 3, 4, FLAT)
    xf, _, wf = flat[0].trace.gamma.coupling_points(flat[0].trace, space, 2)
    assert np.array_equal(x, xf) and np.array_equal(x_trace, xf) and np.array_equal(w, wf)


# ------------------------------------------------------------------ refusals
@pytest.mark.parametrize("options, key", [
    (dict(gamma="cylinder", radius=1.0), "radius"),
    (dict(gamma="cylinder", radius=float("nan")), "radius"),
    (dict(gamma="cylinder", radius=-2.0), "radius"),
    (dict(gamma="cylinder"), "radius"),
    (dict(radius=2.0), "radius"),
    (dict(coupling="exact"), "coupling"),
    (dict(gamma="square", radius=2.0), "radius"),
    (dict(gamma="arc", radius=2.0), "gamma"),
    (dict(gamma="cylinder", radius=2.0, coupling="normal"), "coupling"),
    (dict(gamma="cylinder", radius=2.0, coupling="projection", element="tet"), "coupling"),
    (dict(gamma="cylinder", radius=2.0, element="hex20"), "element"),
    (dict(gamma="cylinder", radius=2.0, width=0.5), "width"),
])
def test_bad_cylinder_options_are_refused_naming_the_key(options, key):
    with pytest.raises(InputError) as e:
        MEMBRANES3D.gamma("structured", **{"element": "hex", **options})  # resolved without a mesh
    assert e.value.key == key


@pytest.mark.parametrize("family, element", [("unstructured", "tet"), ("perturbed", "tet")])
def test_faces_that_are_no_tensor_grid_are_refused(family, element):
    with pytest.raises(InputError) as e:
        MEMBRANES3D.gamma(family, element=element, gamma="cylinder", radius=2.0)
    assert e.value.key == "family"


@pytest.mark.parametrize("argv, key", [
    (["--model", "membranes3d", "--gamma", "cylinder", "--radius", "1"], "--radius"),
    (["--model", "membranes3d", "--gamma", "cylinder", "--radius", "nan"], "--radius"),
    (["--model", "membranes3d", "--radius", "2"], "--radius"),
    (["--model", "membranes3d", "--coupling", "projection"], "--coupling"),
    (["--model", "membranes3d", "--gamma", "arc", "--radius", "2"], "--gamma"),
    (["--model", "membranes", "--gamma", "cylinder", "--radius", "2"], "--gamma"),
    (["--model", "membranes3d", "--gamma", "cylinder", "--radius", "2", "--element", "tet",
      "--coupling", "projection"], "--coupling"),
])
def test_the_command_line_refuses_in_one_line(capsys, argv, key):
    code = cli_main(["beta", "--case", "T3", "--k", "1", "--N1", "2", "--N2", "3", *argv])
    err = capsys.readouterr().err.strip()
    assert code != 0 and "\n" not in err and "Traceback" not in err and key in err, err


@pytest.mark.parametrize("mesh, key", [(Flags(gamma="cylinder", radius=2.0), "gamma"),
                                       (Flags(gamma="arc", radius=2.0, coupling="exact"), "gamma"),
                                       (Flags(radius=2.0), "radius"),
                                       (cylinder(2.0), "gamma")])
def test_contact_scenes_refuse_a_curved_gamma(mesh, key):
    """The command line's flags, and a request's resolved Γ."""
    with pytest.raises(InputError) as e:
        check_flat_gamma(gamma=mesh[1]) if isinstance(mesh, tuple) else check_flat_gamma(mesh)
    assert e.value.key == key
    check_flat_gamma(Flags(gamma="square"))  # the flat face is the contact scenes' own
    check_flat_gamma(gamma=options_of(MEMBRANES3D, gamma="square")[1])
