"""One PARDISO factorization for S and the solves (``pardiso.SchurFactor``, ``iparm[35] = 2``):
S equals the discarding route's (``gamma_schur``), A x = b is solved to round-off against SuperLU
(scipy ``spsolve``) on random SPD matrices from tiny (dense elimination below MIN_INTERIOR) to a
few thousand unknowns, and on a real face (membranes3d, the face patch scene) the kept factor's
solves equal those of the former route (a second, full factorization) and the contact solution
is unchanged."""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from infsup_contact.models import pardiso

pytestmark = pytest.mark.skipif(not pardiso.available(), reason="MKL PARDISO is not installed")


def random_spd(n: int, seed: int) -> sp.csr_matrix:
    """A sparse SPD matrix: R Rᵀ (about 8 entries a row) plus a positive diagonal."""
    rng = np.random.default_rng(seed)
    R = sp.random(n, n, density=min(1.0, 8.0 / n), random_state=rng)
    return sp.csr_matrix(R @ R.T + sp.diags(0.1 + rng.random(n)))


def rel(a, b) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


def backward_error(A, x, b) -> float:
    """‖A x − b‖ / (‖A‖ ‖x‖ + ‖b‖) in the max norms: round-off level for a stable solve."""
    norm_a = abs(A).sum(axis=1).max()
    return float(np.abs(A @ x - b).max() / (norm_a * np.abs(x).max() + np.abs(b).max()))


SIZES = [(1, 1), (2, 1), (2, 0), (5, 5), (3, 2), (pardiso.MIN_INTERIOR + 1, 1), (9, 0), (12, 4), (40, 10),
         (200, 30), (1000, 100), (2000, 150)]


@pytest.mark.parametrize("n,n_gamma", SIZES)
def test_schur_and_solves_against_scipy(n, n_gamma):
    A = random_spd(n, seed=n + 7 * n_gamma)
    factor = pardiso.SchurFactor(A, n_gamma)
    D = A.toarray()
    I, G = slice(0, n - n_gamma), slice(n - n_gamma, n)
    S_dense = D[G, G] - D[G, I] @ np.linalg.solve(D[I, I], D[I, G]) if n > n_gamma else D[G, G]
    assert factor.schur.shape == (n_gamma, n_gamma) and np.array_equal(factor.schur, factor.schur.T)
    if n_gamma:
        assert rel(factor.schur, S_dense) < 1e-12
        assert np.array_equal(factor.schur, pardiso.gamma_schur(A, n_gamma))  # the same S as before
    b = np.random.default_rng(n).standard_normal((n, 3))
    ref = spla.spsolve(sp.csc_matrix(A), b).reshape(n, 3)
    for _ in range(2):  # the factor is kept: solve twice, vectors and blocks
        x = factor.solve(b)
        assert x.shape == b.shape and rel(x, ref) < 1e-11
        assert all(backward_error(A, x[:, j], b[:, j]) < 1e-14 for j in range(3))
        assert rel(factor.solve(b[:, 1]), ref[:, 1]) < 1e-11
    factor.release()


def test_an_indefinite_matrix_is_refused_as_before():
    A = random_spd(40, 3).tolil()
    A[0, 0] = -1e3
    with pytest.raises(pardiso.PardisoError):
        pardiso.SchurFactor(sp.csr_matrix(A), 10)


@pytest.fixture(scope="module")
def face_sides():
    """The face patch scene's sides of one body, route "pardiso": the factor kept or freed."""
    from infsup_contact.models import make_model
    from infsup_contact.models import membranes3d
    from infsup_contact.study import face_patch
    from infsup_contact.study.scene_registry import FACE_PATCH

    model = make_model(FACE_PATCH.models[0])
    scene = face_patch.patch_scene()
    mesh = model.subdomain_mesh("structured", 4, 2, element="hex")
    supports = scene.supports
    kept, freed = (membranes3d.side_operator(mesh, 2, route="pardiso", dirichlet=supports, keep_factor=keep)
                   for keep in (True, False))
    F, _ = model.load(kept, scene, 1)
    return kept, freed, F


def test_on_a_face_the_kept_factor_solves_as_a_second_factorization(face_sides):
    """Backward stable like the full factorization and SuperLU; the solutions agree to what the
    conditioning allows (this stiffness is clamped on the far face only: cond(S) ≈ 3e4)."""
    kept, freed, F = face_sides
    A = kept.stiffness
    assert np.array_equal(kept.schur, freed.schur)
    rhs = np.column_stack([F, np.random.default_rng(0).standard_normal(len(F))])
    x_kept, x_freed, x_splu = kept.solve(rhs), freed.solve(rhs), spla.spsolve(A.tocsc(), rhs)
    for j in range(2):
        for x in (x_kept, x_freed, x_splu):
            assert backward_error(A, x[:, j], rhs[:, j]) < 1e-14
        assert rel(x_kept[:, j], x_freed[:, j]) < 1e-8 and rel(x_kept[:, j], x_splu[:, j]) < 1e-8
    x = kept.solve(F)  # a vector: the same factor again
    assert x.shape == F.shape and backward_error(A, x, F) < 1e-14 and rel(x, x_kept[:, 0]) < 1e-8


def _membrane_rows():
    from infsup_contact.discretization import registry
    from infsup_contact.study import face_patch

    return face_patch.face_patch_rows(registry.space_ids(), [2], [(3, 4)])


def _elastic_rows():
    from infsup_contact.discretization import registry
    from infsup_contact.study import elastic_face_patch

    return elastic_face_patch.elastic_face_patch_rows(registry.space_ids(), [1], [(2, 3)])


@pytest.mark.parametrize("patch_rows", [_membrane_rows, _elastic_rows], ids=["membranes3d", "elastic3d"])
def test_the_face_patch_contact_solution_is_unchanged(monkeypatch, patch_rows):
    """The scenes' sides keep their factor (scene_side); forcing route "pardiso" on these small
    pairs, the patch rows equal those with the factor freed (the former route) to round-off."""
    from infsup_contact.models import schur
    from infsup_contact.study.face_patch import PASS_RTOL

    real = schur.gamma_factorization
    kept = []

    def rows(keep):
        def forced(A, n_gamma, route="auto", gamma_dim=1, keep_factor=False):
            kept.append(keep_factor and keep)
            return real(A, n_gamma, "pardiso", gamma_dim, keep_factor and keep)
        monkeypatch.setattr(schur, "gamma_factorization", forced)
        return patch_rows()

    new = rows(True)
    assert kept and all(kept)  # every side of the scene asked to keep its factor
    old = rows(False)
    assert [r["case"] for r in new] == [r["case"] for r in old] and new
    for a, b in zip(new, old):
        assert a["passes"] == b["passes"] == a["predicted"], (a, b)
        # A passing row's errors are round-off (~1e-12) and the two routes' round-off differs
        # with the code path: R5.4, k = 2 gave λ errors 1.5e-12 / 2.7e-12 under OpenBLAS SkylakeX
        # and MKL's default branch, equal to 1e-12 under Haswell or MKL_CBWR=COMPATIBLE
        # (tests/test_machines.py). Two decades below PASS_RTOL they cannot flip ``passes``.
        for key in ("lambda_max_rel_error", "u_max_rel_error"):
            assert a[key] == pytest.approx(b[key], rel=1e-6, abs=1e-2 * PASS_RTOL), (key, a, b)
