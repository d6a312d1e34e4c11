"""Side operators shared by the mesh pairs of one sweep (one process, e.g. one β_h batch).

A side operator (:mod:`infsup_contact.models.contract`) depends on its own mesh and k only,
and the mesh of Ω_i is addressed by (family, N_i, side, mesh parameters), never by the other
side's N (:func:`~infsup_contact.discretization.segment.meshes.subdomain_mesh`). So the pairs
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



def side_keys(model, family: str, k: int, n1: int, n2: int, **mesh_kwargs) -> list:
    """The cache keys of the two sides of the pair (N1, N2): Ω1 with N1, Ω2 with N2."""
    kw = tuple(sorted(mesh_kwargs.items()))
    return [(model, family, int(k), int(n), side, kw) for n, side in ((n1, 1), (n2, 2))]


class SideCache:
    """Side operators by (model, family, k, N, side, mesh parameters), each built once."""

    def __init__(self):
        self._ops = {}
        self._uses_left = Counter()

    @classmethod
    def for_sweep(cls, model, family: str, k: int, pairs, **mesh_kwargs) -> "SideCache":
        """A cache told to expect the pairs of one sweep (:meth:`expect`)."""
        cache = cls()
        cache.expect(model, family, k, pairs, **mesh_kwargs)
        return cache

    def expect(self, model, family: str, k: int, pairs, **mesh_kwargs) -> None:
        """Announce that :meth:`pair` will be asked for each (N1, N2) in ``pairs``."""
        for n1, n2 in pairs:
            self._uses_left.update(side_keys(model, family, k, n1, n2, **mesh_kwargs))

    def pair(self, model, family: str, k: int, n1: int, n2: int, **mesh_kwargs) -> list:
        """[side operator of Ω1 (N1 segments on Γ), side operator of Ω2 (N2)]. The arguments are
        a validated request's (:class:`~.request.BetaRequest`) or checked by the mesh builder."""
        return [self._get(key, model, family, k, **mesh_kwargs)
                for key in side_keys(model, family, k, n1, n2, **mesh_kwargs)]

    def _get(self, key, model, family, k, **mesh_kwargs):
        op = self._ops.pop(key, None)
        if op is None:
            n, side = key[3], key[4]
            op = model.side_operator(model.subdomain_mesh(family, n, side, **mesh_kwargs), k)
        if self._uses_left[key] > 1:  # more uses announced: keep it for them
            self._uses_left[key] -= 1
            self._ops[key] = op
        else:
            self._uses_left.pop(key, None)
        return op

    def __len__(self) -> int:
        return len(self._ops)
