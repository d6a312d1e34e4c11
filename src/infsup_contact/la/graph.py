"""The graph of a stiffness pattern the Γ-last nested dissection works on (:mod:`.ordering`).

:class:`Twins` merges indistinguishable interior nodes (equal closed neighbourhoods: the dofs
of one vertex, one edge, one face of a higher-order element) into one weighted node;
:class:`Graph` is the quotient graph of the interior, its breadth-first labels and levels;
:func:`segment_rank` numbers the members of each piece in order.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import breadth_first_order


class Twins:
    """Classes of indistinguishable interior nodes: equal closed neighbourhoods.

    High-order elements give them (the k − 1 dofs inside an edge, the bubbles of a cell).
    Such nodes can be ordered consecutively at no cost in fill, so the dissection runs on
    the quotient graph, one node per class, and each class is expanded in place. Classes
    are found by hashing the neighbourhoods; a (most improbable) false match would only
    cost fill, never correctness.
    """

    MIN_ROW = 14       # mean row length below which classes are not worth looking for
    MAX_SHARE = 0.9    # class count / m above which the quotient is not worth building

    def __init__(self, members, first, m):
        self.members, self.first, self.m = members, first, m
        self.count = int(first.sum())
        self.reps = np.sort(members[first])          # lowest index of each class

    @classmethod
    def find(cls, K, m: int) -> "Twins | None":
        """The classes among the first m nodes, or None where they would not pay off."""
        end = int(K.indptr[m])
        if end < cls.MIN_ROW * m:
            return None
        key = np.random.default_rng(0).integers(1, 2 ** 63, K.shape[0], dtype=np.uint64)
        hashed = np.append(key[K.indices[:end]], np.uint64(0))
        row = np.add.reduceat(hashed, K.indptr[:m])   # sum over the row, wrapping around
        length = np.diff(K.indptr[: m + 1])
        row[length == 0] = 0
        row += length.astype(np.uint64) * np.uint64(0x9E3779B97F4A7C15)
        members = np.argsort(row, kind="stable")
        ordered = row[members]
        first = np.empty(m, dtype=bool)
        first[0] = True
        np.not_equal(ordered[1:], ordered[:-1], out=first[1:])
        twins = cls(members, first, m)
        return twins if twins.count < cls.MAX_SHARE * m else None

    def quotient(self, K):
        """K restricted to one node per class and Γ (classes first, in index order)."""
        keep = np.concatenate([self.reps, np.arange(self.m, K.shape[0])])
        return K[keep][:, keep]

    def expand(self, order: np.ndarray) -> np.ndarray:
        """Order of the interior nodes from an order of the quotient's interior nodes."""
        start_in_members = np.flatnonzero(self.first)
        size = np.diff(np.append(start_in_members, self.m))
        klass = np.empty(self.m, dtype=np.intp)           # class of each node
        klass[self.members] = np.cumsum(self.first) - 1
        sequence = klass[self.reps[order]]                # classes in elimination order
        start = np.empty(self.count, dtype=np.intp)
        start[sequence] = np.cumsum(size[sequence]) - size[sequence]
        within = np.arange(self.m) - start_in_members[klass[self.members]]
        out = np.empty(self.m, dtype=np.intp)
        out[start[klass[self.members]] + within] = self.members
        return out


class Graph:
    """The pattern of K in CSR arrays, the Γ nodes cut out, plus node n: the BFS source.

    Interior nodes are relabelled in BFS order (``label[new] = old``, Γ keeps its labels),
    so that neighbours sit close in memory. Row n lists the cut-out nodes (Γ, then the
    separators), then the BFS start nodes: the cut-out nodes are visited first and their
    own rows are empty or point at n, so no BFS passes through them. Self loops (the
    diagonal) are kept: they are harmless.
    """

    def __init__(self, K, m: int):
        n = K.shape[0]
        end = int(K.indptr[m])
        indptr = np.full(n + 1, end, dtype=np.int32)
        indptr[: m + 1] = K.indptr[: m + 1]         # Γ rows empty
        raw = sp.csr_matrix((np.ones(end, dtype=np.int8), K.indices[:end], indptr), shape=(n, n))
        self.label = _bfs_labels(raw, m)
        rank = np.arange(n, dtype=np.int32)
        rank[self.label] = np.arange(m, dtype=np.int32)
        raw = raw[np.concatenate([self.label, np.arange(m, n)])]
        self.source, self.n_edges, self.n_cut, self.dead = n, end, n - m, 0
        self.indptr = np.empty(n + 2, dtype=np.int32)
        self.indptr[: n + 1] = raw.indptr
        self.indptr[n + 1] = end + n - m              # the source row: Γ
        self._allocate(end + n)
        np.take(rank, raw.indices, out=self.indices[:end])
        self.indices[end : end + n - m] = np.arange(m, n)
        self._position = np.empty(n + 1, dtype=np.intp)
        self._count = np.arange(n + 1)

    def _csr(self, data):
        shape = (self.source + 1, self.source + 1)
        return sp.csr_matrix((data, self.indices, self.indptr), shape=shape)

    def bfs(self, starts: np.ndarray):
        """Multi-source BFS from ``starts``: the nodes reached, in BFS order, and their level."""
        first = self.n_edges + self.n_cut
        self.indices[first : first + len(starts)] = starts
        self.indptr[-1] = first + len(starts)
        order, pred = breadth_first_order(self._csr(self._data), self.source, directed=True,
                                          return_predecessors=True)
        order = order.astype(np.intp)
        self._position[order] = self._count[: len(order)]
        level = _levels(self._position[pred[order[1:]]])
        return order[1 + self.n_cut :], level[self.n_cut :]

    def any_neighbour(self, nodes: np.ndarray, flag: np.ndarray) -> np.ndarray:
        """For each node, whether ``flag`` holds for one of its neighbours."""
        sub = self._csr(self._ones)[nodes]
        hits = np.zeros(sub.nnz + 1, dtype=np.int32)
        hits[:-1] = flag[sub.indices]
        return (np.add.reduceat(hits, sub.indptr[:-1]) > 0) & (np.diff(sub.indptr) > 0)

    def cut(self, nodes: np.ndarray) -> None:
        """Cut ``nodes`` out of the graph: empty their rows, let the source visit them."""
        start = self.indptr[nodes].astype(np.intp)
        count = self.indptr[nodes + 1] - start
        entries = np.arange(count.sum()) + np.repeat(start - (np.cumsum(count) - count), count)
        self.indices[entries] = self.source
        self.dead += len(entries)
        first = self.n_edges + self.n_cut
        self.indices[first : first + len(nodes)] = nodes
        self.n_cut += len(nodes)

    def compact(self, live: np.ndarray) -> None:
        """Keep only the rows of the ``live`` nodes (unordered ones): every BFS would scan
        the rows of the cut-out nodes in vain. The source still lists those nodes."""
        n = self.source
        cut_list = self.indices[self.n_edges : self.n_edges + self.n_cut]
        sub = self._csr(self._ones)[live]
        count = np.zeros(n + 1, dtype=np.int32)
        count[live] = np.diff(sub.indptr)
        np.cumsum(count, out=self.indptr[1:])
        self.n_edges, self.dead = sub.nnz, 0
        # room for the starts; at most twice the entries in use, or scipy would copy them
        self._allocate(self.n_edges + self.n_cut + len(live))
        self.indices[: self.n_edges] = sub.indices
        self.indices[self.n_edges : self.n_edges + self.n_cut] = cut_list

    def _allocate(self, length: int) -> None:
        self.indices = np.empty(length, dtype=np.int32)
        # csgraph wants float data of the same length; for a traversal explicit zeros are edges
        self._data = np.zeros(length)
        self._ones = np.ones(length, dtype=np.int8)


def _bfs_labels(graph, m: int) -> np.ndarray:
    """Interior nodes (< m) in BFS order from node 0, then those it did not reach."""
    order = breadth_first_order(graph, 0, directed=True, return_predecessors=False)
    order = order[order < m]
    if len(order) < m:
        missing = np.ones(m, dtype=bool)
        missing[order] = False
        order = np.concatenate([order, np.flatnonzero(missing)])
    return order.astype(np.intp)


def _levels(parent: np.ndarray) -> np.ndarray:
    """Levels of the nodes of a BFS order, given the positions of their parents in it.

    A FIFO BFS appends children in the order of their parents, so ``parent`` is
    non-decreasing: level j + 1 is the run of nodes whose parents lie in level j. The
    virtual source sits at position 0; the nodes it lists form level 0.
    """
    bounds = [0]
    while bounds[-1] < len(parent):
        bounds.append(int(np.searchsorted(parent, bounds[-1] + 1)))
    return np.repeat(np.arange(len(bounds) - 1), np.diff(bounds))


def segment_rank(keys: np.ndarray) -> np.ndarray:
    """Rank of each entry among the entries with the same key, in order of appearance."""
    small = keys.astype(np.uint16) if len(keys) and keys.max() < 2 ** 16 else keys
    by_key = np.argsort(small, kind="stable")   # a radix sort for 16-bit keys
    sorted_keys = keys[by_key]
    idx = np.arange(len(keys))
    new_key = np.empty(len(keys), dtype=bool)
    new_key[:1] = True
    np.not_equal(sorted_keys[1:], sorted_keys[:-1], out=new_key[1:])
    rank = np.empty(len(keys), dtype=np.intp)
    rank[by_key] = idx - np.maximum.accumulate(np.where(new_key, idx, 0))
    return rank
