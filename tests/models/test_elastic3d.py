"""The 3D elastic bodies (models/elastic3d.py, issue 28 item 1): exact properties of the
stiffness, its Γ Schur complement against two independent routes, the kernel counts against
the dimension argument and the 3D membranes, and the elastic face patch test
(study/elastic_face_patch.py) against its closed form by a second route (Hooke's stress)."""
from __future__ import annotations

import ngsolve
import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from helpers.cli import run_in_process

from infsup_contact.discretization.spaces import registry
from infsup_contact.models import MODELS, make_model, model_of_dim, model_taking
from infsup_contact.models.elastic3d import (ELASTIC3D, elastic_stiffness, side_operator, subdomain_mesh,
                                             vector_space)
from infsup_contact.models.plane_strain import lame
from infsup_contact.models.contract import Body, schur_by_solves
from infsup_contact.contact.contact import solve_contact_on
from infsup_contact.solvers.infsup import beta_rows_all
from infsup_contact.study.patch import elastic3d as efp
from infsup_contact.study.patch.face import PASS_RTOL
from infsup_contact.study.contact.registry import ELASTIC_FACE_PATCH
from infsup_contact.solvers.request import MeshOptions

FREE = ("nothing",) * 3
"""Supports matching no boundary: a floating body."""


def _dofs(fes, cf) -> np.ndarray:
    gf = ngsolve.GridFunction(fes)
    gf.Set(ngsolve.CoefficientFunction(cf))
    return gf.vec.FV().NumPy().copy()


def _dense(mat) -> np.ndarray:
    data, cols, rows = (np.array(a, copy=True) for a in mat.CSR())
    return sp.csr_matrix((data, cols, rows), shape=(mat.height, mat.width)).toarray()


def test_registered_without_displacing_the_first_models():
    """Registered last: the 2D elastic model stays the first taking ν, the 3D membranes the
    first of dimension 3 (studies asking the registry see what they saw)."""
    assert MODELS["elastic3d"] is ELASTIC3D and ELASTIC3D.components == 3 and ELASTIC3D.dim == 3
    assert model_taking("nu") is MODELS["elastic"] and model_of_dim(3) is MODELS["membranes3d"]
    assert make_model("elastic3d", nu=0.45).side_operator.keywords["nu"] == 0.45


@pytest.mark.parametrize("element, k", [("hex", 1), ("hex", 2), ("tet", 1)])
def test_floating_body_has_exactly_the_six_rigid_modes(element, k):
    """No support: K r = 0 for the 3 translations and 3 rotations, and dim ker K = 6 exactly
    (eigenvalues of K against the mass matrix: NGSolve's hierarchical Q2 bubbles make K's own
    spectrum basis-scaled, ~1e-7 on a single cube even for the Laplacian)."""
    fes = vector_space(subdomain_mesh("structured", 2, 2, element=element).mesh, k, FREE)
    K = elastic_stiffness(fes, 0.3)
    x, y, z = ngsolve.x, ngsolve.y, ngsolve.z
    for r in ((1, 0, 0), (0, 1, 0), (0, 0, 1), (-y, x, 0), (0, -z, y), (z, 0, -x)):
        v = _dofs(fes, r)
        assert np.linalg.norm(K @ v) < 1e-12 * abs(K).max() * np.linalg.norm(v)
    u, v = fes.TnT()
    mass = ngsolve.BilinearForm(ngsolve.InnerProduct(u, v) * ngsolve.dx).Assemble().mat
    ev = sla.eigvalsh(K.toarray(), _dense(mass))
    assert np.sum(ev < 1e-10 * ev[-1]) == 6 and ev[6] > 1e-6 * ev[-1]


@pytest.mark.parametrize("element", ["hex", "tet"])
@pytest.mark.parametrize("nu", [0.0, 0.3, 0.49])
def test_constant_strain_energy_is_exact(element, nu):
    """u = G x (G a random 3×3 matrix) lies in V_h: uᵀKu = |Ω| (2μ̂ ε:ε + λ̂ (tr ε)²), |Ω| = 1."""
    fes = vector_space(subdomain_mesh("structured", 2, 1, element=element).mesh, 2, FREE)
    K = elastic_stiffness(fes, nu)
    G = np.random.default_rng(3).normal(size=(3, 3))
    X = (ngsolve.x, ngsolve.y, ngsolve.z)
    u = _dofs(fes, tuple(sum(G[i, j] * X[j] for j in range(3)) for i in range(3)))
    eps = 0.5 * (G + G.T)
    mu, lam = lame(nu)
    assert u @ (K @ u) == pytest.approx(2 * mu * np.sum(eps * eps) + lam * np.trace(eps) ** 2, rel=1e-11)


@pytest.fixture(scope="module", params=[("hex", 2), ("tet", 1)])
def side(request):
    element, k = request.param
    return side_operator(subdomain_mesh("structured", 2, 1, element=element), k)


def test_schur_is_spd_and_equals_the_reference_routes(side):
    """S (the trailing block of one factorization) is SPD and equals S by solves
    (:func:`schur_by_solves`); S⁻¹ is the zz block of the inverse of the Schur complement onto
    the Γ dofs of all three components (tangential ones not eliminated first), and the
    nested-dissection route gives the same S."""
    S = side.schur
    assert np.allclose(S, S.T) and sla.eigvalsh(S)[0] > 0
    scale = abs(S).max()
    assert np.allclose(S, schur_by_solves(side), rtol=0, atol=1e-10 * scale)
    K = side.stiffness.toarray()
    ng, nt = len(side.trace.gamma_dofs), side.n_tangential
    assert ng > 0 and nt == 2 * ng  # clamped on ∂Ω∖Γ: the same Γ nodes carry x, y and z
    nb = ng + nt
    S_all = K[-nb:, -nb:] - K[-nb:, :-nb] @ np.linalg.solve(K[:-nb, :-nb], K[:-nb, -nb:])
    X = side.steklov_inverse()
    assert np.allclose(np.linalg.inv(S_all)[nt:, nt:], X, rtol=1e-9, atol=1e-12 * abs(X).max())
    nested = side_operator(Body(side.trace.fes.mesh, side.trace.gamma), side.trace.fes.globalorder, route="nested")
    assert np.allclose(nested.schur, S, rtol=0, atol=1e-10 * scale)


@pytest.fixture(scope="module")
def matching_rows():
    """β_h rows of both 3D models, every case, k = 1, 2, matching hexahedra N = 3, both norms."""
    out = {}
    for name in ("elastic3d", "membranes3d"):
        for k in (1, 2):
            out[name, k] = beta_rows_all("structured", k, 3, 3, registry.common_ids(k), norms=("H", "L2"),
                                         model=MODELS[name], mesh=MeshOptions(element="hex"))
    return out


def test_kernels_on_matching_meshes_are_the_dimension_count(matching_rows):
    """dim ker = max(dim M − dim W, 0), W the z traces vanishing on ∂Γ: dim W is the number of
    free z Γ dofs of a side, as for the 3D membranes' scalar trace."""
    for k in (1, 2):
        n_w = len(side_operator(subdomain_mesh("structured", 3, 1), k).trace.gamma_dofs)
        assert n_w == (3 * k - 1) ** 2
        for r in matching_rows["elastic3d", k]:
            assert r["dim_W"] == n_w and r["kernel_dim"] == max(r["dim_M"] - n_w, 0), r
            assert r["kernel_check"] == "agree", r


def test_elastic_and_membranes_share_kernels_and_both_are_stable_for_t3(matching_rows):
    """The kernel of Σ B_i X_i B_iᵀ is that of the couplings (traces only), so it is the same
    for both models case by case; β_h of T3 is positive for both (no kernel)."""
    for k in (1, 2):
        el = {(r["case"], r["norm"]): r for r in matching_rows["elastic3d", k]}
        mem = {(r["case"], r["norm"]): r for r in matching_rows["membranes3d", k]}
        assert el.keys() == mem.keys()
        for key in el:
            assert el[key]["kernel_dim"] == mem[key]["kernel_dim"], key
        t3 = [c for c in registry.common_ids(k) if not registry.space_spec(c).contains_constants(k)]
        for case in t3:
            for norm in ("H", "L2"):
                assert el[case, norm]["beta"] > 0 and mem[case, norm]["beta"] > 0


def test_non_matching_kernels_equal_the_membranes():
    """On a non-matching pair (tetrahedra 2:3) both models see the same couplings: equal kernels."""
    kw = dict(norms=("L2",), mesh=MeshOptions(element="tet"))
    el = beta_rows_all("structured", 1, 2, 3, registry.common_ids(1), model=ELASTIC3D, **kw)
    mem = beta_rows_all("structured", 1, 2, 3, registry.common_ids(1), model=MODELS["membranes3d"], **kw)
    assert [(r["case"], r["kernel_dim"]) for r in el] == [(r["case"], r["kernel_dim"]) for r in mem]


# ------------------------------------------------------------------ the elastic face patch test
@pytest.mark.parametrize("element, k", [("hex", 1), ("hex", 2), ("tet", 2)])
def test_patch_passes_iff_the_space_contains_the_constants(element, k):
    rows = efp.elastic_face_patch_rows(registry.common_ids(), [k], [(3, 4)], element=element)
    assert {r["case"] for r in rows} == set(registry.common_ids(k))
    for r in rows:
        assert r["scene"] == ELASTIC_FACE_PATCH.id and r["kernel_dim"] == 0
        assert r["passes"] == r["predicted"] == registry.space_spec(r["case"]).contains_constants(k), r
        if r["passes"]:
            assert max(r["lambda_max_rel_error"], r["u_max_rel_error"]) <= PASS_RTOL, r
        else:  # a real failure, not a tolerance artefact
            assert r["lambda_max_rel_error"] > 1e-2, r
    assert any(r["passes"] for r in rows) and any(not r["passes"] for r in rows)


def test_patch_closed_form_by_hookes_stress():
    """E1 ≠ E2, ν = 0.35: at interior points of both bodies the discrete stress of u_h
    (Hooke's law on its gradient, not the formula) is −p e_z⊗e_z with p = λ_h, the bodies
    slip (u_x jumps across Γ by ν p x (1/E2 − 1/E1)) and the z displacements meet on Γ, each to the
    patch test's own tolerance (PASS_RTOL of p or δ), not to this CPU's round-off digits."""
    E, nu, delta = (1.0, 4.0), 0.35, 0.02
    p = delta / (1.0 / E[0] + 1.0 / E[1])
    pair = efp.patch_pair(2, 3, 4, E, nu, delta)
    sol = solve_contact_on(pair, "T5", "omega2", time_floor=False)
    mu, lam = lame(nu)
    rng = np.random.default_rng(28)
    xy = rng.uniform(0.05, 0.95, size=(15, 2))
    for i, (gf, zlo) in enumerate(zip(sol.u, (0.0, 1.0))):
        mesh = gf.space.mesh
        pts = mesh(xy[:, 0], xy[:, 1], rng.uniform(zlo + 0.05, zlo + 0.95, size=15))
        grad = np.asarray(ngsolve.Grad(gf)(pts)).reshape(-1, 3, 3)
        eps = 0.5 * (grad + grad.transpose(0, 2, 1))
        sigma = E[i] * (2 * mu * eps + lam * np.trace(eps, axis1=1, axis2=2)[:, None, None] * np.eye(3))
        target = np.zeros((3, 3))
        target[2, 2] = -p
        np.testing.assert_allclose(sigma, np.broadcast_to(target, sigma.shape), atol=PASS_RTOL * p)
    np.testing.assert_allclose(sol.pressure(xy), p, rtol=PASS_RTOL)
    on_gamma = [np.asarray(gf(gf.space.mesh(xy[:, 0], xy[:, 1], np.ones(15)))).reshape(-1, 3) for gf in sol.u]
    np.testing.assert_allclose(on_gamma[1][:, 2] - on_gamma[0][:, 2], 0.0, atol=PASS_RTOL * delta)
    np.testing.assert_allclose(on_gamma[1][:, 0] - on_gamma[0][:, 0], nu * p * xy[:, 0] * (1 / E[1] - 1 / E[0]),
                               atol=PASS_RTOL * delta)


# ------------------------------------------------------------------ the command line
def _csv(out):
    header, *rows = out.strip().splitlines()
    return [dict(zip(header.split(","), r.split(","))) for r in rows]


def test_cli_beta_and_verdict():
    code, out, err = run_in_process(["beta", "--model", "elastic3d", "--case", "all", "--k", "1", "--N1", "2",
                                     "--N2", "3", "--element", "tet", "--nu", "0.49", "--norm", "L2"])
    assert code == 0, err
    rows = _csv(out)
    assert {r["case"] for r in rows} == set(registry.common_ids(1))
    assert all(r["model"] == "elastic3d" and r["element"] == "tet" and float(r["nu"]) == 0.49 for r in rows)
    code, out, err = run_in_process(["verdict", "--model", "elastic3d", "--case", "T3", "--k", "1",
                                     "--N", "2", "3", "4"])
    assert code == 0, err
    row = _csv(out)[0]  # T3 has no kernel (the dimension count): never UNSTABLE by a kernel
    assert row["kernel_dim"] == "0" and row["verdict"] in ("STABLE", "INCONCLUSIVE"), row


@pytest.mark.parametrize("argv, key", [
    (["--nu", "0.5"], "nu"), (["--element", "prism"], "element"), (["--family", "unstructured"], "element"),
    (["--family", "sqrt2"], "family"),
    (["--c1", "2"], "c1")])
def test_cli_bad_input_one_line(argv, key):
    code, out, err = run_in_process(["beta", "--model", "elastic3d", "--case", "T3", "--k", "1", "--N1", "2",
                                     "--N2", "2", *argv])
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and key in err, err


@pytest.mark.parametrize("family", ["perturbed", "unstructured"])
def test_the_3d_families_give_the_proven_kernels(family):
    """The membranes' perturbed and unstructured tetrahedral meshes serve the elastic bodies too (the
    lateral faces renamed, the triangulated face kept): kernels equal the proof, T3 has none.
    The kernel is Bᵀ's, whatever the norm: every space in L² (the general triangulation's H Gram,
    a double sine series, is 5x dearer), T3's β in H."""
    def rows_of(case, norm):
        code, out, err = run_in_process(["beta", "--model", "elastic3d", "--case", case, "--k", "1", "--N1", "2",
                                         "--N2", "3", "--element", "tet", "--family", family, "--norm", norm])
        assert code in (0, None), err
        return {r["case"]: r for r in _csv(out)}

    rows = rows_of("all", "L2")
    assert len(rows) >= 5 and all(r["kernel_dim"] == r["structural_kernel_dim"] for r in rows.values()), rows
    assert sum(int(r["kernel_dim"]) > 0 for r in rows.values()) >= 3  # R5.2, R5.4, DUAL-ALL
    t3 = rows_of("T3", "H")["T3"]
    assert rows["T3"]["kernel_dim"] == t3["kernel_dim"] == "0" and float(t3["beta"]) > 0.1


def test_cli_contact_patch_rows():
    code, out, err = run_in_process(["contact", "--model", "elastic3d", "--scene", ELASTIC_FACE_PATCH.id,
                                     "--case", "all", "--k", "1", "--N1", "2", "--N2", "3", "--E2", "2"])
    assert code == 0, err
    rows = _csv(out)
    assert rows and all(r["passes"] == r["predicted"] and float(r["E2"]) == 2.0 for r in rows)
