"""The curved segment (discretization/segment/arc.py, projection.py): R = ∞ is the paper's segment bit
for bit, the curved bodies and Γ_h converge to the exact ones at their rates, β_h tends to the flat
one like 1/R, the projection is exact where it must be (matching curves, flat Γ) and accurate where
it is a quadrature, and every bad option is one line naming its key."""
from __future__ import annotations

import io
import math

import numpy as np
import ngsolve
import pandas as pd
import pytest

from helpers.cli import run_in_process

from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.segment.arc import Arc
from infsup_contact.discretization.spaces.gammas import arc_of
from infsup_contact.discretization.segment.projection import project, side_curve
from infsup_contact.discretization.spaces import registry
from infsup_contact.errors import InputError
from infsup_contact.models import MODELS
from infsup_contact.solvers.infsup import beta_rows
from infsup_contact.solvers.request import resolve_gamma
from infsup_contact.solvers.side_cache import SideCache

MEMBRANES = MODELS["membranes"]
COLUMNS = ["case", "norm", "beta", "kernel_dim", "structural_kernel_dim", "smallest_nonzero"]


def arc_options(radius, coupling="exact"):
    """The request's Γ: the arc (an Interface, not a mesh option)."""
    return resolve_gamma(MODELS["membranes"], gamma="arc", radius=float(radius), coupling=coupling)


def rows(k, n1, n2, gamma=None, cases=None):
    return pd.DataFrame(beta_rows("structured", k, n1, n2, cases=cases, model=MEMBRANES, gamma=gamma))[COLUMNS]


@pytest.mark.parametrize("k,n1,n2", [(1, 5, 4), (2, 6, 6), (2, 7, 5)])
def test_infinite_radius_is_the_paper(k, n1, n2):
    """R = ∞ builds the paper's meshes: the exact coupling is the paper's, bit for bit; on a flat Γ the
    projection is the identity, with a longer rule and |p'| = 1 computed, so β_h agrees to round-off
    and every kernel is the same."""
    paper = rows(k, n1, n2)
    pd.testing.assert_frame_equal(rows(k, n1, n2, arc_options(math.inf)), paper, check_exact=True)
    projected = rows(k, n1, n2, arc_options(math.inf, "projection"))
    pd.testing.assert_frame_equal(projected.drop(columns=["beta", "smallest_nonzero"]),
                                  paper.drop(columns=["beta", "smallest_nonzero"]))
    for column in ("beta", "smallest_nonzero"):
        assert np.abs(projected[column] - paper[column]).max() <= 1e-12 * paper[column].max()


def test_curving_twice_is_curving_once():
    """Φ maps the square: a second curve() starts again from the square, not from the curved body."""
    body = curved_mesh(4, 2, 2)
    once = ngsolve.Integrate(1, body.mesh)
    body.interface.curve(body.mesh, 2)
    assert ngsolve.Integrate(1, body.mesh) == once


def test_beta_tends_to_the_flat_one_like_one_over_r():
    """The bodies move by O(1/R), so does β_h: the log-log slope of |β_R − β_∞| against R is −1."""
    flat = rows(2, 6, 7, cases=["T3", "T5"]).beta.to_numpy()
    radii = np.array([1e2, 1e3, 1e4])
    gaps = [np.abs(rows(2, 6, 7, arc_options(r), ["T3", "T5"]).beta.to_numpy() - flat).max() for r in radii]
    slope = np.polyfit(np.log(radii), np.log(gaps), 1)[0]
    assert -1.15 < slope < -0.85, (gaps, slope)


def curved_mesh(n, side, k, radius=2.0):
    body = MEMBRANES.subdomain_mesh("structured", n, side, gamma=arc_options(radius))
    body.interface.curve(body.mesh, k)
    return body


@pytest.mark.parametrize("k", [1, 2])
def test_curved_bodies_converge_to_the_annular_sectors(k):
    """∫_Ω 1 on the isoparametric body → |Ω_i| = (2R ∓ 1)/(2R); the error falls like h^{k+1} at least."""
    R, ns = 2.0, [4, 8, 16]
    for side, exact in ((1, (2 * R - 1) / (2 * R)), (2, (2 * R + 1) / (2 * R))):
        errors = [abs(ngsolve.Integrate(1, curved_mesh(n, side, k, R).mesh, order=2 * k + 2) - exact) for n in ns]
        slope = np.polyfit(np.log(1.0 / np.array(ns)), np.log(errors), 1)[0]
        assert slope > k + 1 - 0.2, (side, errors, slope)


@pytest.mark.parametrize("k", [1, 2])
def test_discrete_gamma_has_its_vertices_on_the_arc_and_length_tending_to_one(k):
    """Γ_h passes through the arc at its vertices (s = arc length) and its length → 1 like h^{2k}
    (the arc length of a degree-k interpolant of a circle)."""
    R, lengths = 2.0, []
    for n in (4, 8, 16):
        side = MEMBRANES.side_operator(curved_mesh(n, 2, k, R), k)
        curve = side_curve(side.trace, k)
        p, _ = curve.point(curve.breakpoints)
        exact = np.column_stack(Arc(radius=R).embed(curve.breakpoints))
        assert np.abs(p - exact).max() < 1e-13
        x, w = side.trace.gamma.quadrature(curve.breakpoints, 4 * k + 8)
        lengths.append(abs(w @ np.linalg.norm(curve.point(x)[1], axis=1) - 1.0))
    slope = np.polyfit(np.log([1 / 4, 1 / 8, 1 / 16]), np.log(lengths), 1)[0]
    assert slope > 2 * k - 0.3, (lengths, slope)


def pair(k, n1, n2, coupling, radius=2.0):
    return SideCache().pair(MEMBRANES, "structured", k, n1, n2, gamma=arc_options(radius, coupling))


def space_of(sides, case, k, choice="omega2"):
    gamma = sides[0].trace.gamma
    g_h = gamma.multiplier_partition(*(s.trace.partition for s in sides), choice)
    return registry.case_space(case, k, g_h, gamma)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_matching_sides_share_gamma_h_so_projection_couples_them_identically(k):
    """The deformation is interpolated edge by edge: on matching meshes both sides' Γ_h are one
    curve, P = id, and B_1 = B_2 to round-off (which keeps the kernels the count proves)."""
    sides = pair(k, 6, 6, "projection")
    curves = [side_curve(s.trace, k) for s in sides]
    assert np.abs(curves[0].coefficients - curves[1].coefficients).max() < 1e-14
    space = space_of(sides, "R5.2", k)
    B = [coupling_matrix(s.trace, space, k) for s in sides]
    assert np.abs(B[0] - B[1]).max() <= 1e-14 * np.abs(B[0]).max()


@pytest.mark.parametrize("choice", ["omega2", "omega1", "union"])
def test_projection_quadrature_is_accurate_to_round_off(choice):
    """The curved integrands are not polynomials: a rule 8 degrees longer changes B by round-off only."""
    sides = pair(2, 7, 9, "projection")
    space = space_of(sides, "T3", 2, choice)
    for s in sides:
        B, longer = coupling_matrix(s.trace, space, 2), coupling_matrix(s.trace, space, 2, extra_degree=8)
        assert np.abs(B - longer).max() <= 1e-13 * np.abs(B).max()


def test_projection_lands_on_the_master_curve_along_the_slave_normal():
    """(p_m(P(x)) − p_s(x)) × n_s(x) = 0, and P is increasing."""
    sides = pair(2, 5, 8, "projection", radius=1.5)
    slave, master = (side_curve(s.trace, 2) for s in (sides[1], sides[0]))
    x = np.linspace(0.05, 0.95, 301)
    y = project(slave, master, x)
    p, q, n = slave.point(x)[0], master.point(y)[0], slave.normal(x)
    assert np.abs((q - p)[:, 0] * n[:, 1] - (q - p)[:, 1] * n[:, 0]).max() < 1e-14
    assert np.all(np.diff(y) > 0)


def test_exact_coupling_on_the_arc_is_the_flat_coupling():
    """The exact coupling maps both traces to the arc by arc length: B_i is the segment's, so the
    kernels on the arc are the flat ones by construction (only the bodies, X_i, are curved)."""
    curved, flat = pair(2, 6, 7, "exact"), SideCache().pair(MEMBRANES, "structured", 2, 6, 7)
    for case in ("R5.2", "R5.4", "T3"):
        for s, f in zip(curved, flat):
            np.testing.assert_array_equal(coupling_matrix(s.trace, space_of(curved, case, 2), 2),
                                          coupling_matrix(f.trace, space_of(flat, case, 2), 2))


@pytest.mark.parametrize("options,key", [
    (dict(gamma="arc"), "radius"), (dict(gamma="arc", radius=1.0), "radius"),
    (dict(gamma="arc", radius=float("nan")), "radius"), (dict(gamma="arc", radius=-2.0), "radius"),
    (dict(gamma="arc", radius=True), "radius"), (dict(radius=2.0), "radius"),
    (dict(coupling="exact"), "coupling"), (dict(gamma="arc", radius=2.0, coupling="mortar"), "coupling"),
    (dict(gamma="circle"), "gamma")])
def test_bad_arc_options_name_their_key(options, key):
    with pytest.raises(InputError) as err:
        arc_of(**options)
    assert err.value.key == key


@pytest.mark.parametrize("argv,flag", [
    (["--gamma", "arc"], "--radius"), (["--gamma", "arc", "--radius", "1"], "--radius"),
    (["--gamma", "arc", "--radius", "nan"], "--radius"), (["--gamma", "arc", "--radius", "two"], "--radius"),
    (["--radius", "2"], "--radius"), (["--coupling", "projection"], "--coupling"),
    (["--gamma", "arc", "--radius", "2", "--coupling", "mortar"], "--coupling"),
    (["--model", "membranes3d", "--gamma", "arc", "--radius", "2"], "--gamma")])
def test_bad_arc_flags_are_one_line(argv, flag):
    code, out, err = run_in_process(["beta", "--case", "T3", "--k", "1", "--N1", "3", "--N2", "4", *argv])
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and flag in err, err


def test_contact_refuses_the_arc_in_one_line():
    code, _, err = run_in_process(["contact", "--scene", "manufactured", "--case", "T3", "--k", "1", "--N1", "3",
                                   "--N2", "3", "--gamma", "arc", "--radius", "2"])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "gamma" in err, err


def test_acceptance_line_prints_every_registered_segment_space():
    """``beta --gamma arc --radius 2 --case all --k 2 --N1 16 --N2 17``: a row per space and norm."""
    code, out, err = run_in_process(["beta", "--model", "membranes", "--gamma", "arc", "--radius", "2", "--case", "all",
                                     "--k", "2", "--N1", "16", "--N2", "17"])
    assert code == 0, err
    table = pd.read_csv(io.StringIO(out))
    assert set(table.case) == set(registry.common_ids(2)) and len(table) == 2 * len(set(table.case))
    assert (table.gamma == "arc").all() and (table.radius == 2.0).all() and (table.coupling == "exact").all()
    assert np.isfinite(table.beta).all() and (table.beta >= 0).all()
