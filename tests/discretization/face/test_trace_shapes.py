"""The face's trace basis evaluates NGSolve's CalcShape once per distinct reference point and kind
of element (type, dofs, order of its vertex numbers; trace_shapes.shape_values): its values are those
of every element's own CalcShape calls, bit for bit, on hexahedra and tetrahedra of several
degrees, matching and not, at the couplings' and the norms' points."""
import numpy as np
import pytest

from infsup_contact.models import make_model


def _per_element(sq, trace, x):
    """The former route: every element's own FE and one CalcShape per point it takes."""
    part = trace.breakpoints
    position = -np.ones(trace.fes.ndof, dtype=int)
    position[trace.gamma_dofs] = np.arange(len(trace.gamma_dofs))
    phi = np.zeros((len(x), len(trace.gamma_dofs)))
    ix, iy = sq._cell_index(part, x)
    todo = np.ones(len(x), dtype=bool)
    for verts, dn, el in trace.elements:
        c = sq._cell_index(part, verts.mean(axis=0)[None, :])
        pts = np.flatnonzero((ix == c[0][0]) & (iy == c[1][0]) & todo)
        ref = sq._reference(verts, x[pts])
        inside = np.all(ref >= -1e-10, axis=1)
        if sq.cell == "trig":
            inside &= ref.sum(axis=1) <= 1.0 + 1e-10
        if not inside.any():
            continue
        todo[pts[inside]] = False
        fe = trace.fes.GetFE(el)
        pos = position[dn]
        keep = pos >= 0
        shapes = np.array([np.asarray(fe.CalcShape(a, b, 0.0)) for a, b in ref[inside]])
        phi[np.ix_(pts[inside], pos[keep])] += shapes[:, keep]
    return phi


@pytest.mark.parametrize("element, k, sizes", [("hex", 1, (3, 4)), ("hex", 2, (4, 4)), ("hex", 3, (2, 3)),
                                                ("tet", 1, (3, 3)), ("tet", 2, (2, 3))])
def test_the_trace_basis_is_each_elements_own_calcshape_bit_for_bit(element, k, sizes):
    m = make_model("membranes3d")
    for i, n in enumerate(sizes):
        trace = m.side_operator(m.subdomain_mesh("structured", n, i + 1, element=element), k).trace
        sq = trace.gamma
        for degree in (2 * k, 2 * k + 3):
            x = sq.quadrature(trace.partition, degree)[0]
            want = _per_element(sq, trace, x)
            assert np.array_equal(sq.trace_values(trace, x), want)
            assert np.array_equal(sq.sparse_trace_basis(trace, x).toarray(), want)
            assert np.count_nonzero(want) > 0


def test_elements_of_other_vertex_orders_keep_their_own_shapes():
    """On an unstructured triangulation the elements' vertex numbers come in several orders, and
    at degree 3 the edge functions' signs follow them: shape_values keeps each order apart (the
    same reference points on every element), each element's values its own CalcShape's."""
    import ngsolve
    from netgen.geom2d import unit_square

    from infsup_contact.discretization.face.shapes.trace_shapes import shape_values

    mesh = ngsolve.Mesh(unit_square.GenerateMesh(maxh=0.3))
    fes = ngsolve.H1(mesh, order=3)
    ref = np.random.default_rng(1).dirichlet(np.ones(3), size=6)[:, :2]
    elements = list(mesh.Elements(ngsolve.VOL))
    items = [(el, ref, len(fes.GetDofNrs(el))) for el in elements]
    got = shape_values(fes, items)
    own = [np.array([np.asarray(fes.GetFE(el).CalcShape(a, b, 0.0)) for a, b in ref]) for el in elements]
    assert all(np.array_equal(g, o) for g, o in zip(got, own))
    assert len({tuple(np.argsort([v.nr for v in el.vertices])) for el in elements}) > 1
    assert any(not np.array_equal(o, own[0]) for o in own)  # the orders matter at this degree
