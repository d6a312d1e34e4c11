"""The 3D contact patch test on serendipity HEX20 bodies (k = 2, QUAD8 faces): every space the
QUAD8 face builds (taken from the registry) reproduces the uniform pressure to round-off iff it
holds the constants and K has no kernel; u_h stays exact where K has one; the scene's numpy
exact solution is its NGSolve one; what HEX20 bodies cannot serve is refused in one line."""
from types import SimpleNamespace

import ngsolve
import numpy as np
import pytest

from helpers.cli import run_in_process

from infsup_contact.discretization.face.shapes.serendipity import SERENDIPITY
from infsup_contact.discretization.spaces.registry import SPACES
from infsup_contact.errors import InputError
from infsup_contact.models import hex20
from infsup_contact.models.membranes3d import MEMBRANES3D, subdomain_mesh
from infsup_contact.contact.contact import solve_contact_on
from infsup_contact.study.claims.membranes3d_studies import natural_kernel_count
from infsup_contact.study.contact.registry import FACE_PATCH
from infsup_contact.study.face.hex20 import quad8_cases
from infsup_contact.study.patch import face as face_patch
from infsup_contact.study.patch import elastic3d

EPS = np.finfo(float).eps
N1, N2 = 3, 4


def contact_cases() -> list:
    """The QUAD8-face spaces with one basis (a Petrov–Galerkin pair has two: no contact solve)."""
    return [c for c in quad8_cases(2) if not SPACES[c].petrov_galerkin]


@pytest.fixture(scope="module")
def pair():
    return face_patch.patch_pair(2, N1, N2, element="hex20")


@pytest.fixture(scope="module")
def rows(pair):
    """One row per QUAD8-face space, with the round-off bounds of its solve (see the test)."""
    out = []
    n_kappa_a = max(np.linalg.cond(s.stiffness.toarray()) * s.ndof for s in pair.sides)
    for case in contact_cases():
        row = face_patch.solve_face_patch(case, 2, N1, N2, element="hex20", pair=pair)
        ev = np.linalg.eigvalsh(solve_contact_on(pair, case, "omega2", time_floor=False).K)
        row["lambda_bound"] = row["dim_M"] * EPS * ev[-1] / ev[0] if row["kernel_dim"] == 0 else np.inf
        # u_h sees λ_h only through Bᵀλ_h, blind to the kernel: K on its range sets its error
        row["u_bound"] = row["dim_M"] * EPS * ev[-1] / ev[row["kernel_dim"]] + EPS * n_kappa_a
        out.append(row)
    return out


def test_every_quad8_space_passes_iff_it_holds_the_constants_and_k_has_no_kernel(rows):
    """A backward-stable solve of K λ = −g0 (dim M = m unknowns) has relative error ≤ m ε κ(K)
    (γ_m = m ε, Higham's bound); u_h = A⁻¹(F ∓ Bᵀλ_h) adds at most n_i ε κ(A_i) relative to δ
    (n_i free dofs of side i). A
    space holding 1 without a kernel stays inside these bounds; one lacking 1 (T3 vanishing on ∂Γ,
    the QUAD8 ones with the ∂Γ nodes dropped) misses λ by order 1."""
    assert {r["case"] for r in rows} == set(contact_cases())
    for r in rows:
        if r["predicted"] and r["kernel_dim"] == 0:
            assert r["lambda_max_rel_error"] <= r["lambda_bound"] < face_patch.PASS_RTOL, r
            assert r["u_max_rel_error"] <= r["u_bound"], r
            assert r["passes"], r
        elif not r["predicted"]:
            assert r["lambda_max_rel_error"] > 0.5 and not r["passes"], r
    lacking = {r["case"] for r in rows if not r["predicted"]}
    assert {"T3", "Q8", "LIN0-Q8"} <= lacking  # the spaces vanishing on ∂Γ
    assert any(r["passes"] for r in rows)


def test_a_kernel_leaves_u_exact_and_is_counted_from_below(rows):
    """u_h is unique whatever the kernel of K (module docstring of the face patch test): it is
    reproduced to the u bound by every space holding 1; the measured kernel is at least the
    predicted count (dimension count and QUAD8's product modes), which sees R5.2's modes."""
    for r in rows:
        count = natural_kernel_count(SPACES[r["case"]], 2, N1, N2, SERENDIPITY)
        assert r["kernel_dim"] >= count, r
        if r["predicted"]:
            assert r["u_max_rel_error"] <= r["u_bound"], r
    assert any(r["kernel_dim"] > 0 for r in rows)
    assert natural_kernel_count(SPACES["R5.2"], 2, N1, N2, SERENDIPITY) > 0


def test_standard_quad8_multipliers_start_with_open_corners(pair):
    """QUAD8's consistent nodal forces of a uniform pressure are negative at the corners, so the
    unconstrained weighted gap −δ ∫μ_j is positive exactly there for the standard (nodal) basis:
    those dofs start inactive, the PDAS needs one more step, and λ_h is still the constant."""
    sol = solve_contact_on(pair, "Q8-ALL", "omega2", time_floor=False)
    x, w = sol.gamma.quadrature(sol.space.breakpoints, 4)
    mass = (sol.space.evaluate(x) * w[:, None]).sum(axis=0)
    u0 = [u[-len(s.trace.gamma_dofs):] for u, s in zip(pair.u0, pair.sides)]
    from infsup_contact.discretization.gamma.coupling import coupling_matrix

    B = [coupling_matrix(s.trace, sol.space, 2) for s in pair.sides]
    g0 = B[1] @ u0[1] - B[0] @ u0[0]
    assert np.array_equal(g0 > 0, mass < 0) and (mass < 0).any()
    assert sol.pdas.iterations == 2 and np.all(sol.lam > 0)


@pytest.mark.parametrize("scene", [face_patch.patch_scene((1.0, 3.0), 0.02),
                                   elastic3d.patch_scene((2.0, 1.0), 0.3, 0.02)])
def test_numpy_exact_solution_is_the_ngsolve_one(scene):
    """On NGSolve bodies, ``exact_values`` equals ``exact()`` at points of each body to the round-off
    of evaluating the same affine formula twice (a few ε of the largest value)."""
    rng = np.random.default_rng(42)
    for i, cf in enumerate(scene.exact()):
        mesh = subdomain_mesh("structured", 2, i + 1).mesh
        p = rng.uniform(0.0, 1.0, size=(50, 3)) + np.array([0.0, 0.0, i])
        ng = np.asarray(cf(mesh(p[:, 0], p[:, 1], p[:, 2]))).reshape(len(p), -1)
        ours = np.asarray(scene.exact_values(i, p)).reshape(len(p), -1)
        assert np.max(np.abs(ng - ours)) <= 8 * EPS * max(np.max(np.abs(ours)), scene.d)


def test_the_hex20_field_evaluates_its_nodal_values_at_points(pair):
    """u_h of a HEX20 body: the per-cell samples and the point evaluation (``Basis.probes``) give
    the same values, and a linear field's nodal values give the linear function to round-off."""
    side = pair.sides[1]
    basis = side.trace.fes.basis
    lin = 0.3 * basis.doflocs[0] - 0.7 * basis.doflocs[2] + 0.1
    f = hex20.field(side, lin[side.free], lin)
    p, v = f.samples(2)
    assert np.max(np.abs(v - (0.3 * p[:, 0] - 0.7 * p[:, 2] + 0.1))) <= 16 * EPS * 2.0
    assert np.max(np.abs(f(p[:40]) - v[:40])) <= 16 * EPS * 2.0


def test_hostile_requests_are_refused_in_one_line():
    for k in (1, 3):
        with pytest.raises(InputError, match="k"):
            face_patch.solve_face_patch("T5", k, 2, 3, element="hex20")
        code, _, err = run_in_process(["contact", "--model", "membranes3d", "--scene", FACE_PATCH.id, "--case",
                                       "T5", "--k", str(k), "--N1", "2", "--N2", "3", "--element", "hex20"])
        assert code == 2 and len(err.strip().splitlines()) == 1 and "--k" in err, err
    pairs = [c for c in quad8_cases(2) if SPACES[c].petrov_galerkin]
    for case in pairs:  # two bases: the contact solve refuses the pair, naming it
        with pytest.raises(InputError, match="case"):
            face_patch.solve_face_patch(case, 2, 2, 3, element="hex20")
    body = subdomain_mesh("structured", 2, 1, element="hex20")
    with pytest.raises(InputError, match="element"):  # supports a HEX20 side does not have
        MEMBRANES3D.scene_side(SimpleNamespace(supports="side"), body, 2)
    side = MEMBRANES3D.scene_side(face_patch.patch_scene(), body, 2)
    with pytest.raises(InputError, match="element"):  # no interpolant of NGSolve functions
        MEMBRANES3D.interpolate(side, (ngsolve.z,))


def test_the_command_runs_every_quad8_space():
    """``contact --case all --element hex20``: a row per space the QUAD8 face builds (the registry's
    answer, not a list), each kernel-free row passing exactly where 1 ∈ M_h."""
    code, out, err = run_in_process(["contact", "--model", "membranes3d", "--scene", FACE_PATCH.id, "--case", "all",
                                     "--k", "2", "--N1", "2", "--N2", "3", "--element", "hex20"])
    assert code == 0, err
    lines = out.splitlines()
    rows = [dict(zip(lines[0].split(","), line.split(","))) for line in lines[1:]]
    assert [r["case"] for r in rows] == contact_cases()
    assert all(r["passes"] == r["predicted"] for r in rows if r["kernel_dim"] == "0")


def test_the_dag_table_leaves_the_petrov_galerkin_pairs_out():
    """A pair in ``face.cases`` (two bases: β_h only) is skipped by the patch table, not an error."""
    from infsup_contact.study.patch.face import face_patch_table

    rows = face_patch_table(["T4", "PGLIN0-Q8"], [2], [(2, 3)], ["hex20"])
    assert [r["case"] for r in rows] == ["T4"] and rows[0]["passes"]
