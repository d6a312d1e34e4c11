"""study/patch/membranes.py: the membranes' contact patch test passes iff 1 ∈ M_h."""
from functools import lru_cache

import ngsolve
import numpy as np
import pytest

from infsup_contact.discretization.gamma.constants import spans_constants
from infsup_contact.discretization.spaces import registry
from infsup_contact.errors import InputError
from infsup_contact.models import MODELS
from infsup_contact.contact.contact import solve_contact_on
from infsup_contact.study.contact.blocks import block_mesh
from infsup_contact.study.patch import membranes as patch

C = (1.0, 3.0)
"""Unequal prestresses: the pressure is not δ/2, the slopes differ across Γ."""
N1, N2 = 5, 4
"""Non-matching traces: Ω1 nodes inside most intervals of G_h."""


@lru_cache(maxsize=None)
def _pair(k):
    return patch.patch_pair(k, N1, N2, C)


@pytest.mark.parametrize("k, case", [(k, case) for k in (1, 2, 3) for case in registry.common_ids(k)])
def test_passes_exactly_when_the_multiplier_space_holds_the_constants(k, case):
    row = patch.solve_membranes_patch(case, k, N1, N2, C, pair=_pair(k))
    space = solve_contact_on(_pair(k), case, "omega2").space
    assert row["predicted"] == spans_constants(space)
    if row["predicted"]:
        assert row["lambda_max_rel_error"] < 1e-8 and row["u_max_rel_error"] < 1e-8
        assert row["passes"]
    else:
        assert row["lambda_max_rel_error"] > 1e-5 and not row["passes"]


def test_a_space_without_the_constants_is_among_the_cases():
    """The iff has both sides here: T3 vanishes at Γ's ends, the natural sides do not."""
    rows = patch.membranes_patch_rows(list(registry.PAPER_CASES), [1], [(N1, N2)], C)
    assert {r["predicted"] for r in rows} == {True, False}
    assert all(r["passes"] == r["predicted"] for r in rows)


@pytest.mark.parametrize("c", [(1.0, 3.0), (2.5, 0.4)])
def test_the_discrete_pressure_is_the_series_spring_formula(c):
    delta = 0.02
    row = patch.solve_membranes_patch("R5.4", 2, N1, N2, c, delta)
    lam = delta / (1.0 / c[0] + 1.0 / c[1])
    assert row["pressure"] == pytest.approx(lam, rel=1e-14)
    assert row["lambda_max_rel_error"] < 1e-8


@pytest.mark.parametrize("c", [(1.0, 3.0), (2.5, 0.4)])
def test_the_exact_solution_meets_supports_contact_and_flux_continuity(c):
    delta = 0.02
    u1, u2 = patch.exact_displacements(delta, c)
    lam = patch.exact_pressure(delta, c)
    m1, m2 = block_mesh(2, 1), block_mesh(2, 2)
    at = lambda f, m, y: f(m(0.3, y))  # noqa: E731
    dy = lambda f, m, y: (at(f, m, y + 1e-3) - at(f, m, y - 1e-3)) / 2e-3  # noqa: E731 (exact for linear f)
    assert at(u1, m1, 0.0) == pytest.approx(0.0, abs=1e-15)
    assert at(u2, m2, 2.0) == pytest.approx(-delta, rel=1e-14)
    assert at(u1, m1, 1.0) == pytest.approx(at(u2, m2, 1.0), rel=1e-13)  # zero gap on Γ
    assert -c[0] * dy(u1, m1, 0.5) == pytest.approx(lam, rel=1e-9)
    assert -c[1] * dy(u2, m2, 1.5) == pytest.approx(lam, rel=1e-9)
    assert lam > 0.0  # pushes the bodies apart: contact is active


def test_the_scene_side_leaves_the_lateral_sides_and_gammas_ends_free():
    """Natural lateral sides: both end dofs of Γ are unknowns, Γ dofs of the trace."""
    mesh = block_mesh(3, 2)
    side = MODELS["membranes"].side_for(patch.patch_scene(C), mesh, 1)
    free = np.array(side.trace.fes.FreeDofs(), dtype=bool)
    ends = [v.nr for v in mesh.vertices if abs(v.point[1] - 1.0) < 1e-14 and v.point[0] in (0.0, 1.0)]
    assert len(ends) == 2 and free[ends].all()
    assert set(side.trace.gamma_dofs) >= set(ends)


def test_the_lift_carries_the_far_displacement_only():
    scene = patch.patch_scene(C, 0.03)
    mesh = block_mesh(3, 2)
    model = MODELS["membranes"]
    side = model.side_for(scene, mesh, 2)
    F, lift = model.load(side, scene, 1)
    fes = side.trace.fes
    free = np.array(fes.FreeDofs(), dtype=bool)
    assert np.all(lift[free] == 0.0)
    gf = ngsolve.GridFunction(fes)
    gf.vec.FV().NumPy()[:] = lift
    assert gf(mesh(0.4, 2.0)) == pytest.approx(-0.03, rel=1e-14)
    assert F.shape == (side.ndof,) and np.abs(F).max() > 0.0


@pytest.mark.parametrize("kwargs, key", [(dict(delta=0.0), "delta"), (dict(delta=np.nan), "delta"),
                                         (dict(c=(-1.0, 1.0)), "c1"), (dict(c=(1.0, 0.0)), "c2")])
def test_bad_data_is_one_line_naming_the_key(kwargs, key):
    with pytest.raises(InputError) as err:
        patch.patch_scene(**kwargs)
    assert key in str(err.value) and "\n" not in str(err.value)
