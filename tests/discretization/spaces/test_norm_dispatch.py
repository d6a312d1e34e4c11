"""The one dispatch on the norm (:func:`~infsup_contact.discretization.segment.norms.gram_by_norm`) for every
Γ: each module's ``gram`` returns exactly (bit for bit) what its own L² and H routes return, calls
only the route asked for, and rejects any other norm with the one InputError naming ``norm`` and
the allowed values :data:`~infsup_contact.discretization.segment.norms.NORMS`."""
import numpy as np
import pytest

from infsup_contact.discretization.face.norms import cellwise as fcn
from infsup_contact.discretization.face.norms import tensor as fn
from infsup_contact.discretization.face.norms import triangles as ftn
from infsup_contact.discretization.segment import norms
from infsup_contact.discretization.face.norms import unstructured as tf
from infsup_contact.discretization.face.spaces.cellwise import CellwiseFaceSpace
from infsup_contact.discretization.face.spaces.triangles import TriangleSpace
from infsup_contact.discretization.face.spaces.unstructured import mesh_space
from infsup_contact.discretization.segment.multipliers import make_space
from infsup_contact.discretization.spaces.registry import case_space
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.discretization.face.partitions.triangulation import from_elements
from infsup_contact.errors import InputError

GRID = TensorPartition(np.array([0.0, 0.3, 0.55, 1.0]), np.array([0.0, 0.45, 1.0]))
KW = {"rtol": 1e-3, "n_cap": 64}  # a cheap H series: the point is equality of routes, not accuracy


def _segment():
    return make_space(np.array([0.0, 0.3, 0.55, 1.0]), 2, True, True)


def _spaces():
    """(module gram, space, its L² route, its H route, H kwargs) for the five kinds of Γ space."""
    tri = TriangleSpace(GRID, 2, True, True, False)
    return {
        "segment": (norms.gram, _segment(), norms.gram_l2, norms.gram_h_logkernel, {}),
        "face": (fn.gram, case_space("T3", 2, GRID, SQUARE), fn.gram_l2_face, fn.gram_h_face, KW),
        "cellwise": (fcn.gram_cellwise, CellwiseFaceSpace(GRID, "QUAD4", "dual"), fcn.gram_l2_cellwise,
                     fcn.gram_h_cellwise, KW),
        "triangles": (ftn.gram, tri, ftn.gram_l2_tri, ftn.gram_h_tri, KW),
        "mesh": (tf.gram, mesh_space(from_elements(tri.triangles()), 2, True, True, False), tf.gram_l2,
                 tf.gram_h, KW),
    }


SPACES = _spaces()


@pytest.mark.parametrize("kind", SPACES)
def test_gram_is_its_routes_bit_for_bit(kind):
    gram, space, l2, h, kw = SPACES[kind]
    G, info = gram(space, "L2")
    assert np.array_equal(G, l2(space)) and info == {"n_max": 0, "nmax_rel_error": 0.0}
    G, info = gram(space, "H", **kw)
    Gh = h(space, **kw)
    Gh, info_h = Gh if isinstance(Gh, tuple) else (Gh, {"n_max": 0, "nmax_rel_error": 0.0})
    assert np.array_equal(G, Gh) and info == info_h
    assert np.all(np.linalg.eigvalsh(G) > 0)  # and it is a Gram matrix: SPD


@pytest.mark.parametrize("kind", SPACES)
@pytest.mark.parametrize("bad", ["h", "L1", "", None])
def test_unknown_norm_is_one_input_error_naming_norm(kind, bad):
    gram, space, *_ = SPACES[kind]
    with pytest.raises(InputError) as err:
        gram(space, bad)
    assert err.value.key == "norm" and all(n in err.value.allowed for n in norms.NORMS)


def test_only_the_asked_route_is_called_and_kwargs_reach_h_only():
    calls = []
    l2 = lambda: calls.append("l2") or np.eye(2)  # noqa: E731
    h = lambda **kw: calls.append(("h", kw)) or (2 * np.eye(2), {"n_max": 8})  # noqa: E731
    G, info = norms.gram_by_norm("L2", l2, h, rtol=1e-3)
    assert calls == ["l2"] and np.array_equal(G, np.eye(2))
    info["n_max"] = 99  # the caller owns its info: the shared default is not changed
    assert norms.L2_INFO == {"n_max": 0, "nmax_rel_error": 0.0}
    calls.clear()
    G, info = norms.gram_by_norm("H", l2, h, rtol=1e-3)
    assert calls == [("h", {"rtol": 1e-3})] and info == {"n_max": 8}
    with pytest.raises(InputError):
        norms.gram_by_norm("X", l2, h)


def test_segment_h_route_is_still_checked_and_the_two_routes_agree():
    space = _segment()
    with pytest.raises(InputError) as err:
        norms.gram(space, "H", h_route="fft")
    assert err.value.key == "h_route"
    Gk, _ = norms.gram(space, "H")
    Gs, _ = norms.gram(space, "H", h_route="series", rtol=1e-8)
    assert np.abs(Gk - Gs).max() < 1e-6 * np.abs(Gk).max()
