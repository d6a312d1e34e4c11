"""A fill-reducing elimination order that keeps the Γ dofs last, for one sparse LU.

Why this exists
---------------
The Γ Schur complement S = K_ΓΓ − K_ΓI K_II⁻¹ K_IΓ is the trailing block of the LU factors,
S = L_ΓΓ U_ΓΓ, provided the Γ dofs are eliminated last (:mod:`infsup_contact.la.schur`). SuperLU
(``scipy.sparse.linalg.splu``) accepts no user ordering: it either computes its own column
order, which mixes Γ into the interior, or takes the matrix as given
(``permc_spec="NATURAL"``). So the order has to be computed here and the matrix permuted
before the one factorization. Without it, a first factorization of K_II was needed only to
read SuperLU's minimum-degree order off it — as costly as the factorization that matters.

Method
------
Nested dissection of the graph of the interior block K_II (Γ is appended afterwards),
purely graph based (no coordinates, any mesh family, any polynomial degree):

* a breadth-first search (BFS) splits a piece of the graph into level sets. Every level is
  a vertex separator (nodes of level ℓ touch only levels ℓ − 1, ℓ, ℓ + 1); the one cut
  minimizes width / (nodes below × nodes above) among levels leaving at least 15 % of the
  piece on either side, and is thinned to its nodes that touch the level above;
* both sides are ordered first, the separator after them, recursively, until a piece has
  at most ``leaf_size`` nodes; a leaf is ordered by reversed BFS order (a profile order).

All pieces of one recursion depth are handled together: one multi-source BFS (a virtual
source node linked to a start in every piece) and a few numpy passes per depth, with no
Python loop over pieces or nodes. Separators are cut out of the graph by letting the
virtual source visit them first and emptying their rows, so the pieces fall apart
without rebuilding the graph. The next BFS of a side starts where the level front of its
parent ended, near an end of the separator, so the next cut runs across the previous one
as nested dissection wants; the first BFS starts at a peripheral node. Nodes are
relabelled in BFS order once, for memory locality. For high-order elements (long rows),
indistinguishable nodes (equal neighbourhoods: the dofs inside one edge or cell) are
merged first and ordered consecutively, which shrinks the graph at no cost in fill.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from .graph import Graph, Twins, segment_rank

__all__ = ["nested_dissection_gamma_last"]


def nested_dissection_gamma_last(K, n_gamma: int, leaf_size: int = 24) -> np.ndarray:
    """Fill-reducing order of a symmetric sparse matrix that eliminates its last block last.

    Parameters
    ----------
    K : sparse matrix (n, n)
        Structurally symmetric, e.g. a stiffness matrix. Only the pattern of the stored
        entries of the interior block is used (CSC and CSR give the same order); for a
        non-symmetric pattern the order is still a valid permutation, only less effective.
    n_gamma : int
        The last ``n_gamma`` rows/cols (the Γ dofs) stay last, in their given order.
    leaf_size : int
        Pieces with at most this many nodes are not dissected further.

    Returns
    -------
    order : ndarray of int, shape (n,)
        A permutation: new position p holds old index ``order[p]``, so ``K[order][:, order]``
        is the reordered matrix. ``order[n - n_gamma:]`` is ``arange(n - n_gamma, n)`` and
        ``order[:n - n_gamma]`` a nested-dissection order of the interior block.
    """
    n = K.shape[0]
    if K.shape != (n, n) or not 0 <= n_gamma <= n:
        raise ValueError(f"need a square matrix and 0 <= n_gamma <= n, got {K.shape}, {n_gamma}")
    if leaf_size < 1:
        raise ValueError(f"leaf_size must be >= 1, got {leaf_size}")
    m = n - n_gamma
    tail = np.arange(m, n)
    if m == 0:
        return tail
    K = K if K.format in ("csr", "csc") else sp.csr_matrix(K)
    twins = Twins.find(K, m)
    if twins is None:
        return np.concatenate([_interior_order(K, m, leaf_size), tail])
    quotient = _interior_order(twins.quotient(K), twins.count, leaf_size)
    return np.concatenate([twins.expand(quotient), tail])


def _interior_order(K, m: int, leaf_size: int) -> np.ndarray:
    """Nested-dissection order of the first m nodes of K (the rest: Γ, left out)."""
    graph = Graph(K, m)
    position = _dissect(graph, m, leaf_size)
    interior = np.empty(m, dtype=np.intp)
    interior[position[:m]] = graph.label
    return interior


class _Pieces(NamedTuple):
    """Pieces still to dissect: start and size of their range in the new order, and the
    node their next BFS starts from."""

    lo: np.ndarray
    size: np.ndarray
    start: np.ndarray


def _dissect(graph: Graph, m: int, leaf_size: int) -> np.ndarray:
    """New position of every interior node (labels < m): nested dissection, one depth per
    pass."""
    size = graph.source + 1
    position = np.empty(size, dtype=np.intp)
    group = np.full(size, -1, dtype=np.intp)     # piece of each unordered node
    group[:m] = 0
    above = np.zeros(size, dtype=bool)            # beyond the cut level of its piece
    # the last node of the labelling BFS is far from its start: a peripheral node
    pieces = _Pieces(np.array([0]), np.array([m]), np.array([m - 1]))
    while len(pieces.start):
        if pieces.size.sum() <= m // 32:           # not worth another BFS
            _order_remainder(group, pieces, position)
            break
        if graph.dead > graph.n_edges // 4:
            graph.compact(np.flatnonzero(group >= 0))
        pieces = _dissect_once(graph, pieces, leaf_size, position, group, above)
    return position


def _dissect_once(graph, pieces: _Pieces, leaf_size, position, group, above) -> _Pieces:
    """One depth: a BFS in every piece, leaves ordered, the others cut in two."""
    lo = pieces.lo
    nodes, level = graph.bfs(pieces.start)
    piece = group[nodes]
    if piece.min() < 0:                # only if the pattern is not symmetric
        mine = piece >= 0
        nodes, level, piece = nodes[mine], level[mine], piece[mine]
    reached = np.bincount(piece, minlength=len(lo))
    rest = _Rest(group, nodes, pieces, reached) if np.any(reached < pieces.size) else None
    depth = np.zeros(len(lo), dtype=level.dtype)
    np.maximum.at(depth, piece, level)
    leaf = (reached <= leaf_size) | (depth < 2)
    if leaf.any():
        nodes, piece, level = _order_leaves(nodes, piece, leaf, lo, position, group, level)
    following = _Pieces(*(np.zeros(0, dtype=np.intp),) * 3)
    if len(nodes):
        cut = _cut_levels(level, piece, reached, depth)
        nodes, piece, is_above = _separate(graph, nodes, level, piece, cut, reached, lo,
                                           position, group, above)
        following = _split(nodes, piece, is_above, lo, position, group, leaf_size)
    return following if rest is None else rest.after(following, group)


def _order_remainder(group, pieces: _Pieces, position) -> None:
    """Order a small remainder (all pieces left) without another BFS: each piece as a
    leaf, in reversed label order, which is a BFS order of the whole graph."""
    nodes = np.flatnonzero(group >= 0)[::-1]
    piece = group[nodes]
    position[nodes] = pieces.lo[piece] + segment_rank(piece)
    group[nodes] = -1


class _Rest:
    """The parts of pieces that a BFS did not reach: a side of a cut may fall apart.

    The reached part keeps the front of the piece's range; the rest becomes a piece of its
    own with the back of the range, and waits for the next pass.
    """

    def __init__(self, group, nodes, pieces: _Pieces, reached):
        seen = np.zeros(len(group), dtype=bool)
        seen[nodes] = True
        self.nodes = np.flatnonzero((group >= 0) & ~seen)
        self.old = group[self.nodes]
        short = np.flatnonzero(reached < pieces.size)
        first = np.full(len(reached), len(group), dtype=np.intp)
        np.minimum.at(first, self.old, self.nodes)
        self.renumber = np.empty(len(reached), dtype=np.intp)
        self.renumber[short] = np.arange(len(short))
        self.pieces = _Pieces(pieces.lo[short] + reached[short], pieces.size[short] - reached[short],
                              first[short])

    def after(self, pieces: _Pieces, group: np.ndarray) -> _Pieces:
        """``pieces`` followed by the unreached parts, whose nodes get their new piece."""
        group[self.nodes] = len(pieces.start) + self.renumber[self.old]
        return _Pieces(*(np.concatenate(pair) for pair in zip(pieces, self.pieces)))


def _order_leaves(nodes, piece, leaf, lo, position, group, *more):
    """Give the nodes of leaf pieces their final positions; return the other nodes.

    ``nodes`` are in BFS order; a leaf is ordered by reversed BFS order, a profile order
    (reversed Cuthill–McKee-like) that ends at the BFS start. ``more`` are further arrays
    aligned with ``nodes``, filtered alike.
    """
    in_leaf = leaf[piece]
    leaf_nodes, leaf_piece = nodes[in_leaf][::-1], piece[in_leaf][::-1]
    position[leaf_nodes] = lo[leaf_piece] + segment_rank(leaf_piece)
    group[leaf_nodes] = -1
    keep = ~in_leaf
    return (nodes[keep], piece[keep], *(a[keep] for a in more))


def _cut_levels(level, piece, size, depth, balance: float = 0.15) -> np.ndarray:
    """Per piece, the BFS level to cut at: the best ratio cut among balanced levels.

    A level with w nodes, b nodes below and a above scores w / (b a): a small separator
    between two large sides. Levels that leave less than ``balance`` of the piece on a
    side are not candidates; without candidates, the level of the median node is cut.
    Cut levels lie within 1 .. depth − 1, so that both sides are non-empty.
    """
    n_pieces = len(depth)
    offset = np.zeros(n_pieces + 1, dtype=np.intp)
    np.cumsum(depth + 1, out=offset[1:])
    width = np.bincount(offset[:-1][piece] + level, minlength=offset[-1])   # (piece, level)
    owner = np.repeat(np.arange(n_pieces), depth + 1)
    cumulative = np.cumsum(width)
    earlier = np.concatenate([[0], cumulative])[offset[:-1]]   # nodes of the pieces before
    median = np.searchsorted(cumulative, earlier + (size + 1) // 2) - offset[:-1]
    cut = np.clip(median, 1, np.maximum(depth - 1, 1))
    at = np.arange(offset[-1]) - offset[:-1][owner]
    below = cumulative - width - earlier[owner]
    above = size[owner] - below - width
    room = balance * size[owner]
    ok = (at >= 1) & (at < depth[owner]) & (below >= room) & (above >= room)
    score = np.full(len(width), np.inf)
    score[ok] = width[ok] / (below[ok] * above[ok])
    best = np.full(n_pieces, np.inf)
    np.minimum.at(best, owner, score)
    pick = np.flatnonzero(ok & (score == best[owner]))
    cut[owner[pick]] = at[pick]                   # on a tie, any of the best
    return cut


def _separate(graph, nodes, level, piece, cut, size, lo, position, group, above):
    """Order the separators last in their pieces and cut them out of the graph.

    The separator of a piece is the part of its cut level that touches the level above;
    the rest of the cut level joins the side below. Returns the other nodes, their piece
    and whether they lie above the cut.
    """
    rel = level - cut[piece]
    above[nodes] = rel > 0
    at = np.flatnonzero(rel == 0)
    touches = graph.any_neighbour(nodes[at], above)
    rel[at[~touches]] = -1
    sep, sep_piece = nodes[at[touches]], piece[at[touches]]
    sep_size = np.bincount(sep_piece, minlength=len(size))
    position[sep] = lo[sep_piece] + size[sep_piece] - sep_size[sep_piece] + segment_rank(sep_piece)
    group[sep] = -1
    graph.cut(sep)
    keep = rel != 0
    return nodes[keep], piece[keep], rel[keep] > 0


def _split(nodes, piece, is_above, lo, position, group, leaf_size) -> _Pieces:
    """The two sides of every cut piece: the pieces of the next depth.

    The side below the cut takes the front of the piece's range, the side above follows.
    Sides of at most ``leaf_size`` nodes are ordered at once, as leaves. The BFS of a
    larger side starts where the level front of its parent ended: at the last node below
    the cut in BFS order, or at the first node above it.
    """
    key = 2 * piece + is_above
    count = np.bincount(key, minlength=2 * len(lo))
    key_lo = np.repeat(lo, 2)
    key_lo[1::2] += count[0::2]
    leaf = count <= leaf_size
    if leaf.any():
        nodes, key = _order_leaves(nodes, key, leaf, key_lo, position, group)
    used = np.flatnonzero(~leaf)
    renumber = np.empty(len(count), dtype=np.intp)
    renumber[used] = np.arange(len(used))
    new = renumber[key]
    group[nodes] = new
    # below: the last node (largest index), above: the first (smallest index)
    idx = np.arange(len(nodes))
    upper = used % 2 == 1
    pick = np.full(len(used), len(nodes), dtype=np.intp)
    np.minimum.at(pick, new, np.where(key % 2 == 1, idx, len(nodes) - 1 - idx))
    pick = np.where(upper, pick, len(nodes) - 1 - pick)
    return _Pieces(key_lo[used], count[used], nodes[pick])
