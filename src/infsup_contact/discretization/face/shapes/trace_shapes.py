"""NGSolve's shape functions of a face's trace elements at reference points, each distinct point
evaluated once per kind of element (:func:`shape_values`; the trace basis of
:class:`~.square.Square`)."""
from __future__ import annotations

import numpy as np


def shape_values(fes, items: list) -> list:
    """[NGSolve's ``CalcShape`` of element ``el`` at each row of ``ref`` (points, its ndof)] for
    the (el, ref, number of its dofs) of ``items``, each distinct point evaluated once per kind of
    element (type, number of dofs, order of its vertex numbers).

    An element's shape functions depend on its type, order and the order of its global vertex
    numbers only (NGSolve orients the edge and face functions by comparing them), so elements of
    one kind share them: on a structured Γ the reference points of the cells repeat (to the bit,
    about one in eight at k = 2), and CalcShape per point was most of the trace basis' time. The
    values are those of each element's own calls, bit for bit (tests/discretization/face/
    test_trace_shapes.py)."""
    groups = {}
    for i, (el, ref, n_dofs) in enumerate(items):
        key = (str(el.type), n_dofs, tuple(np.argsort([v.nr for v in el.vertices], kind="stable")))
        groups.setdefault(key, []).append(i)
    out = [None] * len(items)
    for members in groups.values():
        refs = np.vstack([items[i][1] for i in members])
        unique, inverse = np.unique(refs, axis=0, return_inverse=True)
        fe = fes.GetFE(items[members[0]][0])
        values = np.array([np.asarray(fe.CalcShape(a, b, 0.0)) for a, b in unique]).reshape(len(unique), -1)
        start = 0
        for i in members:
            n = len(items[i][1])
            out[i] = values[np.ravel(inverse)[start:start + n]]
            start += n
    return out
