"""The plane-strain elastic model (models/elastic.py): exact properties of its stiffness, the
sign convention of b(v, μ), and the Γ-reduced route against the assembled saddle point."""
from __future__ import annotations

import ngsolve
import numpy as np
import pytest

from helpers.cli import run_in_process
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from infsup_contact.discretization.segment import meshes
from infsup_contact.discretization.spaces import registry
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.segment.norms import gram
from infsup_contact.errors import InputError
from infsup_contact.models import MODELS
from infsup_contact.models.elastic import (ELASTIC, check_nu, elastic_model, elastic_space, elastic_stiffness,
                                           interpolate, lame, side_operator)
from infsup_contact.solvers.interface_operator import interface_operator
from infsup_contact.contact.contact import contact_qp
from infsup_contact.solvers.infsup import beta_rows, saddle_point_beta
from infsup_contact.contact.pdas import solve_pdas
from infsup_contact.study.patch.segment import PASS_RTOL
from infsup_contact.discretization.segment.interface import SEGMENT


def test_registered():
    assert MODELS["elastic"] is ELASTIC and "membranes" in MODELS


@pytest.mark.parametrize("k", [1, 2])
def test_floating_body_has_exactly_the_three_rigid_modes(k):
    """No Dirichlet boundary: K r = 0 for the translations and the rotation (−y, x), and the
    kernel of K has dimension exactly 3."""
    mesh = meshes.subdomain_mesh("structured", 3, 2)
    space = elastic_space(mesh, k, x_dirichlet="nothing", y_dirichlet="nothing")
    K = elastic_stiffness(space, 0.3)
    x, y = ngsolve.x, ngsolve.y
    for ux, uy in ((1, 0), (0, 1), (-y, x)):
        r = interpolate(space, ux, uy)
        assert np.linalg.norm(K @ r) < 1e-12 * abs(K).max() * np.linalg.norm(r)
    ev = sla.eigvalsh(K.toarray())
    assert np.sum(ev < 1e-10 * ev[-1]) == 3 and ev[3] > 1e-6 * ev[-1]


@pytest.mark.parametrize("k", [1, 2, 3])
@pytest.mark.parametrize("nu", [0.0, 0.3, 0.49])
def test_constant_strain_energy_is_exact(k, nu):
    """u = (a x + b y, c x + d y) is in P_k: uᵀKu = |Ω| (2μ̂ ε:ε + λ̂ (tr ε)²), |Ω| = 1."""
    mesh = meshes.subdomain_mesh("unstructured", 3, 1)
    space = elastic_space(mesh, k, x_dirichlet="nothing", y_dirichlet="nothing")
    K = elastic_stiffness(space, nu)
    a, b, c, d = 0.3, -0.7, 1.1, 0.4
    u = interpolate(space, a * ngsolve.x + b * ngsolve.y, c * ngsolve.x + d * ngsolve.y)
    eps = np.array([[a, 0.5 * (b + c)], [0.5 * (b + c), d]])
    mu, lam = lame(nu)
    exact = 2 * mu * np.sum(eps * eps) + lam * np.trace(eps) ** 2
    assert u @ (K @ u) == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("k", [1, 2])
def test_interface_operator_is_the_normal_block_of_the_inverse(k):
    """K (clamped) SPD; S⁻¹ of the side = ((K⁻¹)_ΓΓ)_nn = the nn block of the inverse of the
    Schur complement onto the Γ dofs of both components."""
    side = side_operator(meshes.subdomain_mesh("structured", 3, 1), k)
    K = side.stiffness.toarray()
    assert np.allclose(K, K.T) and sla.eigvalsh(K)[0] > 0
    ng, nt = len(side.trace.gamma_dofs), side.n_tangential
    Kinv = np.linalg.inv(K)
    X = side.steklov_inverse()
    assert np.allclose(X, Kinv[-ng:, -ng:], rtol=1e-10, atol=1e-12 * abs(X).max())
    nb = ng + nt  # both components, Γ last
    S_both = K[-nb:, -nb:] - K[-nb:, :-nb] @ np.linalg.solve(K[:-nb, :-nb], K[:-nb, -nb:])
    assert np.allclose(np.linalg.inv(S_both)[nt:, nt:], X, rtol=1e-9, atol=1e-12 * abs(X).max())
    assert sla.eigvalsh(side.schur)[0] > 0


def test_pressure_pushes_the_bodies_apart():
    """λ = 1 (T5 contains the constants) with no load: A_1 u_1 = −B_1ᵀ λ, A_2 u_2 = +B_2ᵀ λ
    gives u_{1,y} < 0 < u_{2,y} on Γ and a gap λᵀ K λ > 0."""
    k = 2
    m1, m2 = meshes.mesh_pair("structured", 4, 4)
    sides = [side_operator(m, k) for m in (m1, m2)]
    space = registry.case_space("T5", k, meshes.multiplier_breakpoints(m1, m2), SEGMENT)
    lam = np.linalg.lstsq(space.evaluate(np.linspace(0.05, 0.95, 40)), np.ones(40), rcond=None)[0]
    assert np.allclose(space.evaluate(np.array([0.3, 0.7])) @ lam, 1.0)
    Bs = [coupling_matrix(s.trace, space, k) for s in sides]
    uy = []
    for sign, s, B in zip((-1.0, 1.0), sides, Bs):
        rhs = np.zeros(s.ndof)
        rhs[s.ndof - B.shape[1]:] = sign * (B.T @ lam)
        gf = s.grid_function(s.solve(rhs))
        uy.append(np.array([gf.components[1](s.space.fes.mesh(x, 1.0)) for x in (0.25, 0.5, 0.75)]))
    assert np.all(uy[0] < 0) and np.all(uy[1] > 0)
    assert lam @ interface_operator(Bs, sides) @ lam > 0


@pytest.mark.parametrize("case, k, n1, n2", [("T3", 2, 3, 3), ("T5", 2, 3, 2), ("R5.4", 1, 2, 3)])
def test_beta_schur_route_equals_full_saddle_point_pencil(case, k, n1, n2):
    """β_h from the Γ-reduced interface operator (beta_rows, model=elastic) equals β_h from
    the assembled pencil [[A, Bᵀ], [B, 0]] (saddle_point_beta), H norm, ν = 0.3 and 0.45."""
    for nu in (0.3, 0.45):
        model = elastic_model(nu)
        row = beta_rows("structured", k, n1, n2, [case], norms=("H",), model=model)[0]
        m1, m2 = meshes.mesh_pair("structured", n1, n2)
        sides = [model.side_operator(m, k) for m in (m1, m2)]
        space = registry.case_space(case, k, meshes.multiplier_breakpoints(m1, m2), SEGMENT)
        Bs = [coupling_matrix(s.trace, space, k) for s in sides]
        A, B, _ = contact_qp(sides, Bs, [np.zeros(s.ndof) for s in sides])
        G, _ = gram(space, "H")
        assert row["beta"] == pytest.approx(saddle_point_beta(A, B.toarray(), G), rel=1e-7)


def test_contact_schur_route_equals_sparse_saddle_point_solve():
    """Frictionless contact of the clamped bodies pressed together by body forces f_2 = (0, −1),
    f_1 = (0, 1) with an initial gap: the active set on (K, g0) plus the recovery equal the
    sparse saddle-point solve of the assembled problem with that contact set."""
    k, n1, n2, E = 2, 4, 3, (1.0, 3.0)
    m1, m2 = meshes.mesh_pair("structured", n1, n2)
    sides = [side_operator(m, k) for m in (m1, m2)]
    space = registry.case_space("T3", k, meshes.multiplier_breakpoints(m1, m2), SEGMENT)
    Bs = [coupling_matrix(s.trace, space, k) for s in sides]
    F = []
    for s, fy in zip(sides, (1.0, -1.0)):
        lf = ngsolve.LinearForm(s.space.fes)
        lf += fy * s.space.fes.TestFunction()[1] * ngsolve.dx
        lf.Assemble()
        F.append(lf.vec.FV().NumPy()[s.free].copy())
    gap = 0.02 * np.linspace(0.0, 1.0, space.dim)  # a weighted initial gap growing along Γ
    K = interface_operator(Bs, sides, E)
    u0 = [s.solve(Fi) / c for s, Fi, c in zip(sides, F, E)]
    ng = [B.shape[1] for B in Bs]
    g0 = gap + Bs[1] @ u0[1][-ng[1]:] - Bs[0] @ u0[0][-ng[0]:]
    res = solve_pdas(K, g0)
    assert res.active.any() and not res.active.all()
    u_schur = []
    for sign, s, Fi, B, c in zip((-1.0, 1.0), sides, F, Bs, E):
        rhs = Fi.copy()
        rhs[s.ndof - B.shape[1]:] += sign * (B.T @ res.lam)
        u_schur.append(s.solve(rhs) / c)
    A, Bq, Fv = contact_qp(sides, Bs, F, E)
    # the gap enters as B u >= −gap: shift the right-hand side of the active rows
    Ba = Bq[res.active]
    n = A.shape[0]
    kkt = sp.bmat([[A, Ba.T], [Ba, None]], format="csc")
    sol = spla.spsolve(kkt, np.concatenate([Fv, -gap[res.active]]))
    assert np.allclose(np.concatenate(u_schur), sol[:n], rtol=1e-9, atol=1e-12)
    assert np.allclose(res.lam[res.active], -sol[n:], rtol=1e-8, atol=1e-12)
    assert np.all(res.lam >= -1e-12)


@pytest.mark.parametrize("bad", [0.5, 0.6, -1.0, -2.0, float("nan"), float("inf"), "x", True])
def test_bad_nu_refused(bad):
    with pytest.raises(InputError, match="invalid nu"):
        check_nu(bad)


def _run(argv):
    return run_in_process(argv)


def test_cli_beta_elastic_columns_and_agreement():
    code, out, err = _run(["beta", "--model", "elastic", "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4",
                           "--norm", "H", "--nu", "0.3", "--E1", "1", "--E2", "2"])
    assert code == 0, err
    header, row = out.splitlines()[:2]
    cols = dict(zip(header.split(","), row.split(",")))
    assert cols["model"] == "elastic" and float(cols["nu"]) == 0.3 and float(cols["E2"]) == 2.0
    ref = beta_rows("structured", 2, 4, 4, ["T3"], c1=1.0, c2=2.0, norms=("H",), model=elastic_model(0.3))[0]
    assert float(cols["beta"]) == pytest.approx(ref["beta"], rel=1e-10)


@pytest.mark.parametrize("flag, value, model", [("--nu", "0.5", "elastic"), ("--nu", "-1", "elastic"),
                                                ("--E1", "0", "elastic"), ("--E2", "-3", "elastic"),
                                                ("--E1", "nan", "elastic"), ("--nu", "0.3", "membranes"),
                                                ("--c1", "2", "elastic")])
def test_cli_bad_elastic_input_one_line_exit_2(flag, value, model):
    code, out, err = _run(["beta", "--model", model, "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4",
                           flag, value])
    assert code == 2 and out == "" and len(err.splitlines()) == 1 and flag in err, (code, err)


@pytest.mark.parametrize("model, flag", [("membranes", "--nu"), ("membranes", "--E2"), ("elastic", "--c1")])
def test_cli_refuses_another_models_flag_naming_the_models_flags(model, flag):
    """The material flags come from the model contract (Model.params): a flag the model lacks
    is refused in one line naming it and the flags the model has."""
    from infsup_contact.models import MODELS

    code, out, err = _run(["beta", "--model", model, "--case", "T3", "--k", "2", "--N1", "4", "--N2", "4",
                           flag, "2", "--dry-run"])
    assert code == 2 and out == "" and len(err.splitlines()) == 1 and flag in err, (code, err)
    assert all(f"--{name}" in err for name in MODELS[model].param_names()), err


# ----------------------------------------------------------------- the contact patch test

def test_patch_passes_with_constants_and_t3_fails_at_the_ends():
    """5:4 non-matching blocks, k = 2: T5 (contains the constants) reproduces λ = p and the
    linear displacement to round-off; T3 (zero at Γ's ends) cannot: λ_h(0) = 0, error 1 at the
    ends, and its displacement is wrong."""
    from infsup_contact.study.patch.segment import exact_pressure, solve_patch

    good = solve_patch("T5", 2, 5, 4, nu=0.3, E=(1.0, 2.0))
    assert good["passes"] and max(good["lambda_max_rel_error"], good["u_max_rel_error"]) < PASS_RTOL
    assert good["kernel_dim"] == 0 and good["p"] == pytest.approx(exact_pressure(1e-2, 0.3, (1.0, 2.0)))
    bad = solve_patch("T3", 2, 5, 4, nu=0.3, E=(1.0, 2.0))
    assert not bad["passes"] and bad["lambda_end_rel_error"] == pytest.approx(1.0) and bad["u_max_rel_error"] > 1e-3


def test_patch_pressure_is_the_uniform_stress():
    """p = δ/(1/M1 + 1/M2) is the stress of two stacked constrained layers: with E1 = E2 and
    ν = 0 (M = E) it is δE/2."""
    from infsup_contact.study.patch.segment import exact_pressure

    assert exact_pressure(0.2, 0.0, (3.0, 3.0)) == pytest.approx(0.3)


def test_cli_contact_patch_row():
    code, out, err = _run(["contact", "--model", "elastic", "--scene", "patch", "--case", "R5.4", "--k", "1",
                           "--N1", "7", "--N2", "3"])
    assert code == 0, err
    header, row = out.splitlines()[:2]
    cols = dict(zip(header.split(","), row.split(",")))
    assert cols["passes"] == "True" and float(cols["lambda_max_rel_error"]) < PASS_RTOL


@pytest.mark.parametrize("argv, flag", [
    (["contact", "--scene", "patch", "--case", "T3", "--k", "1", "--N1", "5", "--N2", "4"], "--scene"),
    (["contact", "--model", "elastic", "--scene", "membranes", "--case", "T3", "--k", "1", "--N1", "5", "--N2", "4"],
     "--model"),
    (["contact", "--model", "elastic", "--scene", "patch", "--case", "T3", "--k", "1", "--N1", "5", "--N2", "4",
      "--family", "unstructured"], "--family"),
    (["contact", "--model", "elastic", "--scene", "patch", "--case", "T3", "--k", "1", "--N1", "5", "--N2", "4",
      "--E2", "0"], "--E2"),
])
def test_cli_contact_elastic_refusals(argv, flag):
    code, out, err = _run(argv)
    assert code == 2 and out == "" and len(err.splitlines()) == 1 and flag in err, (code, err)


# ----------------------------------------------------------------- the Hertz scene

def test_hertz_energy_error_of_the_reference_itself_is_zero():
    """energy_error(ref, ref) = 0 and a coarse solution's error against it is > 0."""
    from infsup_contact.study.contact.hertz import energy_error, reference_data, solve_hertz

    ref = solve_hertz("T3", 2, 8, 1.0, 0.05)
    assert energy_error(ref, reference_data(ref), 0.3) < 1e-12
    coarse = solve_hertz("T3", 1, 4, 1.0, 0.05)
    assert energy_error(coarse, reference_data(ref), 0.3) > 1e-4


def test_hertz_modeling_error_falls_as_the_contact_zone_shrinks():
    """Against plane-strain Hertz for the measured P, the max-pressure error decreases with a/W
    (T3, k = 2, N = 32); the half-width a of Hertz grows with the indentation d."""
    from infsup_contact.study.contact.hertz import modeling_rows

    rows = modeling_rows("T3", 2, 32, 1.0, [0.02, 0.05, 0.1])
    err = [r["p_max_rel_error"] for r in rows]
    a = [r["hertz_a"] for r in rows]
    assert err[0] < err[1] < err[2] and a[0] < a[1] < a[2]


def test_hertz_formulas():
    """a = sqrt(4PR/(πE*)), p0 = 2P/(πa), and ∫ p = P for the Hertz profile (Gauss)."""
    from infsup_contact.study.contact.hertz import combined_modulus, hertz, hertz_pressure

    P, R, nu, E = 0.01, 2.0, 0.25, (1.0, 3.0)
    a, p0 = hertz(P, R, nu, E)
    assert combined_modulus(nu, E) == pytest.approx(1 / ((1 - nu**2) * (1 + 1 / 3)))
    t, w = np.polynomial.legendre.leggauss(200)
    x = 0.5 + a * np.sin(0.5 * np.pi * t)  # substitution removes the square-root edge
    jac = a * 0.5 * np.pi * np.cos(0.5 * np.pi * t)
    assert w @ (hertz_pressure(x, P, R, nu, E) * jac) == pytest.approx(P, rel=1e-10)
    assert p0 == pytest.approx(2 * P / (np.pi * a))


# ----------------------------------------------------------------- the paper section

def test_elastic_section_uses_only_generated_macros_and_has_no_typed_results():
    """From small real tables (tiny meshes): every \\elastic… macro and \\input of
    paper/elastic.tex is generated, every macro value comes from its table, and the section
    types no result (no 3+ decimals, no scientific notation)."""
    import re
    from pathlib import Path

    from helpers.elastic_tables import small_elastic_tables

    from infsup_contact.report.sections.elastic import check_elastic_tex, elastic_paper_files

    t = small_elastic_tables()
    claims = t["claims"]
    files = elastic_paper_files(**t)
    tex = (Path(__file__).resolve().parents[2] / "paper" / "elastic.tex").read_text()
    check_elastic_tex(tex, files)
    body = re.sub(r"(?<!\\)%.*", "", tex)
    assert not re.findall(r"\d\.\d{3,}", body) and not re.findall(r"\d[eE]-?\d|\\times\s*10\^", body)
    macros = dict(re.findall(r"\\newcommand\{\\([A-Za-z]+)\}\{([^}]*)\}", files["elastic_macros.tex"]))
    assert int(macros["elasticNClaims"]) == len(claims)
    assert macros["elasticFinestN"] == "4" and macros["elasticCoarsestN"] == "2"
    assert int(macros["elasticPatchNPass"]) == 1 and int(macros["elasticPatchNSeries"]) == 2  # T5 passes, T3 not
    from infsup_contact.report.tables import claims_table

    assert "longtable" in claims_table(claims)  # raises PaperTexError if a claim text has no LaTeX form
