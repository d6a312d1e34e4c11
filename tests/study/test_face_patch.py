"""The 3D contact patch test on the face (issue 28, item 6): a uniform pressure across
non-matching faces is reproduced to round-off iff M_h contains the constants (the registry's
computed ``contains_constants``), and the closed form of the scene is checked by a second
route (the discrete solution's own fluxes, values and gap)."""
import ngsolve
import numpy as np
import pytest

from helpers.cli import run_in_process

from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError
from infsup_contact.contact.contact import gamma_values, solve_contact_on
from infsup_contact.study.patch import face as face_patch
from infsup_contact.study.contact.registry import FACE_PATCH


@pytest.fixture(scope="module", params=[1, 2])
def hex_rows(request):
    """Every registered space valid for k on the non-matching hexahedral pair 3:4."""
    return face_patch.face_patch_rows(registry.common_ids(), [request.param], [(3, 4)])


def test_passes_iff_the_space_contains_the_constants(hex_rows):
    assert {r["case"] for r in hex_rows} == set(registry.common_ids(hex_rows[0]["k"]))
    for r in hex_rows:
        spec = registry.space_spec(r["case"])
        assert r["passes"] == spec.contains_constants(r["k"]), r
        if r["passes"]:
            assert max(r["lambda_max_rel_error"], r["u_max_rel_error"]) <= face_patch.PASS_RTOL, r
        else:  # a real failure, not a tolerance artefact
            assert r["lambda_max_rel_error"] > 1e-2, r
    assert any(not r["passes"] for r in hex_rows) and any(r["passes"] for r in hex_rows)


def test_non_matching_tetrahedra_agree_with_the_prediction():
    rows = face_patch.face_patch_rows(registry.common_ids(), [2], [(3, 4)], element="tet")
    assert rows and all(r["passes"] == r["predicted"] for r in rows), rows


def test_closed_form_by_a_second_route():
    """Unequal scales c: the discrete solution of two spaces holding the constants gives, at
    interior points, λ = −c_i ∂u_{i,h}/∂z (the flux of each body, not the formula), u_h equal to
    the closed form, u_{1,h} = u_{2,h} on Γ (zero gap, contact active) and λ > 0, each to the patch
    test's own tolerance (PASS_RTOL of λ or δ), not to this CPU's round-off digits (~1e-14)."""
    c, delta = (1.0, 3.0), 0.02
    scene = face_patch.patch_scene(c, delta)
    lam = delta / (1.0 / c[0] + 1.0 / c[1])
    assert scene.pressure == pytest.approx(lam, rel=1e-15) and lam > 0
    rng = np.random.default_rng(28)
    for case, k in (("T5", 2), ("R5.2", 1)):
        pair = face_patch.patch_pair(k, 3, 4, c, delta)
        sol = solve_contact_on(pair, case, "omega2", time_floor=False)
        xy = rng.uniform(0.05, 0.95, size=(20, 2))
        for i, (gf, zlo) in enumerate(zip(sol.u, (0.0, 1.0))):
            z = rng.uniform(zlo + 0.05, zlo + 0.95, size=20)
            mesh = gf.space.mesh
            pts = mesh(xy[:, 0], xy[:, 1], z)
            flux = -c[i] * np.asarray(ngsolve.grad(gf)[2](pts)).ravel()
            np.testing.assert_allclose(flux, lam, rtol=face_patch.PASS_RTOL)
            exact = -lam / c[0] * z if i == 0 else -delta + lam / c[1] * (2.0 - z)
            np.testing.assert_allclose(np.asarray(gf(pts)).ravel(), exact, rtol=0, atol=face_patch.PASS_RTOL * delta)
        u1, u2 = gamma_values(sol, xy)
        np.testing.assert_allclose(u1, u2, rtol=0, atol=face_patch.PASS_RTOL * delta)
        assert np.all(sol.lam > 0) and sol.pdas.active.all()


def test_a_kernel_leaves_u_unique():
    """On the union of both traces R5.2 has more multipliers than the traces can see: K has a
    kernel, λ_h is not unique (the PDAS flags it), yet u_h is the exact u to round-off."""
    pair = face_patch.patch_pair(1, 2, 3)
    row = face_patch.solve_face_patch("R5.2", 1, 2, 3, pair=pair,
                                      multiplier_mesh="union")
    assert row["kernel_dim"] > 0 and row["nonunique"]
    assert row["u_max_rel_error"] <= face_patch.PASS_RTOL


def test_nodal_face_bases_are_nodal_at_their_nodes():
    """The cone of the face spaces: at ``FaceSpace.nodes()`` the tensor basis evaluates to the
    Kronecker product of its 1D factors at theirs (numbering a·dim M^y + b), the identity for a
    continuous nodal basis (coefficients = nodal values, the cone ``SpaceSpec.cone`` states; a
    discontinuous one has its nodes twice at the breakpoints, one per side)."""
    part = TensorPartition(np.linspace(0, 1, 4), np.array([0.0, 0.2, 0.7, 1.0]))
    checked = 0
    for k in (1, 2):
        for case in registry.common_ids(k):
            spec = registry.space_spec(case)
            if not spec.nodal_basis:
                continue
            space = SQUARE.space(spec, k, part)
            sx, sy = space.factors
            ex, ey = (f.evaluate(f.nodes()) for f in (sx, sy))
            np.testing.assert_allclose(space.evaluate(space.nodes()), np.kron(ex, ey), atol=1e-12)
            if all(len(np.unique(f.nodes())) == f.dim for f in (sx, sy)):  # continuous: nodes are distinct
                np.testing.assert_allclose(space.evaluate(space.nodes()), np.eye(space.dim), atol=1e-12)
                checked += 1
    assert checked > 0


def test_cli_prints_the_rows_and_refuses_a_bad_delta():
    code, out, err = run_in_process(["contact", "--model", "membranes3d", "--scene", FACE_PATCH.id, "--case", "all",
                                     "--k", "1", "--N1", "2", "--N2", "3", "--element", "hex"])
    assert code == 0, err
    lines = out.splitlines()
    cols = lines[0].split(",")
    rows = [dict(zip(cols, line.split(","))) for line in lines[1:]]
    assert len(rows) == len(registry.common_ids(1))
    assert all(r["passes"] == r["predicted"] for r in rows)
    with pytest.raises(InputError, match="delta"):
        face_patch.patch_scene(delta=-1.0)


@pytest.mark.parametrize("element", ["hex", "tet"])
def test_beta_sides_clamp_the_lateral_faces_the_scene_does_not(element):
    """The mesh names the far and lateral faces apart; β_h's side still vanishes on all of
    ∂Ω_i∖Γ (its Γ dofs: the (n k − 1)² interior nodes of the face), the scene's side only on the
    far face (all (n k + 1)² Γ nodes), and its lift carries −δ on Ω2's far face only."""
    from infsup_contact.models import make_model

    model = make_model(FACE_PATCH.models[0])
    scene = face_patch.patch_scene()
    n, k = 3, 2
    for side in (1, 2):
        body = model.subdomain_mesh("structured", n, side, element=element)
        beta, contact = model.side_operator(body, k), model.side_for(scene, body, k)
        mesh = body.mesh
        gamma = beta.trace.gamma
        assert len(beta.trace.gamma_dofs) == gamma.trace_dimension(k, n)
        assert len(contact.trace.gamma_dofs) == gamma.trace_nodes(k, n)
        F, lift = model.load(contact, scene, side - 1)
        gf = ngsolve.GridFunction(contact.trace.fes)
        gf.vec.FV().NumPy()[:] = lift
        far_z, middle = (0.0, 0.5) if side == 1 else (2.0, 1.5)
        assert gf(mesh(0.3, 0.6, far_z)) == pytest.approx(scene.far_displacement[side - 1], abs=1e-14)
        assert gf(mesh(0.0, 0.5, middle)) == pytest.approx(0.0, abs=1e-14)  # a lateral face, off the far one
