"""β_h of the 3D membranes with the contact face Γ = (0,1)²×{1} (issue 28): the kernel against
the dimension argument and an independent count from 1D ranks, β_h > 0 where there is no
kernel, β_h against the full saddle-point pencil, and the command line."""
import io

import numpy as np
import pandas as pd
import pytest

from helpers.cli import run_in_process
from infsup_contact.discretization.gamma.coupling import coupling_matrix
from infsup_contact.discretization.segment.multipliers import make_space
from infsup_contact.discretization.spaces.registry import case_space, common_ids, SPACES
from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.models import make_model
from infsup_contact.solvers.side_cache import SideCache
from infsup_contact.solvers.infsup import beta_rows, saddle_point_beta
from infsup_contact.contact.contact import contact_qp
from infsup_contact.solvers.request import MeshOptions

MODEL = make_model("membranes3d")


def rows_of(k, n1, n2, element="hex", **kw):
    return pd.DataFrame(beta_rows("structured", k, n1, n2, model=MODEL, mesh=MeshOptions(element=element), **kw))


def tensor_kernel(space, partitions, k) -> int:
    """dim ker Bᵀ from 1D ranks: μ ⊥ W_i = W_i^x ⊗ W_i^y ⟺ (C_i^x ⊗ C_i^y)ᵀ μ = 0 with the 1D L² pairings
    C_i^x of the multiplier factor and the 1D trace (continuous P_k vanishing at the ends), so
    ker = (U1x⊗U1y + U2x⊗U2y)^⊥, U = ranges, and (A⊗B) ∩ (C⊗D) = (A∩C) ⊗ (B∩D)."""
    def pairing(factor, breaks):
        w = make_space(breaks, k, True, True)
        x, q = SEGMENT.quadrature(SEGMENT.common_refinement(breaks, factor.breakpoints), k + factor.degree)
        return (factor.evaluate(x) * q[:, None]).T @ w.evaluate(x)

    def rank(A):
        return np.linalg.matrix_rank(A, tol=1e-10 * max(np.abs(A).max(), 1e-300)) if A.size else 0

    r, c = {}, {}
    for d, (factor, attr) in enumerate(zip(space.factors, ("xs", "ys"))):
        C = [pairing(factor, getattr(p, attr)) for p in partitions]
        r[d] = [rank(Ci) for Ci in C]
        c[d] = r[d][0] + r[d][1] - rank(np.hstack(C))
    return space.dim - (r[0][0] * r[1][0] + r[0][1] * r[1][1] - c[0] * c[1])


@pytest.mark.parametrize("k", [1, 2])
@pytest.mark.parametrize("n1,n2", [(2, 2), (3, 3), (3, 4), (2, 3)])
def test_kernel_is_the_dimension_count(k, n1, n2):
    frame = rows_of(k, n1, n2)
    sides = SideCache().pair(MODEL, "structured", k, n1, n2, MeshOptions(element="hex"))
    parts = [s.trace.partition for s in sides]
    assert set(frame.case) == set(common_ids(k))
    for case, rows in frame.groupby("case"):
        row = rows.iloc[0]
        assert (rows.kernel_decision == "clear").all()
        # the dimension argument max(dim M − dim(W1 + W2), 0) is proven: never lost
        assert row.structural_kernel_dim == max(row.dim_M - row.dim_W, 0) <= row.kernel_dim
        if n1 == n2:
            assert row.kernel_dim == row.structural_kernel_dim, case
        gamma = sides[0].trace.gamma
        space = case_space(case, k, gamma.multiplier_partition(*parts), gamma)
        assert row.kernel_dim == tensor_kernel(space, parts, k), case
        if row.kernel_dim == 0:
            assert (rows.beta > 0).all() and (rows.beta == rows.smallest_nonzero).all()
        else:
            assert (rows.beta == 0).all() and (rows.smallest_nonzero > 0).all()


def test_continuous_multipliers_without_end_condition_have_a_growing_kernel():
    """R5.2's face analogue Q_k on matching n × n grids: dim M − dim W = (nk+1)² − (nk−1)² = 4nk."""
    for n in (2, 3, 4):
        for k in (1, 2):
            row = rows_of(k, n, n, cases=["R5.2"], norms=("L2",)).iloc[0]
            assert row.kernel_dim == 4 * n * k


@pytest.mark.slow_first  # the largest 3D β tests: started first under xdist (tests/conftest.py)
@pytest.mark.parametrize("k", [1, 2])
@pytest.mark.parametrize("n1,n2", [(2, 2), (3, 3), (3, 4)])
def test_tetrahedra(k, n1, n2):
    """On triangles the Lagrange cases are P_s spaces (face_triangles). The count is a lower
    bound; it is the kernel on matching meshes except for discontinuous P_s with s ≤ k − 2
    (Thm 4's analogue, modes beyond the count: test_face_triangles); on the non-matching (3, 4)
    pair discontinuous P_1 (Rem 5.4's analogue, k = 2) has one mode beyond it too."""
    frame = rows_of(k, n1, n2, element="tet")
    assert (frame.kernel_decision == "clear").all()
    assert (frame.kernel_dim >= frame.structural_kernel_dim).all()
    extra = frame.case.map(lambda c: SPACES[c].lagrange == (False, False) and SPACES[c].degree(k) <= k - 2)
    if n1 == n2:
        assert (frame[~extra].kernel_dim == frame[~extra].structural_kernel_dim).all()
    assert (frame[frame.kernel_dim == 0].beta > 0).all()


@pytest.mark.parametrize("element,n1,n2,case", [("hex", 2, 3, "T3"), ("tet", 2, 2, "T5"), ("tet", 3, 2, "T4")])
def test_beta_agrees_with_the_saddle_point_pencil(element, n1, n2, case):
    """The Γ-reduced route (Schur complements, Γ last) against the dense pencil of the whole
    system [[A, Bᵀ], [B, 0]] x = σ [[A, 0], [0, G]] x (solvers.infsup.saddle_point_beta)."""
    k = 2
    sides = SideCache().pair(MODEL, "structured", k, n1, n2, MeshOptions(element=element))
    gamma = sides[0].trace.gamma
    space = case_space(case, k, gamma.multiplier_partition(*(s.trace.partition for s in sides)), gamma)
    Bs = [coupling_matrix(s.trace, space, k) for s in sides]
    A, B, _ = contact_qp(sides, Bs, [np.zeros(s.ndof) for s in sides])  # the assembled pencil's blocks
    B = B.toarray()
    frame = rows_of(k, n1, n2, element=element, cases=[case])
    for norm, row in frame.set_index("norm").iterrows():
        G = gamma.gram(space, norm)[0]
        assert saddle_point_beta(A, B, G) == pytest.approx(row.beta, rel=1e-8)


def test_cli_beta_3d_and_its_refusals():
    code, out, err = run_in_process(["beta", "--model", "membranes3d", "--case", "T3", "--k", "2", "--N1", "3",
                                     "--N2", "3", "--element", "hex"])
    assert code == 0, err
    frame = pd.read_csv(io.StringIO(out))
    assert list(frame.norm) == ["H", "L2"] and (frame.element == "hex").all() and (frame.beta > 0).all()
    for argv, needle in ((["--model", "membranes", "--element", "hex"], "--element"),
                         (["--model", "membranes3d", "--element", "prism"], "element"),
                         (["--model", "membranes3d", "--family", "unstructured", "--element", "hex"], "element")):
        base = ["beta", "--case", "T3", "--k", "1", "--N1", "3", "--N2", "3"]
        code, out, err = run_in_process(base[:-2] + (argv if "--N2" in argv else argv + base[-2:]))
        assert code == 2 and len(err.strip().splitlines()) == 1 and needle in err, (argv, err)


def test_verdict_for_the_3d_model():
    code, out, err = run_in_process(["verdict", "--model", "membranes3d", "--case", "R5.2", "--k", "1", "--N", "2",
                                     "3", "4", "--expect", "unstable"])
    assert code == 0, err
    row = pd.read_csv(io.StringIO(out)).iloc[0]
    assert row.verdict == "UNSTABLE" and row.kernel_dim == 4 * 4 * 1
    code, out, err = run_in_process(["verdict", "--case", "T3", "--k", "1", "--N", "2", "3", "4", "--element", "hex"])
    assert code == 2 and "--element" in err


def test_a_3d_request_too_large_for_the_memory_is_refused_before_computing():
    code, out, err = run_in_process(["beta", "--model", "membranes3d", "--case", "T3", "--k", "2", "--N1", "96",
                                     "--N2", "96"])
    assert code == 2 and "N1" in err and "memory" in err and not out


def test_exported_3d_system_gives_the_same_verdict(tmp_path):
    """export → verdict --system (the foreign-system route, its own β_h solver) agrees with verdict."""
    common = ["--case", "T3", "--k", "1", "--N", "2", "3", "4", "--model", "membranes3d", "--element", "tet"]
    code, out, err = run_in_process(["export", *common, "--out", str(tmp_path)])
    assert code == 0, err
    code, out, err = run_in_process(["verdict", "--system", out.strip()])
    assert code == 0, err
    foreign = pd.read_csv(io.StringIO(out)).iloc[0]
    code, out, err = run_in_process(["verdict", *common])
    direct = pd.read_csv(io.StringIO(out)).iloc[0]
    assert foreign.verdict == direct.verdict and foreign.kernel_dim == direct.kernel_dim == 0
    assert foreign.beta_min == pytest.approx(direct.beta_min, rel=1e-5)
    assert foreign.beta_max == pytest.approx(direct.beta_max, rel=1e-5)


@pytest.mark.parametrize("element", ["hex", "tet"])
def test_every_schur_route_agrees_in_3d(element):
    """The Γ-last nested dissection (graph based, no 2D assumption), the solves route and MKL
    PARDISO's partial factorization give one Schur complement, equal to the reference
    K_ΓΓ − K_ΓI K_II⁻¹ K_IΓ; PARDISO's solves are backward stable: ‖K x − b‖ / (‖K‖ ‖x‖ + ‖b‖)
    within (3n + 1) ε (a Cholesky solve, Higham Thm 10.4), not an absolute 1e-10 (on the hexahedra
    ‖x‖ ≈ 3e6: the residual is 1e-12, round-off of that size)."""
    from infsup_contact.models.membranes3d import side_operator, subdomain_mesh
    from infsup_contact.models.contract import schur_by_solves

    mesh = subdomain_mesh("structured", 3, 1, element=element)
    sides = [side_operator(mesh, 2, route=r) for r in ("nested", "solves", "pardiso")]
    ref = schur_by_solves(sides[0])
    for side in sides:
        np.testing.assert_allclose(side.schur, ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    rhs = np.linspace(-1.0, 1.0, sides[0].ndof)
    K, x = sides[0].stiffness, sides[2].solve(rhs)
    norm_k = abs(K).sum(axis=1).max()
    backward = np.abs(K @ x - rhs).max() / (norm_k * np.abs(x).max() + np.abs(rhs).max())
    assert backward <= (3 * len(rhs) + 1) * np.finfo(float).eps


def test_auto_route_takes_pardiso_on_a_face_and_superlu_on_the_segment():
    """Above the solves route's work limit a face takes PARDISO, the segment SuperLU's nested
    dissection (both measured in la/schur.gamma_factorization's docstring)."""
    from infsup_contact.discretization.segment.meshes import subdomain_mesh as mesh_2d
    from infsup_contact.models.membranes import side_operator as side_2d
    from infsup_contact.models.membranes3d import side_operator, subdomain_mesh
    from infsup_contact.la.schur import SOLVES_MAX_WORK, gamma_factorization

    face = side_operator(subdomain_mesh("structured", 8, 1), 2, route="solves")
    segment = side_2d(mesh_2d("structured", 64, 1), 2, route="solves")
    for side, expected in ((face, "pardiso"), (segment, "nested")):
        n_gamma = len(side.trace.gamma_dofs)
        assert side.ndof * n_gamma > SOLVES_MAX_WORK
        fac = gamma_factorization(side.stiffness, n_gamma, "auto", gamma_dim=side.trace.gamma.dim)
        assert fac.route == expected


def test_pardiso_refuses_a_matrix_that_is_not_positive_definite():
    import scipy.sparse as sp
    from infsup_contact.la.pardiso import PardisoError, gamma_schur

    diagonal = np.full(20, 2.0)
    diagonal[5] = -1.0
    indefinite = sp.csr_matrix(np.diag(diagonal) + np.diag([0.5] * 19, 1) + np.diag([0.5] * 19, -1))
    with pytest.raises(PardisoError):
        gamma_schur(indefinite, 2)


@pytest.mark.parametrize("n, n_gamma", [(2, 1), (3, 2), (9, 1), (12, 3), (40, 7)])
def test_pardiso_schur_on_small_matrices_equals_dense_elimination(n, n_gamma):
    """Tiny interiors (below pardiso.MIN_INTERIOR, where MKL reads out of bounds) and larger ones
    give the same S as dense elimination."""
    import scipy.sparse as sp
    from infsup_contact.la.pardiso import gamma_schur

    D = np.diag(np.full(n, 4.0)) - np.diag(np.ones(n - 1), 1) - np.diag(np.ones(n - 1), -1)
    I, G = slice(0, n - n_gamma), slice(n - n_gamma, n)
    ref = D[G, G] - D[G, I] @ np.linalg.solve(D[I, I], D[I, G])
    np.testing.assert_allclose(gamma_schur(sp.csr_matrix(D), n_gamma), ref, rtol=0, atol=1e-13)
