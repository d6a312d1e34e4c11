"""The NGSolve producer (examples/producers/ngsolve/export.py): two separately meshed membranes
tied by NGSolve's ``ContactBoundary`` (μ (u2 − u1.Other()) on Ω2's Γ, the other side at the
closest point), run by the suite's own interpreter (NGSolve is one of its dependencies).
Checked against the mathematics: A SPD of the dimension the free dofs count; G the L² mass of
the basis the manifest describes (NGSolve's own basis read at Lagrange nodes); dim M_h the
space's count; B the exact mortar coupling of the described bases on matching meshes (NGSolve's
rule of order 4 on Ω2's segments is exact for μ φ there), its Ω2 block exact on non-matching
ones too, its Ω1 block off by the quadrature (u1 kinks inside Ω2's segments)."""
from __future__ import annotations

import sys

import numpy as np
import pytest

import helpers.producers as P

PYTHON = sys.executable  # the suite's interpreter: NGSolve is a dependency of the suite
SCRIPT = P.ROOT / "examples" / "producers" / "ngsolve" / "export.py"
if not P.python_has(PYTHON, "ngsolve"):
    pytest.skip(f"NGSolve is not importable by {PYTHON}: run `make env`", allow_module_level=True)

# id: (body degree k, multiplier degree s, continuous, vanishing at Γ's ends)
SPACES = {"T3-k1": (1, 1, True, True), "T3-k2": (2, 2, True, True), "R5.2-k1": (1, 1, True, False),
          "R5.2-k2": (2, 2, True, False), "T4-k2": (2, 0, False, False), "R5.4-k1": (1, 0, False, False),
          "R5.4-k2": (2, 1, False, False), "T5-k2": (2, 1, True, False)}
NS = (3, 4, 6)
CONTACT_ROUNDOFF = 4 * P.ROUNDOFF
"""Round-off of an entry of NGSolve's contact term relative to max |b|: its special elements
integrate at points mapped through the closest-point search on either side; measured ≤ 19 ε, and
105 ε for SurfaceL2 at N = 3 (on both bodies' blocks), so the producers' 64 ε with a factor 4."""
@pytest.fixture(scope="module")
def export(tmp_path_factory):
    """The manifest of one space and offset on NS, exported once per module run."""
    return P.export_once(tmp_path_factory, PYTHON, SCRIPT, NS)


def test_list_spaces():
    code, out, err = P.run_cli(PYTHON, SCRIPT, "--list-spaces")
    assert code == 0 and err == ""
    assert [line.split("\t")[0] for line in out.splitlines()] == list(SPACES)


@pytest.mark.parametrize("args, names", [
    (("--out", "OUT", "--space", "T3-k1", "--N", "4", "8", "--offset", "-4"), "--offset -4"),
    (("--out", "OUT", "--space", "Q9", "--N", "4"), "--space 'Q9'"),
    (("--out", "OUT", "--space", "T3-k1", "--N", "0", "4"), "--N 0"),
    (("--out", "OUT", "--space", "T3-k1", "--N", "4", "100000"), "--N 100000"),
    (("--out", "OUT", "--space", "T3-k1", "--N", "8", "4"), "increasing"),
    (("--out", "OUT", "--N", "4"), "--space"),
    (("--out", "FILE", "--space", "T3-k1", "--N", "4"), "not a directory"),
])
def test_bad_arguments_one_line_exit_2(tmp_path, args, names):
    P.check_refused(PYTHON, SCRIPT, tmp_path, args, names)


def _space(form: dict):
    """The SegmentSpace of a general form (its ``dofs`` number the functions)."""
    from infsup_contact.discretization.segment.multipliers import local_basis_space

    return local_basis_space(form["breakpoints"], form["degree"], np.asarray(form["dofs"]), form["coefficients"])


def _exact(lv: dict, n: int) -> np.ndarray:
    """∫_Γ μ_i φ_l (sign of the body) on the union of the partitions, Gauss exact for the
    degree: the exact mortar coupling of the described multipliers (row = its number) against
    the described traces (column = ``columns``)."""
    mult = _space(lv["multipliers"])
    out = np.zeros((mult.dim, n))
    for tr in lv["traces"]:
        phi = _space(tr)
        x, w = P.gauss_on_union(mult.breakpoints, phi.breakpoints)
        local = tr["sign"] * (mult.evaluate(x) * w[:, None]).T @ phi.evaluate(x)
        out[:, np.asarray(tr["columns"])] += local
    return out


def _counts(space: str, n1: int, n2: int) -> tuple:
    """(dim M_h, free dofs of Ω1, of Ω2): continuous P_s on N segments has sN + 1 functions
    (sN − 1 vanishing at Γ's ends), discontinuous (s + 1)N; P_k on n × n squares with u = 0 on
    three sides keeps the kn − 1 interior lattice columns on kn rows: kn (kn − 1)."""
    k, s, continuous, drop = SPACES[space]
    m = (s * n2 + (-1 if drop else 1)) if continuous else (s + 1) * n2
    return m, k * n1 * (k * n1 - 1), k * n2 * (k * n2 - 1)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("offset", [0, 1])
def test_dimensions_A_spd_G_mass(export, space, offset):
    """A = diag(K1, K2) SPD of the free dofs' dimension, dim M_h exact, G the described L² mass."""
    from infsup_contact.discretization.segment.norms import gram_l2

    for i, n in enumerate(NS):
        lv, A, B, G = P.read_level(export(space, offset), i)
        m, n1, n2 = _counts(space, n + offset, n)
        assert B.shape == (m, n1 + n2) and A.shape == (n1 + n2,) * 2 and G.shape == (m, m)
        assert not A[:n1, n1:].count_nonzero()  # the bodies are coupled through B only
        P.check_spd(A)
        M = gram_l2(_space(lv["multipliers"]))
        assert np.abs(G.toarray() - M).max() <= P.ROUNDOFF * np.abs(M).max()


@pytest.mark.parametrize("space", SPACES)
def test_B_is_the_exact_coupling_on_matching_meshes(export, space):
    """Offset 0: the rule of order 4 on Ω2's segments integrates μ φ (degree s + k ≤ 4) exactly and
    the closest point of a Gauss point is the point itself: B = the exact mortar coupling."""
    for i, n in enumerate(NS):
        lv, A, B, G = P.read_level(export(space, 0), i)
        exact = _exact(lv, B.shape[1])
        assert np.abs(B.toarray() - exact).max() <= CONTACT_ROUNDOFF * np.abs(exact).max()


@pytest.mark.parametrize("space", SPACES)
def test_non_matching_closest_point_quadrature(export, space):
    """Offset 1: B's Ω2 columns are still exact (μ and φ2 live on the same segments); its Ω1
    columns are not: u1.Other() kinks inside an Ω2 segment and the rule does not see it.
    ‖B1 − B1_exact‖_F / ‖B1_exact‖_F between 1e-3 and 0.5 (README: the measured distance per level)."""
    for i, n in enumerate(NS):
        lv, A, B, G = P.read_level(export(space, 1), i)
        n1 = _counts(space, n + 1, n)[1]
        exact, Bd = _exact(lv, B.shape[1]), B.toarray()
        assert np.abs(Bd[:, n1:] - exact[:, n1:]).max() <= CONTACT_ROUNDOFF * np.abs(exact).max()
        dist = np.linalg.norm(Bd[:, :n1] - exact[:, :n1]) / np.linalg.norm(exact[:, :n1])
        assert 1e-3 < dist < 0.5, dist


@pytest.mark.parametrize("space", ["T3-k2", "R5.4-k2", "R5.2-k1"])
def test_certifier_coupling_distance(export, space):
    """The manifest's ``traces`` let the certifier measure the distance itself: round-off on
    matching meshes, ours (the exact coupling above) to 1e-10 on non-matching ones."""
    for offset in (0, 1):
        for i, row in enumerate(P.beta_rows(export(space, offset))):
            lv, A, B, G = P.read_level(export(space, offset), i)
            exact = _exact(lv, B.shape[1])
            ours = np.linalg.norm(B.toarray() - exact) / np.linalg.norm(exact)
            theirs = float(row["coupling_distance"])
            if offset == 0:
                assert max(ours, theirs) <= 10 * CONTACT_ROUNDOFF
            else:
                assert theirs == pytest.approx(ours, rel=1e-10)


@pytest.mark.parametrize("space", ["T3-k1", "R5.4-k1", "T5-k2"])
def test_beta_matching_equals_beta_case(export, space):
    """Matching meshes: the same triangles, the exact coupling: NGSolve's L² β above the kernel
    equals ``beta --case`` (a basis change of the rows and columns leaves the pencil's eigenvalues)."""
    case, k = space.split("-k")
    for n, row in zip(NS, P.beta_rows(P.strip_manifest(export(space, 0), "L2"))):
        ref = float(P.suite_beta(case, int(k), n, n)["smallest_nonzero"])
        assert float(row["smallest_nonzero"]) == pytest.approx(ref, rel=1e-9)
