"""The side-operator cache of a sweep: shared sides are built once, rows are unchanged."""
import numpy as np
import pandas as pd
import pytest

from infsup_contact.discretization.segment.interface import SEGMENT
from infsup_contact.errors import InputError
from infsup_contact.models.membranes import MEMBRANES
from infsup_contact.solvers.side_cache import SideCache, side_keys
from infsup_contact.solvers.infsup import beta_rows_all
from infsup_contact.solvers.request import MeshOptions


class _Counting:
    """A model that counts its side-operator builds."""

    def __init__(self):
        self.builds = 0
        self.name = "counting"

    def side_operator(self, mesh, k):
        self.builds += 1
        return MEMBRANES.side_operator(mesh, k)

    def gamma(self, family="structured", **options):
        """The request's Γ (the model contract): the membranes'."""
        return MEMBRANES.gamma(family, **options)

    def subdomain_mesh(self, family, n, side, **mesh_kwargs):
        return MEMBRANES.subdomain_mesh(family, n, side, **mesh_kwargs)


def test_pairs_sharing_a_side_build_it_once_and_drop_it_after_its_last_use():
    model, cache = _Counting(), SideCache()
    pairs = [(4, 4), (5, 4), (6, 4), (5, 5)]
    cache.expect(model, "structured", 1, pairs)
    distinct = {key for p in pairs for key in side_keys(model, "structured", 1, *p)}
    for p in pairs:
        cache.pair(model, "structured", 1, *p)
    assert model.builds == len(distinct) == 5  # Ω1 with N1 = 4, 5, 6; Ω2 with N2 = 4, 5
    assert len(cache) == 0  # every expected use consumed: nothing kept


def test_beta_rows_of_a_sweep_take_shared_sides_from_the_cache():
    model, pairs = _Counting(), [(4, 4), (5, 4), (6, 4)]
    cache = SideCache.for_sweep(model, "structured", 1, pairs)
    for p in pairs:
        beta_rows_all("structured", 1, *p, cases=["T3"], norms=["L2"], model=model, side_cache=cache)
    assert model.builds == 4  # Ω1 with N1 = 4, 5, 6 and Ω2 with N2 = 4 once


def test_unannounced_pairs_are_built_and_not_kept():
    model, cache = _Counting(), SideCache()
    cache.pair(model, "structured", 1, 3, 3)
    cache.pair(model, "structured", 1, 3, 3)
    assert model.builds == 4 and len(cache) == 0


def test_seeds_are_distinct_sides():
    keys = [side_keys(MEMBRANES, "perturbed", 2, 5, 4, MeshOptions(seed=s, alpha=0.2)) for s in (0, 1)]
    assert not set(keys[0]) & set(keys[1])
    assert side_keys(MEMBRANES, "structured", 2, 5, 4)[1] == side_keys(MEMBRANES, "structured", 2, 7, 4)[1]


def test_cached_sweep_gives_the_rows_of_fresh_builds_bitwise():
    pairs = [(6, 4), (4, 4), (5, 4)]
    cache = SideCache()
    cache.expect(MEMBRANES, "perturbed", 2, pairs, MeshOptions(seed=1, alpha=0.2))
    kw = dict(cases=["T3", "R5.4"], multiplier_meshes=("omega2", "union"), c_pairs=((1.0, 1.0), (1.0, 10.0)),
              mesh=MeshOptions(seed=1, alpha=0.2))
    cached = pd.DataFrame([r for p in pairs for r in beta_rows_all("perturbed", 2, *p, side_cache=cache, **kw)])
    fresh = pd.DataFrame([r for p in pairs for r in beta_rows_all("perturbed", 2, *p, **kw)])
    cols = [c for c in fresh.columns if not c.startswith("t_")]
    pd.testing.assert_frame_equal(cached[cols], fresh[cols], check_exact=True)


def test_pairs_repeating_g_h_reuse_its_grams_bitwise_and_read_only():
    """G_h = the trace of Ω2 repeats in N:N and N+1:N; on the tetrahedra's triangle faces the H Gram
    (a Richardson-extrapolated series) is then computed once, and the rows equal fresh ones bit for bit."""
    from infsup_contact.models.membranes3d import MEMBRANES3D

    pairs, mesh = [(3, 3), (4, 3)], MeshOptions(element="tet")
    kw = dict(cases=["T3", "DUAL"], norms=["H", "L2"], model=MEMBRANES3D, mesh=mesh)
    cache = SideCache.for_sweep(MEMBRANES3D, "structured", 1, pairs, mesh)
    cached = pd.DataFrame([r for p in pairs for r in beta_rows_all("structured", 1, *p, side_cache=cache, **kw)])
    assert cache.grams.hits == 4  # the second pair: 2 cases × 2 norms
    fresh = pd.DataFrame([r for p in pairs for r in beta_rows_all("structured", 1, *p, **kw)])
    cols = [c for c in fresh.columns if not c.startswith("t_")]
    pd.testing.assert_frame_equal(cached[cols], fresh[cols], check_exact=True)
    G, _ = next(iter(cache.grams._grams.values()))
    with pytest.raises(ValueError):
        G[0, 0] = 1.0  # shared by later pairs: read-only


def test_gram_cache_forgets_the_oldest_beyond_its_bound():
    from infsup_contact.discretization.spaces import registry
    from infsup_contact.solvers.side_cache import GramCache

    def ask(grams, x):
        return grams.gram(SEGMENT, "T3", 2, x, registry.case_space("T3", 2, x, SEGMENT), "L2", "logkernel")

    grams = GramCache(max_bytes=5 * 8 * 5 ** 2)  # five Grams of T3, k = 2 on 3 cells (5 × 5)
    partitions = [np.array([0.0, 0.2 + 0.01 * i, 0.6, 1.0]) for i in range(7)]
    for x in partitions:
        ask(grams, x)
    assert len(grams) == 5 and grams._bytes == grams.max_bytes  # the two oldest forgotten
    ask(grams, partitions[-1])
    ask(grams, partitions[0])
    assert grams.hits == 1  # the newest was kept, the oldest was not
    ask(grams, np.linspace(0.0, 1.0, 6))  # 9 × 9: above a quarter of the bound, not kept
    assert len(grams) == 5


@pytest.mark.parametrize("x1,x2,choice,expected", [
    ([0, .5, 1], [0, .25, .5, .75, 1], "omega2", [0, .25, .5, .75, 1]),
    ([0, .5, 1], [0, .25, .5, .75, 1], "omega1", [0, .5, 1]),
    ([0, 1 / 3, 2 / 3, 1], [0, .5, 1], "union", [0, 1 / 3, .5, 2 / 3, 1]),
])
def test_partition_choice(x1, x2, choice, expected):
    assert np.array_equal(SEGMENT.multiplier_partition(np.array(x1), np.array(x2), choice), expected)


def test_partition_choice_names_the_allowed_values():
    with pytest.raises(InputError, match="multiplier_mesh.*omega2, omega1, union"):
        SEGMENT.multiplier_partition(np.array([0, 1.0]), np.array([0, 1.0]), "both")


def test_the_sweeps_face_grams_stay_in_their_parity_blocks_and_rows_are_unchanged(monkeypatch):
    """A β_h request takes its face Grams in parity blocks (GramCache under deferred_assembly):
    the pencils read the blocks and the kernel's scaling the L² diagonal, so no dense G is formed
    on the split route, and every row is the one of the eager route (G formed at once, every
    consumer reading it)."""
    from infsup_contact.la import face_parity
    from infsup_contact.models.membranes3d import MEMBRANES3D
    from infsup_contact.solvers.infsup import beta_table
    from infsup_contact.solvers.request import BetaRequest

    def request():
        return BetaRequest(family="structured", k=2, n1=3, n2=3, cases=("R5.2", "DUAL-Q9"), model=MEMBRANES3D)

    from infsup_contact.discretization.face.norms import tensor

    assembled = []
    real = face_parity.assemble
    monkeypatch.setattr(face_parity, "assemble", lambda *a: assembled.append(1) or real(*a))
    kron = tensor.KronParityGram.dense.func
    monkeypatch.setattr(tensor.KronParityGram, "dense", property(lambda g: assembled.append(2) or kron(g)))
    lazy = pd.DataFrame(beta_table(request()))
    assert not assembled  # neither space's H Gram was assembled, nor R5.2's L² Gram formed
    monkeypatch.setattr(face_parity, "deferred_assembly", __import__("contextlib").nullcontext)
    monkeypatch.setattr("infsup_contact.solvers.side_cache.deferred_assembly", __import__("contextlib").nullcontext)
    eager = pd.DataFrame(beta_table(request()))
    assert assembled  # the eager route assembles them
    cols = [c for c in lazy.columns if not c.startswith("t_")]
    pd.testing.assert_frame_equal(lazy[cols], eager[cols], check_exact=True)


class _Gate:
    """An interface whose Grams wait at a barrier of two: two threads inside ``gram`` at once pass
    it, one alone times out (``passed``); ``independent`` is what it says of every space."""

    def __init__(self, independent):
        import threading

        self.barrier, self.passed, self.calls = threading.Barrier(2, timeout=0.5), [], 0
        if independent is not None:
            self.gram_independent = lambda space: independent

    def partition_key(self, partition):
        return tuple(partition)

    def gram(self, space, norm, h_route="logkernel"):
        import threading

        self.calls += 1
        try:
            self.barrier.wait()
            self.passed.append(True)
        except threading.BrokenBarrierError:
            self.passed.append(False)
        return np.eye(2), {"n_max": 0}


@pytest.mark.parametrize("independent, together", [(True, True), (False, False), (None, False)])
def test_gram_cache_computes_only_independent_grams_side_by_side(independent, together):
    """Grams the interface calls independent are computed by two threads at once; any other (or an
    interface that says nothing) one at a time: the second waits until the first is stored."""
    from concurrent.futures import ThreadPoolExecutor

    from infsup_contact.solvers.side_cache import GramCache

    gate, grams = _Gate(independent), GramCache()
    with ThreadPoolExecutor(2) as pool:
        out = list(pool.map(lambda case: grams.gram(gate, case, 2, (0.0, 1.0), None, "H", "logkernel"), ["a", "b"]))
    assert gate.calls == 2 and all(gate.passed) == together and len(grams) == 2
    assert all(G.flags.writeable is False for G, _ in out)
    assert grams.gram(gate, "a", 2, (0.0, 1.0), None, "H", "logkernel")[0] is out[0][0] and gate.calls == 2  # kept


def test_gram_cache_keeps_the_first_of_two_equal_grams_made_at_once():
    """Two threads asking the same independent Gram at once both compute it; the first stored is
    the one both get and the one kept."""
    from concurrent.futures import ThreadPoolExecutor

    from infsup_contact.solvers.side_cache import GramCache

    gate, grams = _Gate(True), GramCache()
    with ThreadPoolExecutor(2) as pool:
        out = list(pool.map(lambda _: grams.gram(gate, "a", 2, (0.0, 1.0), None, "H", "logkernel"), range(2)))
    assert gate.calls == 2 and all(gate.passed) and len(grams) == 1
    assert out[0][0] is out[1][0]


def test_the_face_says_its_tensor_spaces_grams_are_independent_and_its_cellwise_ones_are_not():
    """The square's tensor spaces sum their own series (face/norms/tensor.py); its cellwise spaces
    share the series of their piece space (face/norms/cellwise.py: a module's state)."""
    from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
    from infsup_contact.discretization.face.shapes.square import SQUARE
    from infsup_contact.discretization.spaces import registry

    part = TensorPartition(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    said = {case: SQUARE.gram_independent(registry.case_space(case, 2, part, SQUARE))
            for case in ("T3", "R5.2", "T4", "DUAL", "DUAL-Q9", "DUAL-Q9-ALL", "TDUAL-Q9", "PWLIN-Q9")}
    assert said == {"T3": True, "R5.2": True, "T4": True, "DUAL": True,
                    "DUAL-Q9": False, "DUAL-Q9-ALL": False, "TDUAL-Q9": False, "PWLIN-Q9": False}
