"""The vectorised sine coefficients of the triangle face spaces (face_triangle_norms) against the
per-cell loop they replace (kept here as the reference route :func:`_sine_coefficients_loop`):
every family (s = 0, 1, 2; continuous or not; vanishing on ∂Γ or not; dual bases) on uniform,
graded and interleaved-width partitions; and the partial H Grams by both routes."""
import numpy as np
import pytest

from infsup_contact.discretization.face.norms import triangles as ftn
from infsup_contact.discretization.face.spaces.triangles import TriangleSpace
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition

FAMILIES = [  # (s, continuous, vanish, dual)
    (0, False, False, False), (1, False, False, False), (2, False, False, False),
    (1, True, False, False), (1, True, True, False), (2, True, False, False), (2, True, True, False),
    (1, True, False, True), (1, True, True, True), (2, True, False, True), (2, True, True, True)]
PARTITIONS = {
    "uniform": TensorPartition(np.linspace(0, 1, 5), np.linspace(0, 1, 4)),
    "graded": TensorPartition(np.array([0.0, 0.3, 0.5, 1.0]), np.array([0.0, 0.2, 0.7, 1.0])),
    # equal widths that are not adjacent: every shape is a sub-grid I × J with gaps
    "interleaved": TensorPartition(np.array([0.0, 0.2, 0.5, 0.7, 1.0]), np.array([0.0, 0.25, 0.4, 0.65, 0.8, 1.0])),
}


def _sine_coefficients_loop(space, m, n_max, q=None, shapes=None):
    """The per-cell loop of face_triangle_norms before vectorisation (reference route): every
    cell (i, j) and triangle, c = 2 Σ_ab R_ab trig_ab, the dual matrix applied per triangle,
    scattered into the global functions."""
    n = np.arange(1, n_max + 1, dtype=float)
    m = np.asarray(m, dtype=float)
    xs, ys = np.asarray(space.breakpoints.xs, float), np.asarray(space.breakpoints.ys, float)
    dofs = space._dofs
    out = np.zeros((space.dim, len(m), n_max))
    shapes = {} if shapes is None else shapes
    blocks = {}
    for i in range(len(xs) - 1):
        hx = xs[i + 1] - xs[i]
        sx, cx = np.sin(m * np.pi * xs[i]), np.cos(m * np.pi * xs[i])
        for j in range(len(ys) - 1):
            hy = ys[j + 1] - ys[j]
            sy, cy = np.sin(n * np.pi * ys[j]), np.cos(n * np.pi * ys[j])
            trig = {("c", "c"): np.outer(sx, sy), ("c", "s"): np.outer(sx, cy),
                    ("s", "c"): np.outer(cx, sy), ("s", "s"): np.outer(cx, cy)}
            for tri, upper in enumerate((False, True)):
                key = (round(hx, 14), round(hy, 14), upper)
                if key not in shapes:
                    qq = ftn.coefficient_points(max(n_max, int(m.max())), hx + hy, space.s) if q is None else q
                    shapes[key] = ftn._Shape(hx, hy, upper, space.s, n, qq)
                if key not in blocks:
                    blocks[key] = shapes[key].integrals(m)
                R = blocks[key]
                c = 2.0 * sum(R[ab] * trig[ab][None] for ab in trig)
                g = dofs[i, j, tri]
                if space.dual:
                    c = np.tensordot(space._dual_matrix(int(space.live_mask(g))), c, axes=(1, 0))
                keep = g >= 0
                out[g[keep]] += c[keep]
    return out


def _close(a, b, rtol=1e-13):
    assert a.shape == b.shape
    assert np.abs(a - b).max() <= rtol * np.abs(b).max()


@pytest.mark.parametrize("part", sorted(PARTITIONS))
@pytest.mark.parametrize("s,continuous,vanish,dual", FAMILIES)
def test_vectorised_coefficients_are_the_loop(part, s, continuous, vanish, dual):
    """Both routes, all m ≤ 20 in two uneven blocks sharing the shape cache, n ≤ 20."""
    space = TriangleSpace(PARTITIONS[part], s, continuous, vanish, dual)
    shapes_new, shapes_old = {}, {}
    for m in (np.arange(1, 8), np.arange(8, 21)):
        new = ftn.sine_coefficients_chunk(space, m, 20, shapes=shapes_new)
        _close(new, _sine_coefficients_loop(space, m, 20, shapes=shapes_old))
    assert shapes_new.keys() == shapes_old.keys()


@pytest.mark.parametrize("s,continuous,vanish,dual", [(0, False, False, False), (2, True, True, True)])
def test_fixed_rule_and_rows_beyond_n_max(s, continuous, vanish, dual):
    """A fixed Gauss order q, and m > n_max (the rule then follows max(m, n_max)): the same
    coefficients as the loop."""
    space = TriangleSpace(PARTITIONS["interleaved"], s, continuous, vanish, dual)
    m = np.array([3.0, 17.0, 40.0])
    _close(ftn.sine_coefficients_chunk(space, m, 12), _sine_coefficients_loop(space, m, 12))
    _close(ftn.sine_coefficients_chunk(space, m, 12, q=60), _sine_coefficients_loop(space, m, 12, q=60))


@pytest.mark.parametrize("part", ["graded", "square"])
@pytest.mark.parametrize("s,continuous,vanish,dual", [(1, False, False, False), (2, True, True, False),
                                                      (1, True, True, True)])
def test_partial_grams_by_both_routes(monkeypatch, part, s, continuous, vanish, dual):
    """S(n_max) as computed (vectorised coefficients in memory-sized blocks of m; on the square
    grid through its reflection and transposition) against the plain Σ C Cᵀ of the loop's
    coefficients in blocks of one row: SPD and equal to round-off."""
    grid = PARTITIONS["graded"] if part == "graded" else TensorPartition(np.linspace(0, 1, 4), np.linspace(0, 1, 4))
    space = TriangleSpace(grid, s, continuous, vanish, dual)
    assert (ftn._symmetries(space)[1] is None) == (part == "graded")
    new = ftn.partial_gram(space, 48)
    assert ftn.chunk_rows(space, 48) == 48  # one block

    def loop(space, m, n_max, q=None, shapes=None, dofs_out=None, n_from=1):
        assert dofs_out is None and n_from == 1
        return _sine_coefficients_loop(space, m, n_max, q, shapes)

    monkeypatch.setattr(ftn, "_coefficients", loop)
    monkeypatch.setattr(ftn, "_symmetries", lambda space: (None, None))
    monkeypatch.setattr(ftn, "chunk_rows", lambda space, n_max: 1)
    old = ftn.partial_gram(space, 48)
    _close(new, old)
    assert np.linalg.eigvalsh(new).min() > 0


def test_chunk_rows_keep_the_budget():
    space = TriangleSpace(TensorPartition(np.linspace(0, 1, 25), np.linspace(0, 1, 25)), 2, True, False)
    for n_max in (16, 512, 4096):
        rows = ftn.chunk_rows(space, n_max)
        assert 1 <= rows <= n_max and (rows == 1 or space.dim * rows * n_max <= ftn._BUDGET)


@pytest.mark.parametrize("s,continuous,vanish,dual", [(1, False, False, False), (2, True, True, True)])
def test_coefficients_of_a_subset_of_dofs(s, continuous, vanish, dual):
    """The rows asked (any order) of the coefficients are those of every dof."""
    space = TriangleSpace(PARTITIONS["graded"], s, continuous, vanish, dual)
    m = np.arange(4, 11)
    full = ftn.sine_coefficients_chunk(space, m, 15)
    ask = np.random.default_rng(5).permutation(space.dim)[: space.dim // 2]
    _close(ftn._coefficients(space, m, 15, dofs_out=ask), full[ask])


@pytest.mark.parametrize("columns", [7, 64])
@pytest.mark.parametrize("s,continuous,vanish,dual", [(0, False, False, False), (2, True, True, True),
                                                      (1, True, False, False)])
def test_column_blocks_and_late_columns_are_the_loop(monkeypatch, columns, s, continuous, vanish, dual):
    """U and W U by blocks of columns n (uneven: 7 does not divide the columns; 64 leaves a short
    last block at n_max = 150), and the columns n ≥ n_from only (the transposition's half): the
    loop's coefficients, the same for every block width, bit for bit."""
    monkeypatch.setattr(ftn, "_COLUMNS", columns)
    space = TriangleSpace(PARTITIONS["interleaved"], s, continuous, vanish, dual)
    m = np.arange(30, 37, dtype=float)
    whole = _sine_coefficients_loop(space, m, 150)
    _close(ftn.sine_coefficients_chunk(space, m, 150), whole)
    late = ftn._coefficients(space, m, 150, n_from=41)
    _close(late, whole[:, :, 40:])
    monkeypatch.setattr(ftn, "_COLUMNS", 10 ** 6)  # one block: the same bits
    assert np.array_equal(ftn._coefficients(space, m, 150, n_from=41), late)
