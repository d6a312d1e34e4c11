"""The 3D bodies' symmetries in the factorization (issue 52, item 1): the parity route against the
general one on every element, the checks refusing a body that is not symmetric, the mirror of a
matching pair against a factorization of side 2, and β_h rows unchanged.

Tolerance: both routes compute the same S = K_ΓΓ − K_ΓI K_II⁻¹ K_IΓ in different elimination orders,
so they differ by round-off; they are compared to :data:`~infsup_contact.la.reflection.INVARIANCE_RTOL`
(1e-11 of max |S|), the level at which the pencils themselves treat two matrices as the same
(their reflection split drops blocks that small), far above the ~1e-15 the small bodies show and
far below any change a wrong permutation makes (an O(1) change of S)."""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd
import pytest
import scipy.sparse as sp

from infsup_contact.la import body_parity, pardiso
from infsup_contact.la.reflection import INVARIANCE_RTOL
from infsup_contact.models import body_symmetry, membranes3d as m3
from infsup_contact.models.membranes3d import MEMBRANES3D
from infsup_contact.solvers.infsup import beta_rows_all
from infsup_contact.solvers.request import MeshOptions
from infsup_contact.solvers.side_cache import SideCache

ROUTES = ("solves", "nested", "pardiso")
"""Dense solves, SuperLU's Γ-last LU (the route where PARDISO is missing), PARDISO's Schur mode."""
ELEMENTS = (("hex", 1, "parity 4"), ("hex", 2, "parity 4"), ("hex20", 2, "parity 4"),
            ("tet", 1, "parity 2"), ("tet", 2, "parity 2"))


def _general(monkeypatch, build):
    """``build()`` with the symmetries off (the general route, as before the parity route)."""
    with monkeypatch.context() as m:
        m.setattr(body_symmetry, "ENABLED", False)
        return build()


def _close(a, b) -> bool:
    return np.abs(a - b).max() <= INVARIANCE_RTOL * np.abs(b).max()


def _solves_agree(side, reference) -> bool:
    b = np.random.default_rng(1).standard_normal((side.ndof, 2))
    return _close(side.solve(b), reference.solve(b))


@pytest.mark.parametrize("route", ROUTES)
@pytest.mark.parametrize("element, k, parts", ELEMENTS)
def test_the_parity_route_gives_the_general_routes_side(monkeypatch, element, k, parts, route):
    if route == "pardiso" and not pardiso.available():
        pytest.skip("MKL PARDISO is not installed")
    body = m3.subdomain_mesh("structured", 3, 1, element=element)
    side = m3.side_operator(body, k, route=route)
    reference = _general(monkeypatch, lambda: m3.side_operator(body, k, route=route))
    assert (side.route, reference.route) == (parts, route)
    assert _close(side.schur, reference.schur) and _solves_agree(side, reference)
    # X = S⁻¹ from the parts' inverses, against the general route's (its own, or S inverted whole)
    assert _close(side.steklov, reference.steklov_inverse())


def test_the_tetrahedra_keep_the_diagonal_only():
    """The Kuhn tetrahedra: the square's axis reflections reverse their diagonals, the reflection
    in the diagonal x ↔ y (and in the other one, x ↔ 1 − y) maps them: two parts."""
    side = m3.side_operator(m3.subdomain_mesh("structured", 3, 1, element="tet"), 1)
    n_gamma = len(side.trace.gamma_dofs)
    found = {name: body_symmetry.permutation(side.signature, side.stiffness, n_gamma, T) is not None
             for name, T in (("x", body_symmetry.REFLECT_X), ("y", body_symmetry.REFLECT_Y),
                             ("point", body_symmetry.POINT), ("swap", body_symmetry.SWAP),
                             ("antiswap", body_symmetry.ANTISWAP))}
    assert not found["x"] and not found["y"] and not found["point"]
    assert found["swap"] != found["antiswap"]  # the one diagonal the generator cut along
    assert side.route == "parity 2"


@pytest.mark.parametrize("element", ("hex", "tet"))
def test_a_perturbed_body_keeps_the_general_route(element):
    side = m3.side_operator(m3.subdomain_mesh("perturbed", 3, 1, element=element), 1, route="solves")
    assert side.route == "solves"
    assert body_symmetry.involutions(side.signature, side.stiffness, len(side.trace.gamma_dofs)) is None


@pytest.mark.parametrize("element", ("hex", "tet"))
def test_the_smallest_bodies(monkeypatch, element):
    """N = 1 (k = 1: no free dof) keeps the general route; N = 2 (one interior dof, one on Γ, both
    fixed by every reflection: one part) gives the general route's S, and so does its mirror."""
    bodies = [m3.subdomain_mesh("structured", 1, s, element=element) for s in (1, 2)]
    side1 = m3.side_operator(bodies[0], 1)
    assert side1.ndof == 0 and side1.route == m3.mirror_side(side1, bodies[1], 1).route == "solves"
    bodies = [m3.subdomain_mesh("structured", 2, s, element=element) for s in (1, 2)]
    side1 = m3.side_operator(bodies[0], 1)
    mirrored = m3.mirror_side(side1, bodies[1], 1)
    reference = [_general(monkeypatch, lambda b=b: m3.side_operator(b, 1)) for b in bodies]
    assert (side1.route, mirrored.route) == ("parity 1", "mirror")
    assert _close(side1.schur, reference[0].schur) and _close(mirrored.schur, reference[1].schur)


def test_the_stiffness_check_refuses_a_permutation_that_does_not_commute():
    """The same nodes (the signature matches) and one stiffness entry K_0j = K_j0 moved by 1e-6 of
    max |K| (dof 0 off the plane x = 1/2): x → 1 − x no longer commutes with K and is refused, and
    the four parts with it (a symmetry the bump spares may still give two)."""
    side = m3.side_operator(m3.subdomain_mesh("structured", 3, 1), 1)
    n_gamma = len(side.trace.gamma_dofs)
    pi_x = body_symmetry.permutation(side.signature, side.stiffness, n_gamma, body_symmetry.REFLECT_X)
    assert pi_x is not None and pi_x[0] != 0
    K = side.stiffness.tolil()
    i, j = 0, int(sp.csr_matrix(side.stiffness)[0].indices[-1])
    bump = 1e-6 * np.abs(side.stiffness.data).max()
    K[i, j] += bump
    K[j, i] += bump
    K = K.tocsc()
    assert body_symmetry.permutation(side.signature, K, n_gamma, body_symmetry.REFLECT_X) is None
    pis = body_symmetry.involutions(side.signature, K, n_gamma)
    assert pis is None or len(pis) < 2


def test_the_parts_are_independent_calls():
    """A thread pool's map factorizes the parts side by side: the same S as one by one."""
    side = m3.side_operator(m3.subdomain_mesh("structured", 3, 1), 2, route="solves")
    n_gamma = len(side.trace.gamma_dofs)
    parts = body_parity.parity_parts(side.stiffness, n_gamma,
                                     body_symmetry.parity_bases(side.signature, side.stiffness, n_gamma))
    from infsup_contact.la import schur

    one = lambda Kc, ng: schur.gamma_factorization(Kc, ng, "nested", gamma_dim=2)  # noqa: E731
    serial = parts.factorize(one)[0]
    with ThreadPoolExecutor(2) as pool:
        threaded = parts.factorize(one, map=pool.map)[0]
    assert len(parts.parts) == 4 and sum(p.stiffness.shape[0] for p in parts.parts) == side.ndof
    assert np.array_equal(serial, threaded)


@pytest.mark.parametrize("element, k", (("hex", 2), ("tet", 1), ("hex20", 2)))
def test_side_2_of_a_matching_pair_is_side_1_mirrored(monkeypatch, element, k):
    bodies = [m3.subdomain_mesh("structured", 3, s, element=element) for s in (1, 2)]
    side1 = m3.side_operator(bodies[0], k)
    mirrored = m3.mirror_side(side1, bodies[1], k)
    direct = _general(monkeypatch, lambda: m3.side_operator(bodies[1], k))
    assert mirrored.route == "mirror"
    assert _close(mirrored.schur, direct.schur) and _solves_agree(mirrored, direct)


def test_no_mirror_between_bodies_that_are_not_images():
    """A perturbed pair (each body moved by its own draw) and a pair of different N: side 2 is
    factorized on its own."""
    bodies = [m3.subdomain_mesh("perturbed", 3, s) for s in (1, 2)]
    side1 = m3.side_operator(bodies[0], 1)
    assert m3.mirror_side(side1, bodies[1], 1).route != "mirror"
    other = m3.side_operator(m3.subdomain_mesh("structured", 4, 2), 1, mirror_of=m3.side_operator(
        m3.subdomain_mesh("structured", 3, 1), 1))
    assert other.route != "mirror"


def test_the_cache_mirrors_matching_pairs_only():
    cache, mesh = SideCache(), MeshOptions(element="hex")
    assert [s.route for s in cache.pair(MEMBRANES3D, "structured", 1, 3, 3, mesh)][1] == "mirror"
    assert [s.route for s in cache.pair(MEMBRANES3D, "structured", 1, 4, 3, mesh)][1] != "mirror"


@pytest.mark.parametrize("element, k, n", (("hex", 2, 3), ("tet", 1, 4)))
def test_beta_rows_are_the_general_routes(monkeypatch, element, k, n):
    """β_h of a few spaces in both norms, a matching pair (parity parts and the mirror) against the
    general route: the same rows to round-off (β to 1e-9 relative: the pencils' round-off grows
    with their condition, kernel dimensions and decisions exactly)."""
    cases = ["T3", "R5.2"]
    args = ("structured", k, n, n, cases)
    kwargs = dict(norms=("H", "L2"), model=MEMBRANES3D, mesh=MeshOptions(element=element))
    new = pd.DataFrame(beta_rows_all(*args, **kwargs))
    old = pd.DataFrame(_general(monkeypatch, lambda: beta_rows_all(*args, **kwargs)))
    assert len(new) == len(old) == 4
    assert (new.kernel_dim == old.kernel_dim).all()
    np.testing.assert_allclose(new.beta.to_numpy(float), old.beta.to_numpy(float), rtol=1e-9, atol=0)


@pytest.mark.parametrize("element", ("hex", "tet"))
def test_k3_keeps_the_general_route(element):
    """k = 3: NGSolve's second edge function is odd about the edge's midpoint (∫ φ = 0, no centroid),
    and a reflection may reverse its sign: no permutation is sought, the body is factorized whole."""
    side = m3.side_operator(m3.subdomain_mesh("structured", 2, 1, element=element), 3)
    assert side.signature is None and side.route == "solves"


@pytest.mark.parametrize("element", ("hex", "hex20"))
def test_a_scene_side_keeps_the_general_route(monkeypatch, element):
    """A contact scene's side (``keep_factor``) is factorized whole even where the body is symmetric:
    the ledger's patch tests print round-off quantities, which must not move with a β_h speed-up;
    its S is the general route's, bit for bit."""
    from types import SimpleNamespace

    from infsup_contact.la import schur

    monkeypatch.setattr(schur, "SOLVES_MAX_WORK", 0)  # the large bodies' route (PARDISO, else SuperLU) at N = 3
    body = m3.subdomain_mesh("structured", 3, 1, element=element)
    assert m3.side_operator(body, 2).route == "parity 4"  # the β_h side of the same body: its parts
    scene = SimpleNamespace(supports=m3.FAR)
    side = m3.scene_side(scene, body, 2)
    reference = _general(monkeypatch, lambda: m3.scene_side(scene, body, 2))
    assert side.route == reference.route != "parity 4"
    assert np.array_equal(side.schur, reference.schur) and _solves_agree(side, reference)


def test_a_beta_side_drops_k_on_every_dof_and_its_load_is_the_scene_sides():
    """A β_h side (no solves) keeps no stiffness on every dof; given a scene's lift anyway, its
    load is assembled again: the scene side's load (same K, same lift)."""
    from types import SimpleNamespace

    body = m3.subdomain_mesh("structured", 2, 1)
    beta_side = m3.side_operator(body, 1)
    scene_side = m3.side_operator(body, 1, keep_factor=True)
    assert beta_side.stiffness_all is None and scene_side.stiffness_all is not None
    scene = SimpleNamespace(c1=2.0, c2=1.0, far_displacement=(0.1, -0.2))
    F_beta, lift_beta = m3.load(beta_side, scene, 0)
    F_scene, lift_scene = m3.load(scene_side, scene, 0)
    assert np.array_equal(lift_beta, lift_scene) and np.abs(lift_scene).max() > 0
    assert np.array_equal(F_beta, F_scene) and np.abs(F_scene).max() > 0
