"""Reference elements of a 2D contact face: QUAD4, QUAD8, QUAD9, TRI3, TRI6.

Quadrilaterals live on [−1, 1]², triangles on the unit triangle {ξ, η ≥ 0, ξ + η ≤ 1}. The
node numbering is the common one (4C / BACI ``Mortar::Element::shape_functions``, also
Exodus): corners counter-clockwise from (−1, −1) (triangles: (0, 0), (1, 0), (0, 1)), then
the edge nodes in the order of the edges (a → b for the corners a, b), then the QUAD9 centre.

Every space is given by the monomials ξ^a η^b it spans (:attr:`ReferenceElement.exponents`):

* QUAD4 = Q1 = {1, ξ, η, ξη};
* QUAD8 = serendipity = P2 + {ξ²η, ξη²} (Q2 without ξ²η²);
* QUAD9 = Q2 (all ξ^a η^b with a, b ≤ 2);
* TRI3 = P1, TRI6 = P2.

The nodal basis is N(ξ) = P(ξ) V⁻¹ with the monomial vector P and the Vandermonde matrix
V[k, m] = P_m(node_k), so N_k(node_l) = δ_kl by construction. Gauss rules: tensor
Gauss–Legendre on the square; on the triangle the collapsed (Duffy) rule
(ξ, η) = (u(1 − v), v), weight w_u w_v (1 − v), exact for total degree 2n − 2 with n points
per direction (the Jacobian 1 − v adds one degree in v).

The 4C option ``LM_QUAD pwlin`` (piecewise linear multipliers on quadratic faces) uses the
split of BACI's ``MortarInterface::SplitIntElements`` (Popp, 03/09): QUAD9 → 4 QUAD4,
TRI6 → 4 TRI3, QUAD8 → 4 corner TRI3 (corner and its two edge nodes) + the QUAD4 of the four
edge nodes. :func:`pwlin_shapes` is the nodal basis that is linear (TRI3) or bilinear (QUAD4)
on each piece; every piece is an affine image of its reference cell.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ....errors import InputError
from ...gamma.quadrature import gauss_legendre, gauss_legendre_01

ELEMENT_NAMES = ("QUAD4", "QUAD8", "QUAD9", "TRI3", "TRI6")


@dataclass(frozen=True, eq=False)
class ReferenceElement:
    """A Lagrange element on its reference cell.

    Attributes
    ----------
    name : str
        One of :data:`ELEMENT_NAMES`.
    cell : str
        ``"quad"`` ([−1, 1]²) or ``"tri"`` (unit triangle).
    nodes : ndarray, shape (n_nodes, 2)
        Reference coordinates of the nodes.
    exponents : tuple of (int, int)
        The monomials ξ^a η^b spanning the space.
    corners : tuple of int
        The vertex nodes.
    edges : tuple of (int, int, int)
        (a, b, m): edge node m sits on the edge between the corners a and b.
    """

    name: str
    cell: str
    nodes: np.ndarray
    exponents: tuple
    corners: tuple
    edges: tuple

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def area(self) -> float:
        """Area of the reference cell: 4 for [−1, 1]², 1/2 for the unit triangle."""
        return 4.0 if self.cell == "quad" else 0.5

    @property
    def degree(self) -> int:
        """Largest degree in one variable (1 for QUAD4/TRI3, 2 for QUAD8/9/TRI6)."""
        return max(max(a, b) for a, b in self.exponents)

    @property
    def total_degree(self) -> int:
        """Largest total degree a + b of the monomials (QUAD8: 3, QUAD9: 4)."""
        return max(a + b for a, b in self.exponents)

    def shapes(self, points) -> np.ndarray:
        """N_k at ``points`` (shape (n, 2)), returned with shape (n, n_nodes)."""
        return monomials(self.exponents, points) @ _inverse_vandermonde(self.name)

    def quadrature(self, total_degree: int) -> tuple[np.ndarray, np.ndarray]:
        """Points (q, 2) and weights (q,) exact for polynomials of ``total_degree``."""
        return cell_quadrature(self.cell, total_degree)


def monomials(exponents, points) -> np.ndarray:
    """ξ^a η^b for each (a, b) in ``exponents`` at ``points`` (n, 2); shape (n, len(exponents))."""
    p = np.atleast_2d(np.asarray(points, dtype=float))
    a, b = np.array(exponents, dtype=int).T
    # each distinct power once (QUAD9: 3 per coordinate instead of 9), by the same elementwise pow
    # as ξ^a for the whole exponent array, then gathered: the same values bit for bit
    (pa, ia), (pb, ib) = (np.unique(e, return_inverse=True) for e in (a, b))
    return (p[:, :1] ** pa[None, :])[:, ia] * (p[:, 1:2] ** pb[None, :])[:, ib]


_SQ_CORNERS = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
_SQ_EDGES = ((0, 1, 4), (1, 2, 5), (2, 3, 6), (3, 0, 7))
_TRI_EDGES = ((0, 1, 3), (1, 2, 4), (2, 0, 5))


def _midpoints(corner_xy, edges):
    c = np.asarray(corner_xy, dtype=float)
    return [0.5 * (c[a] + c[b]) for a, b, _ in edges]


def _build(name: str) -> ReferenceElement:
    q1 = ((0, 0), (1, 0), (0, 1), (1, 1))
    p2 = ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2))
    if name == "QUAD4":
        return ReferenceElement(name, "quad", np.array(_SQ_CORNERS, float), q1, (0, 1, 2, 3), ())
    if name in ("QUAD8", "QUAD9"):
        nodes = _SQ_CORNERS + _midpoints(_SQ_CORNERS, _SQ_EDGES) + ([(0, 0)] if name == "QUAD9" else [])
        exps = p2 + ((2, 1), (1, 2)) + (((2, 2),) if name == "QUAD9" else ())
        return ReferenceElement(name, "quad", np.array(nodes, float), exps, (0, 1, 2, 3), _SQ_EDGES)
    tri = [(0, 0), (1, 0), (0, 1)]
    if name == "TRI3":
        return ReferenceElement(name, "tri", np.array(tri, float), p2[:3], (0, 1, 2), ())
    return ReferenceElement(name, "tri", np.array(tri + _midpoints(tri, _TRI_EDGES), float), p2,
                            (0, 1, 2), _TRI_EDGES)


@lru_cache(maxsize=None)
def reference_element(name: str) -> ReferenceElement:
    """The element called ``name`` (one of :data:`ELEMENT_NAMES`)."""
    if name not in ELEMENT_NAMES:
        raise InputError("element", f"one of {', '.join(ELEMENT_NAMES)}", got=name)
    el = _build(name)
    el.nodes.flags.writeable = False
    return el


@lru_cache(maxsize=None)
def _inverse_vandermonde(name: str) -> np.ndarray:
    el = reference_element(name)
    Vinv = np.linalg.inv(monomials(el.exponents, el.nodes))
    Vinv.flags.writeable = False
    return Vinv


@lru_cache(maxsize=None)
def cell_quadrature(cell: str, total_degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss rule on the reference ``cell`` ("quad" or "tri") exact for ``total_degree``.

    Square: n × n Gauss–Legendre, n = ⌊p/2⌋ + 1 (exact per variable up to 2n − 1 ≥ p).
    Triangle: collapsed rule with n = ⌊(p + 1)/2⌋ + 1 (the pulled-back integrand has
    degree p in u and p + 1 in v).
    """
    if cell == "quad":
        t, w = gauss_legendre(total_degree // 2 + 1)
        pts = np.stack(np.meshgrid(t, t, indexing="ij"), -1).reshape(-1, 2)
        wts = np.outer(w, w).ravel()
    else:
        u, w = gauss_legendre_01((total_degree + 1) // 2 + 1)
        U, Vv = np.meshgrid(u, u, indexing="ij")
        pts = np.stack([U * (1 - Vv), Vv], -1).reshape(-1, 2)
        wts = (np.outer(w, w) * (1 - Vv)).ravel()
    pts.flags.writeable = wts.flags.writeable = False
    return pts, wts


# ---------------------------------------------------------------------------------------------
# 4C ``pwlin``: piecewise linear multipliers on the sub-cells of a quadratic face element
# ---------------------------------------------------------------------------------------------

_PWLIN = {
    "QUAD4": (("QUAD4", (0, 1, 2, 3)),),
    "TRI3": (("TRI3", (0, 1, 2)),),
    "QUAD9": (("QUAD4", (0, 4, 8, 7)), ("QUAD4", (4, 1, 5, 8)), ("QUAD4", (8, 5, 2, 6)),
              ("QUAD4", (7, 8, 6, 3))),
    "TRI6": (("TRI3", (0, 3, 5)), ("TRI3", (3, 1, 4)), ("TRI3", (5, 4, 2)), ("TRI3", (4, 5, 3))),
    "QUAD8": (("TRI3", (0, 4, 7)), ("TRI3", (1, 5, 4)), ("TRI3", (2, 6, 5)), ("TRI3", (3, 7, 6)),
              ("QUAD4", (4, 5, 6, 7))),
}


def pwlin_subelements(name: str) -> tuple:
    """The 4C ``pwlin`` split of element ``name``: tuples (sub-element type, parent nodes).

    The parent nodes are listed in the sub-element's own node order (BACI
    ``MortarInterface::SplitIntElements``). Linear elements are their own single piece.
    """
    reference_element(name)                                   # validates the name
    return _PWLIN[name]


def _to_sub_reference(kind: str, corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Reference coordinates of ``points`` in the affine sub-cell with these corner nodes."""
    o = corners[0]
    if kind == "TRI3":
        J = np.column_stack([corners[1] - o, corners[2] - o])          # x = o + J (ξ, η)
        return np.linalg.solve(J, (points - o).T).T
    J = 0.5 * np.column_stack([corners[1] - o, corners[3] - o])        # x = o + J (ξ + 1, η + 1)
    return np.linalg.solve(J, (points - o).T).T - 1.0


def _inside(kind: str, ref: np.ndarray, tol: float = 1e-12) -> np.ndarray:
    if kind == "TRI3":
        return (ref[:, 0] >= -tol) & (ref[:, 1] >= -tol) & (ref.sum(1) <= 1 + tol)
    return np.all(np.abs(ref) <= 1 + tol, axis=1)


def pwlin_shapes(name: str, points) -> np.ndarray:
    """The ``pwlin`` nodal basis of element ``name`` at ``points`` (n, 2): shape (n, n_nodes).

    Parent node k's function is, on each piece containing k, that piece's TRI3 / QUAD4 shape
    function of k, and 0 on the others. A point on a boundary between pieces takes the first
    piece (the functions are continuous, so the choice does not matter).
    """
    el = reference_element(name)
    p = np.atleast_2d(np.asarray(points, dtype=float))
    out = np.zeros((len(p), el.n_nodes))
    done = np.zeros(len(p), dtype=bool)
    for kind, nodes in pwlin_subelements(name):
        ref = _to_sub_reference(kind, el.nodes[list(nodes)], p)
        take = _inside(kind, ref) & ~done
        out[np.ix_(take, nodes)] = reference_element(kind).shapes(ref[take])
        done |= take
    if not done.all():
        raise InputError("points", f"points inside the reference cell of {name}", got=p[~done][:3].tolist())
    return out
