"""Side operators and Gram matrices shared by the mesh pairs of one sweep (one process, e.g. one β_h batch).

A side operator (:mod:`infsup_contact.models.contract`) depends on its own mesh and k only,
and the mesh of Ω_i is addressed by (family, N_i, side, mesh parameters), never by the other
side's N (:func:`~infsup_contact.discretization.segment.meshes.subdomain_mesh`); the mesh
parameters are a frozen :class:`~.request.MeshOptions` and the request's Γ (None: the model's flat
one) is part of the address too, so that a sweep over two Γs never shares a side. So the pairs
(16, 16), (17, 16) and (24, 16) of one sweep share the operator of Ω2: of the 64 sides of
the β_h study's 32 pairs, 34 are distinct.

:class:`SideCache` builds each operator once. A sweep states its pairs up front
(:meth:`SideCache.expect`) and the cache drops an operator after its last expected use, so
it holds only the operators still to be reused; a pair it was not told of is built and not
kept. The operators are deterministic functions of their key, so a cached one is the one a
fresh build would give (the β_h rows are bitwise identical either way; tested). On a matching
pair (N1 = N2) Ω2's operator is built from Ω1's where the model offers it (``Model.mirror_side``:
the 3D bodies, whose mirror z → 2 − z maps one onto the other; K checked entry by entry, else a
factorization of its own); such an operator serves its pair only, so that the rows of every pair
are the same in a sweep and alone.

The Gram matrix G of a multiplier space in a norm of Γ depends on Γ, the space's definition
(case, k) and its partition G_h only — never on the bodies. The pairs of a sweep repeat
partitions: G_h = the trace of Ω2 is the same for N:N and N+1:N, for the matching and the
non-matching pair of one N2, for every (c1, c2). On the faces' triangles the H Gram is a
Richardson-extrapolated double sine series, most of a row's cost, so it is built once per
(Γ, case, k, G_h, norm, route).

:class:`GramCache` keeps each Gram (and its ``info``) read-only, so that no consumer can change
what the next pair will be given; the computation is deterministic, so a cached Gram is
bit for bit the one a fresh call would give (tested). It holds at most :data:`MAX_BYTES` of
matrices and forgets the oldest first. Spaces run side by side (:mod:`.side_by_side`) ask it
from two threads: Grams are computed one at a time (a lock), so that the series the spaces of one
G_h share (``gamma.gram_session``, a module's state) is never written by two threads at once;
only those the interface calls independent (``gamma.gram_independent``) are computed beside others.
"""
from __future__ import annotations

import contextlib
import threading
from collections import Counter, OrderedDict

import numpy as np

from .. import progress
from ..la.face_parity import ParityGram, deferred_assembly
from .request import NO_OPTIONS, MeshOptions


def side_keys(model, family: str, k: int, n1: int, n2: int, mesh: MeshOptions = NO_OPTIONS, gamma=None) -> list:
    """The cache keys of the two sides of the pair (N1, N2): Ω1 with N1, Ω2 with N2; ``mesh`` (frozen,
    hashable) and the request's Γ ``gamma`` (an Interface, frozen; None: the flat one) are part of
    each key as they are."""
    return [(model, family, int(k), int(n), side, mesh, gamma) for n, side in ((n1, 1), (n2, 2))]


class SideCache:
    """Side operators by (model, family, k, N, side, mesh options, Γ), each built once."""

    def __init__(self):
        self._ops = {}
        self._uses_left = Counter()
        self.grams = GramCache()  # the sweep's Grams (the pairs repeat G_h)

    @classmethod
    def for_sweep(cls, model, family: str, k: int, pairs, mesh: MeshOptions = NO_OPTIONS,
                  gamma=None) -> "SideCache":
        """A cache told to expect the pairs of one sweep (:meth:`expect`)."""
        cache = cls()
        cache.expect(model, family, k, pairs, mesh, gamma)
        return cache

    def expect(self, model, family: str, k: int, pairs, mesh: MeshOptions = NO_OPTIONS, gamma=None) -> None:
        """Announce that :meth:`pair` will be asked for each (N1, N2) in ``pairs`` (on Γ ``gamma``)."""
        for n1, n2 in pairs:
            self._uses_left.update(side_keys(model, family, k, n1, n2, mesh, gamma))

    def pair(self, model, family: str, k: int, n1: int, n2: int, mesh: MeshOptions = NO_OPTIONS,
             gamma=None, checked: bool = False) -> list:
        """[side operator of Ω1 (N1 segments on Γ), side operator of Ω2 (N2)], on the request's Γ
        ``gamma`` (None: the model's flat one). The arguments are a validated request's
        (:class:`~.request.BetaRequest`; ``checked``: the mesh builder does not check them again)
        or checked by the mesh builder."""
        key1, key2 = side_keys(model, family, k, n1, n2, mesh, gamma)
        # NGSolve in one thread at a time: building two sides side by side in threads aborted the
        # process (its meshing and assembly are not thread-safe); the parallel work is inside a side
        # (a body's parity parts, PARDISO's threads) and, on a matching pair, side 1's factorization
        # beside side 2's mesh and stiffness (Model.matching_pair)
        mirror = n1 == n2 and getattr(model, "mirror_side", None) is not None
        if mirror and getattr(model, "matching_pair", None) is not None and key1 not in self._ops:
            progress.note(f"sides 1 and 2 (N1=N2={n1}): mesh, stiffness; side 1's factorization beside side 2's "
                          "mesh and stiffness, side 1 mirrored")
            sides = list(model.matching_pair(self._mesh(key1, checked), lambda: self._mesh(key2, checked), k))
            self._keep(key1, sides[0])
            self._use(key2)
        else:
            side1 = self._get(key1, checked=checked)
            sides = [side1, self._get(key2, mirror_of=side1 if mirror else None, checked=checked)]
        return sides[0].trace.gamma.paired(sides)  # a Γ coupled by projection ties the two

    def _mesh(self, key, checked: bool = False):
        """The mesh of ``key``'s side (the model's builder, with the request's options and Γ)."""
        model, family, k, n, side, mesh, gamma = key
        kwargs = dict(mesh.kwargs(), checked=True) if checked else mesh.kwargs()
        if gamma is not None:  # the request's Γ, the builder's own argument (Model.subdomain_mesh)
            kwargs["gamma"] = gamma
        # the model contract takes the options as keywords: unpacked here, and only here
        return model.subdomain_mesh(family, n, side, **kwargs)

    def _keep(self, key, op) -> None:
        """Keep ``op`` for the uses of ``key`` still announced (:meth:`expect`), count this one."""
        if self._uses_left[key] > 1:  # more uses announced: keep it for them
            self._uses_left[key] -= 1
            self._ops[key] = op
        else:
            self._uses_left.pop(key, None)

    def _get(self, key, mirror_of=None, checked: bool = False):
        """The operator of ``key``, cached or built; ``mirror_of``: side 1 of a matching pair, which
        a model with ``mirror_side`` turns into side 2 where a mirror maps the bodies (checked);
        ``checked``: the request checked the mesh arguments (:meth:`pair`)."""
        model, family, k, n, side, mesh, gamma = key
        mirror = getattr(model, "mirror_side", None) if mirror_of is not None else None
        if mirror is not None:
            # always the mirror on a matching pair, never kept for another pair: each pair's rows
            # stay a function of the pair (a cached side is the one a fresh build gives, bitwise)
            progress.note(f"side {side} of 2 (N{side}={n}): mesh, stiffness, side 1 mirrored")
            op = mirror(mirror_of, self._mesh(key, checked), k)
            self._use(key)
            return op
        op = self._ops.pop(key, None)
        if op is None:
            progress.note(f"side {side} of 2 (N{side}={n}): mesh, stiffness, factorization")
            op = model.side_operator(self._mesh(key, checked), k)
        self._keep(key, op)
        return op

    def _use(self, key) -> None:
        """Count one use of ``key`` served without the cache (the cached operator, if any, stays
        for the uses still announced)."""
        if self._uses_left[key] > 1:
            self._uses_left[key] -= 1
        else:
            self._uses_left.pop(key, None)
            self._ops.pop(key, None)

    def __len__(self) -> int:
        return len(self._ops)


MAX_BYTES = 64 * 2**20
"""Bound on the cached matrices' memory (bytes): a small share of any job's memory estimate."""


class GramCache:
    """Grams by (Γ, case, k, partition key, norm, H route), each computed once."""

    def __init__(self, max_bytes: int = MAX_BYTES):
        self._grams = OrderedDict()
        self._bytes = 0
        self.max_bytes = int(max_bytes)
        self.hits = 0
        self._lock = threading.RLock()  # the Grams whose series spaces share: one at a time
        self._table = threading.Lock()  # the table itself, held for a look-up or a store only

    def gram(self, gamma, case, k: int, partition, space, norm: str, h_route: str) -> tuple:
        """``gamma.gram(space, norm, h_route=h_route)``, from the cache when an equal
        (Γ, case, k, G_h, norm, route) was asked before. ``case`` must identify the space's
        definition (its registry entry or an unregistered spec, a triple). Not cached: an unhashable Γ or case, a Gram
        that is not a dense array or above a quarter of :attr:`max_bytes`. A Gram summed in
        parity blocks comes as its :class:`~infsup_contact.la.face_parity.ParityGram`, assembled
        where a consumer reads it densely (:func:`~infsup_contact.la.face_parity.deferred_assembly`).

        Safe from several threads (spaces side by side, :mod:`.side_by_side`): Grams are computed
        one at a time, except those the interface calls independent of every other space's
        (``gamma.gram_independent(space)``: the face's tensor spaces, numpy alone, no shared series),
        which are computed beside any other (k = 2, N = 16: 7 of 12 spaces; two threads asking
        the same one at once would both compute it, the same bits, and the first stored is kept)."""
        try:
            key = (gamma, case, int(k), gamma.partition_key(partition), norm, h_route)
            hash(key)
        except TypeError:
            return gamma.gram(space, norm, h_route=h_route)
        hit = self._lookup(key)
        if hit is not None:
            return hit
        independent = getattr(gamma, "gram_independent", None)
        with contextlib.nullcontext() if independent is not None and independent(space) else self._lock:
            hit = self._lookup(key)  # made meanwhile by the thread that held the lock
            if hit is not None:
                return hit
            progress.note(f"Gram matrix G, norm {norm}")
            with deferred_assembly():  # a Gram summed in parity blocks stays in them until read densely
                G, info = gamma.gram(space, norm, h_route=h_route)
        return self._store(key, G, info)

    def _lookup(self, key):
        with self._table:
            hit = self._grams.get(key)
            if hit is not None:
                self._grams.move_to_end(key)
                self.hits += 1
            return hit

    def _store(self, key, G, info) -> tuple:
        if not isinstance(G, (np.ndarray, ParityGram)) or 4 * G.nbytes > self.max_bytes:
            return G, info
        for held in (G.blocks if isinstance(G, ParityGram) else (G,)):
            held.setflags(write=False)  # shared by later pairs: nobody may change it
        with self._table:
            if key in self._grams:  # stored meanwhile by another thread: the same bits
                return self._grams[key]
            self._grams[key] = (G, info)
            self._bytes += G.nbytes
            while self._bytes > self.max_bytes:
                _, (old, _) = self._grams.popitem(last=False)
                self._bytes -= old.nbytes
        return G, info

    def __len__(self) -> int:
        return len(self._grams)
