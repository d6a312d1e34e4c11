"""The worst mode of (4.5) (solvers/modes.py): an eigenvector of S m = β² G m for β_h² (its Rayleigh
quotient, against S and G rebuilt here), a kernel vector of Bᵀ where β_h = 0, the same on the dense
and the Lanczos route, the tetrahedra's T4 checkerboard, and nothing computed without the flag."""
import numpy as np
import pytest

from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.la import bottom
from infsup_contact.models import MODELS
from infsup_contact.solvers import modes as modes_mod
from infsup_contact.solvers.infsup import beta_table
from infsup_contact.solvers.interface_operator import combine_terms, interface_terms
from infsup_contact.solvers.modes import mode_on_gamma, normalized
from infsup_contact.solvers.request import BetaRequest, MeshOptions, options_of
from infsup_contact.solvers.side_cache import SideCache

EPS = np.finfo(float).eps


def worst(request):
    found = []
    rows = beta_table(request, modes=found)
    assert len(found) == len(rows)
    for row, mode in zip(rows, found):  # one mode per row, same keys, same order
        assert {k: row[k] for k in mode.keys} == mode.keys and mode.beta == row["beta"]
    return rows, found


def pencil(request, mode):
    """S and G of the mode's row, rebuilt from the sides, the couplings and the Gram (no eigensolver)."""
    sides = SideCache().pair(request.model, request.family, request.k, request.n1, request.n2, request.mesh,
                             request.gamma)
    couplings = [coupling_matrix(s.trace, mode.space, request.k) for s in sides]
    S = combine_terms(interface_terms(couplings, sides), (mode.keys["c1"], mode.keys["c2"]))
    G = sides[0].trace.gamma.gram(mode.space, mode.keys["norm"])[0]
    return np.asarray(S), np.asarray(G), couplings


def rayleigh_gap(request, mode):
    """|mᵀSm/mᵀGm − β²| / λ_max(S, G), and the bound it must meet: 100 m ε (the pencil's round-off
    level n ε λ_max of solvers/kernel.py, with room for the Cholesky reduction by G)."""
    import scipy.linalg as sla

    S, G, _ = pencil(request, mode)
    m = mode.vector
    lam_max = sla.eigh(S, G, eigvals_only=True)[-1]
    return abs(m @ S @ m / (m @ G @ m) - mode.beta ** 2) / lam_max, 100 * len(m) * EPS


@pytest.mark.parametrize("family", ["structured", "perturbed"])
@pytest.mark.parametrize("large", [False, True])
def test_rayleigh_quotient_is_beta_squared(monkeypatch, large, family):
    """T3 and R5.2 (no kernel on 6:7), k = 2, both norms, on the dense route and on the Lanczos
    route (DENSE_MAX_M lowered: bottom_pencil asked for its vector; the structured meshes take the
    reflections' split route, the perturbed ones the plain one)."""
    if large:
        monkeypatch.setattr(bottom, "DENSE_MAX_M", 5)
    request = BetaRequest(family, 2, 6, 7, ("T3", "R5.2"), ("omega2",), ((1.0, 1.0), (1.0, 4.0)), ("H", "L2"))
    rows, found = worst(request)
    for mode in found:
        assert not mode.in_kernel and mode.beta > 0
        gap, bound = rayleigh_gap(request, mode)
        assert gap <= bound, (mode.keys, gap, bound)


def test_the_two_routes_give_the_same_mode(monkeypatch):
    request = BetaRequest("structured", 2, 6, 7, ("T3", "R5.2"), ("omega2",), ((1.0, 1.0),), ("H", "L2"))
    dense = worst(request)[1]
    monkeypatch.setattr(bottom, "DENSE_MAX_M", 5)
    large = worst(request)[1]
    for a, b in zip(dense, large):
        # a simple eigenvalue: the same vector up to its sign, fixed by the normalization
        assert np.max(np.abs(mode_on_gamma(a)[1] - mode_on_gamma(b)[1])) < 1e-9, a.keys


@pytest.mark.parametrize("family", ["structured", "perturbed"])
@pytest.mark.parametrize("large", [False, True])
def test_unstable_mode_is_in_the_kernel_of_bt(monkeypatch, large, family):
    """R5.4 on matching meshes, k = 1 (Remark 5.4: a kernel): ‖B_iᵀ m‖ at round-off, relative to
    ‖B_i‖ ‖m‖ (bound: 100 (rows + m) ε, the SVD's backward error with room)."""
    if large:
        monkeypatch.setattr(bottom, "DENSE_MAX_M", 5)
    request = BetaRequest(family, 1, 8, 8, ("R5.4",), ("omega2",), ((1.0, 1.0),), ("H", "L2"))
    rows, found = worst(request)
    for row, mode in zip(rows, found):
        assert row["kernel_dim"] >= 1 and row["beta"] == 0.0 and mode.in_kernel
        _, _, couplings = pencil(request, mode)
        for B in couplings:
            B = np.asarray(B)
            residual = np.linalg.norm(B.T @ mode.vector) / (np.linalg.norm(B, 2) * np.linalg.norm(mode.vector))
            assert residual <= 100 * (sum(B.shape)) * EPS, residual


def test_tetrahedra_t4_checkerboard_alternates_between_neighbours():
    """T4 at k = 2 on the tetrahedra's Kuhn triangles (P_0 per triangle): the one kernel mode is
    ±1, of opposite sign on every two triangles that share an edge."""
    request = BetaRequest("structured", 2, 3, 3, ("T4",), ("omega2",), ((1.0, 1.0),), ("L2",),
                          model=MODELS["membranes3d"], mesh=MeshOptions(element="tet"))
    rows, (mode,) = worst(request)
    assert rows[0]["kernel_dim"] == 1 and mode.in_kernel
    corners = mode.space.triangles()  # (nt, 3, 2): the Kuhn triangles of G_h
    centroids = corners.mean(axis=1)
    mu = normalized(mode.space.evaluate(centroids) @ mode.vector)
    assert np.allclose(np.abs(mu), 1.0, atol=1e-10)
    edges = {}
    for t, (a, b, c) in enumerate(np.round(corners, 12)):
        for e in ((a, b), (b, c), (c, a)):
            edges.setdefault(tuple(sorted(map(tuple, e))), []).append(t)
    pairs = [ts for ts in edges.values() if len(ts) == 2]
    assert len(pairs) >= len(corners)  # the interior edges: every triangle has neighbours
    for s, t in pairs:
        assert mu[s] * mu[t] < 0, (s, t, mu[s], mu[t])
    # the sampled mode (what --worst-mode writes) holds the same values at the centroids (sixths of a cell)
    x, sampled = mode_on_gamma(mode)
    at = [np.flatnonzero(np.all(np.abs(x - c) < 1e-12, axis=1)) for c in centroids]
    assert all(len(i) == 1 for i in at)
    assert np.allclose(sampled[np.concatenate(at)], mu, atol=1e-10)


def test_normalization_fixes_scale_and_sign():
    v = np.array([0.5, -2.0, 1.0, 2.0 * (1 - 1e-12)])
    out = normalized(v)
    assert np.max(np.abs(out)) == pytest.approx(1.0) and out[1] == 1.0  # the first of the tied peaks
    assert np.array_equal(normalized(-v), out)
    with pytest.raises(ValueError):
        normalized(np.zeros(3))


def test_beta_alone_computes_no_vector(monkeypatch):
    """Without ``modes`` no vector is asked for: the kernel decision keeps none on the dense route
    and mode_vector is never called."""
    def refuse(*args, **kwargs):
        raise AssertionError("a vector computed without --worst-mode")

    monkeypatch.setattr(modes_mod, "mode_vector", refuse)
    request = BetaRequest("structured", 1, 4, 4, ("R5.4", "T3"), ("omega2",), ((1.0, 1.0),), ("H",))
    assert len(beta_table(request)) == 2


ARC = dict(gamma="arc", radius=2.0, coupling="projection")
CYLINDER = dict(gamma="cylinder", radius=2.0, coupling="exact")


@pytest.mark.parametrize("model, options, case, k, n", [
    ("membranes", {}, "T3", 2, 4), ("elastic", {}, "T3", 1, 4), ("membranes", ARC, "R5.2", 1, 5),
    ("membranes3d", {"element": "hex"}, "T3", 1, 3), ("membranes3d", {"element": "tet"}, "T3", 1, 3),
    ("membranes3d", {"element": "hex20"}, "Q8", 2, 2), ("membranes3d", dict(CYLINDER, element="hex"), "T3", 1, 3),
    ("elastic3d", {"element": "hex"}, "T3", 1, 2), ("elastic3d", {"element": "tet"}, "T3", 1, 2),
])
def test_every_model_gives_the_eigenvector(model, options, case, k, n):
    """Segment and face models, scalar and vector bodies, flat and curved Γ: the mode's Rayleigh
    quotient is β_h², and its samples cover Γ (a segment: x; a face: x and y) with max |μ_h| = 1."""
    mesh, gamma = options_of(MODELS[model], **options)
    request = BetaRequest("structured", k, n, n, (case,), ("omega2",), ((1.0, 1.0),), ("H", "L2"),
                          model=MODELS[model], mesh=mesh, gamma=gamma)
    rows, found = worst(request)
    for mode in found:
        gap, bound = rayleigh_gap(request, mode)
        assert gap <= bound, (model, options, mode.keys, gap)
        x, mu = mode_on_gamma(mode)
        assert np.ndim(x) == (1 if MODELS[model].dim == 2 else 2)
        assert np.max(np.abs(mu)) == pytest.approx(1.0) and np.isclose(np.max(mu), 1.0)
