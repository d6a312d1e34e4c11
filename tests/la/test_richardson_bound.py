"""The H^{-1/2}_00 series' stated error is a bound (la/richardson.py): the Richardson
steps are measured in the Gram's own metric, which bounds the relative change of every eigenvalue
of a pencil with it (Loewner order), with a one-level look-ahead on the steps' ratio. Checked on
the face rows whose tail is slow (T5 and R5.2 at k = 2: jumps or boundary values, tail n^{-2})
against the same pencil with a series carried much further."""
import numpy as np
import pytest
import scipy.linalg as sla
from scipy.special import zeta

from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.face.norms.tensor import gram_h_face
from infsup_contact.la.richardson import extrapolate, lookahead_bound, relative_step
from infsup_contact.models import MODELS
from infsup_contact.solvers.interface_operator import combine_terms, interface_terms
from infsup_contact.solvers.side_cache import SideCache
from infsup_contact.discretization.spaces import registry
from infsup_contact.solvers import infsup
from infsup_contact.solvers.request import MeshOptions


def test_lookahead_states_the_step_while_it_shrinks_and_no_bound_when_it_stops():
    assert lookahead_bound(1e-6, None) == 1e-6                 # unconfirmed: the step itself
    assert lookahead_bound(1e-6, 8e-6) == 1e-6                 # ρ = 1/8: the rest is δ/7 < δ
    assert lookahead_bound(1e-6, 1.5e-6) == pytest.approx(4e-6)  # ρ = 2/3: 2 δ ρ/(1 − ρ) = 4δ
    assert lookahead_bound(1e-6, 1e-6) == np.inf and lookahead_bound(2e-6, 1e-6) == np.inf
    assert lookahead_bound(0.0, 1e-6) == 0.0


def test_relative_step_is_the_loewner_distance():
    """For E = ε R the step is ε exactly; for a generic E it is the largest |eigenvalue| of (E, R)
    (both routes: the dense standard form and Lanczos)."""
    rng = np.random.default_rng(3)
    for n in (30, 1600):
        X = rng.standard_normal((n, n))
        R = X @ X.T / n + np.diag(np.logspace(-4, 0, n))      # cond ~ 1e4: the bottom matters
        assert relative_step(1e-3 * R, R) == pytest.approx(1e-3, rel=1e-8)
        E = 1e-6 * (X + X.T)
        if n < 100:
            assert relative_step(E, R) == pytest.approx(np.abs(sla.eigh(E, R, eigvals_only=True)).max(), rel=1e-8)
        assert relative_step(E, R) >= np.abs(np.linalg.eigvalsh(E)).max() / np.linalg.eigvalsh(R).max()
    assert relative_step(np.eye(3), -np.eye(3)) == np.inf


@pytest.mark.parametrize("q", [1.5, 2.0, 2.5, 3.0, 5.0])
@pytest.mark.parametrize("rtol", [1e-4, 1e-9])
def test_the_stated_error_bounds_zeta_also_where_the_tail_is_slower_than_assumed(q, rtol):
    """ζ(q) = Σ n^{−q} extrapolated as if its tail were n^{−2}: its real tail n^{1−q} is slower
    for q < 3 (ρ = 2^{1−q}), faster above; the stated error bounds the real one either way."""
    G, info = extrapolate(lambda n: np.array([[np.sum(np.arange(1, n + 1) ** -q)]]), 2.0, 4, 2 ** 16, rtol)
    assert abs(G[0, 0] - zeta(q)) / zeta(q) <= info["nmax_rel_error"]
    assert info["capped"] == (info["nmax_rel_error"] > rtol)


@pytest.fixture(scope="module")
def face_sides():
    return SideCache().pair(MODELS["membranes3d"], "structured", 2, 6, 7, MeshOptions(element="hex"))


@pytest.mark.parametrize("case", ["T5", "R5.2"])
def test_stated_h_error_bounds_beta_against_a_series_carried_further(face_sides, case):
    """Every eigenvalue of (S, G) moves by at most the stated relative error, so β above the
    kernel (``smallest_nonzero``; β itself for T5) is within it of the converged pencil's."""
    row, = infsup.beta_rows("structured", 2, 6, 7, [case], norms=("H",), model=MODELS["membranes3d"],
                            side_cache=_cache(face_sides), mesh=MeshOptions(element="hex"))
    assert 0 < row["nmax_rel_error"] <= 1e-6
    gamma = face_sides[0].trace.gamma
    partition = gamma.multiplier_partition(*(s.trace.partition for s in face_sides), "omega2")
    space = registry.case_space(case, 2, partition, gamma)
    S = combine_terms(interface_terms([coupling_matrix(s.trace, space, 2) for s in face_sides], face_sides),
                      (1.0, 1.0))
    G, info = gram_h_face(space, rtol=1e-10, n_cap=2 ** 16)
    assert info["nmax_rel_error"] <= 1e-10
    ev = sla.eigh(S, G, eigvals_only=True)
    converged = np.sqrt(ev[row["kernel_dim"]])
    assert abs(row["smallest_nonzero"] - converged) / converged <= row["nmax_rel_error"]


def _cache(sides):
    """A side cache holding the fixture's two sides (no refactorization)."""
    cache = SideCache()
    cache.pair = lambda *a, **k: sides
    return cache


def test_block_steps_by_lanczos_are_the_dense_ones():
    """BlockOps above BLOCK_DENSE_MAX: Lanczos with L⁻¹ shared by the steps gives the largest
    |eigenvalue| of L⁻¹ E L⁻ᵀ to about the square of its residual tolerance (asserted at 1e-7) against the
    whole standard form's eigenvalues, block by block, the max over the blocks."""
    from infsup_contact.la import richardson

    rng = np.random.default_rng(3)
    grams, es = [], [[], []]
    for n in (40, 150, 200):
        X = rng.standard_normal((n, n))
        grams.append(X @ X.T + n * np.eye(n))
        for e in es:
            Y = rng.standard_normal((n, n)) * 1e-4
            e.append(Y + Y.T)
    got = richardson.BlockOps.rel_norms(es, grams)
    for e, g in zip(es, got):
        want = max(richardson._standard_form_norm(E, np.linalg.cholesky(R)) for E, R in zip(e, grams))
        assert g == pytest.approx(want, rel=1e-7)


def test_a_series_capped_at_its_first_extrapolation_states_that_step():
    """The first level with an extrapolation is measured only where the loop ends there (the cap):
    its stated error is then the size of that extrapolation in R's metric, as before."""
    from infsup_contact.la import richardson

    A = np.diag([1.0, 2.0, 3.0])
    B = np.array([[1.0, 0.2, 0.0], [0.2, 1.0, 0.1], [0.0, 0.1, 1.0]])

    def partial(n):
        return A + B / n ** 2 + B * B / n ** 3

    R, info = richardson.extrapolate(partial, 2.0, 8, 16, 1e-12)
    assert info["n_max"] == 16 and info["capped"]
    S8, S16 = partial(8), partial(16)
    T = S16 + (S16 - S8) / 3.0
    assert info["nmax_rel_error"] == pytest.approx(richardson.relative_step(T - S16, T), rel=1e-12)


def test_block_steps_side_by_side_are_the_serial_ones(monkeypatch):
    """BlockOps.rel_norms measures the blocks side by side (two workers): bit for bit the steps
    measured one block after the other (dense and Lanczos blocks)."""
    from infsup_contact.la import richardson, threaded

    rng = np.random.default_rng(5)
    grams, es = [], [[], []]
    for n in (60, 150, 210, 0):
        X = rng.standard_normal((n, n))
        grams.append(X @ X.T + n * np.eye(n))
        for e in es:
            Y = rng.standard_normal((n, n)) * 1e-4
            e.append(Y + Y.T)
    calls = []

    def side_by_side(fn, items):
        calls.append(1)
        return threaded.run_concurrently([lambda x=x: fn(x) for x in items], workers=2)
    monkeypatch.setattr(richardson, "concurrent_map", side_by_side)
    together = richardson.BlockOps.rel_norms(es, grams)
    monkeypatch.setattr(richardson, "concurrent_map", lambda fn, items: [fn(x) for x in items])
    serial = richardson.BlockOps.rel_norms(es, grams)
    assert calls and together == serial and all(np.isfinite(serial))
