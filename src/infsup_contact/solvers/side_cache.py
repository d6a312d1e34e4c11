"""Side operators shared by the mesh pairs of one sweep (one process, e.g. one β_h batch).

A side operator (:mod:`infsup_contact.models.contract`) depends on its own mesh and k only,
and the mesh of Ω_i is addressed by (family, N_i, side, mesh parameters), never by the other
side's N (:func:`~infsup_contact.discretization.segment.meshes.subdomain_mesh`); the mesh
parameters are a frozen :class:`~.request.MeshOptions`. So the pairs
(16, 16), (17, 16) and (24, 16) of one sweep share the operator of Ω2: of the 64 sides of
the β_h study's 32 pairs, 34 are distinct.

:class:`SideCache` builds each operator once. A sweep states its pairs up front
(:meth:`SideCache.expect`) and the cache drops an operator after its last expected use, so
it holds only the operators still to be reused; a pair it was not told of is built and not
kept. The operators are deterministic functions of their key, so a cached one is the one a
fresh build would give (the β_h rows are bitwise identical either way; tested).
"""
from __future__ import annotations

from collections import Counter

from .request import NO_OPTIONS, MeshOptions


def side_keys(model, family: str, k: int, n1: int, n2: int, mesh: MeshOptions = NO_OPTIONS) -> list:
    """The cache keys of the two sides of the pair (N1, N2): Ω1 with N1, Ω2 with N2; ``mesh`` (frozen,
    hashable) is part of each key as it is."""
    return [(model, family, int(k), int(n), side, mesh) for n, side in ((n1, 1), (n2, 2))]


class SideCache:
    """Side operators by (model, family, k, N, side, mesh options), each built once."""

    def __init__(self):
        self._ops = {}
        self._uses_left = Counter()

    @classmethod
    def for_sweep(cls, model, family: str, k: int, pairs, mesh: MeshOptions = NO_OPTIONS) -> "SideCache":
        """A cache told to expect the pairs of one sweep (:meth:`expect`)."""
        cache = cls()
        cache.expect(model, family, k, pairs, mesh)
        return cache

    def expect(self, model, family: str, k: int, pairs, mesh: MeshOptions = NO_OPTIONS) -> None:
        """Announce that :meth:`pair` will be asked for each (N1, N2) in ``pairs``."""
        for n1, n2 in pairs:
            self._uses_left.update(side_keys(model, family, k, n1, n2, mesh))

    def pair(self, model, family: str, k: int, n1: int, n2: int, mesh: MeshOptions = NO_OPTIONS) -> list:
        """[side operator of Ω1 (N1 segments on Γ), side operator of Ω2 (N2)]. The arguments are
        a validated request's (:class:`~.request.BetaRequest`) or checked by the mesh builder."""
        sides = [self._get(key) for key in side_keys(model, family, k, n1, n2, mesh)]
        return sides[0].trace.gamma.paired(sides)  # a Γ coupled by projection ties the two

    def _get(self, key):
        op = self._ops.pop(key, None)
        if op is None:
            model, family, k, n, side, mesh = key
            # the model contract takes the options as keywords: unpacked here, and only here
            op = model.side_operator(model.subdomain_mesh(family, n, side, **mesh.kwargs()), k)
        if self._uses_left[key] > 1:  # more uses announced: keep it for them
            self._uses_left[key] -= 1
            self._ops[key] = op
        else:
            self._uses_left.pop(key, None)
        return op

    def __len__(self) -> int:
        return len(self._ops)
