"""An independent isoparametric discretization of the arc's bodies (docs/models.md, "The curved
segment"), in numpy: the reference the library's curved sides are checked against.

Nothing of NGSolve's element maps, shape functions or quadrature is used. From the library it takes
only the square's mesh (vertices and triangles, the documented input) and, to compare in one basis,
the values of the library's Γ-dof basis at the Γ nodes. The body is Φ(square), Φ the documented polar
map; the isoparametric map of a triangle is the P_k Lagrange interpolant (equispaced nodes) of the
documented interpolant of Φ: exact at the vertices, on each edge the degree-k polynomial in the
edge's parameter with the moments ∫_e (q − Φ) p dt = 0 for p ∈ P_{k−2}, inside the triangle (k = 3)
the mean exact. The stiffness ∫ ∇u·∇v is integrated by a collapsed (Duffy) Gauss rule with ``points``
points per direction, exact for polynomials of degree 2·points − 2, far beyond the integrand's
numerator; its Schur complement on the Γ nodes is the reference S, in the nodal basis of Γ's P_k
(Lagrange in the arc length, equispaced per cell).

The projection coupling's reference (:func:`projection_coupling`) integrates the documented mortar
integral with an adaptive Gauss–Kronrod rule (scipy.integrate.quad) on the documented pieces, the
curves being this module's element edges and the projection a bracketed root (scipy.optimize.brentq).
"""
from __future__ import annotations

from itertools import combinations

import numpy as np
import scipy.integrate as si
import scipy.optimize as so
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def polar_map(radius: float, x, y):
    """Φ(x, y) = ((R − 1 + y) sin(x/R), (R − 1 + y) cos(x/R) − R + 1) (docs/models.md)."""
    r = radius - 1.0 + np.asarray(y, float)
    return np.stack([r * np.sin(np.asarray(x, float) / radius), r * np.cos(np.asarray(x, float) / radius)
                     - radius + 1.0], axis=-1)


def lattice(k: int) -> np.ndarray:
    """The equispaced P_k nodes (i/k, j/k), i + j ≤ k, of the reference triangle (0,0), (1,0), (0,1)."""
    return np.array([(i / k, j / k) for j in range(k + 1) for i in range(k + 1 - j)])


def monomials(k: int, p: np.ndarray) -> tuple:
    """Values and gradients of the monomials ξ^a η^b, a + b ≤ k, at points p (n, 2)."""
    powers = [(a, b) for b in range(k + 1) for a in range(k + 1 - b)]
    xi, eta = p[:, 0:1], p[:, 1:2]
    val = np.hstack([xi ** a * eta ** b for a, b in powers])
    dxi = np.hstack([a * xi ** max(a - 1, 0) * eta ** b for a, b in powers])
    deta = np.hstack([b * xi ** a * eta ** max(b - 1, 0) for a, b in powers])
    return val, np.stack([dxi, deta], axis=-1)


def lagrange(k: int, p: np.ndarray) -> tuple:
    """The P_k Lagrange basis at :func:`lattice` nodes: values (n, m) and gradients (n, m, 2) at p."""
    V, _ = monomials(k, lattice(k))
    val, grad = monomials(k, p)
    inverse = np.linalg.inv(V)
    return val @ inverse, np.einsum("nqd,qm->nmd", grad, inverse)


def duffy_rule(points: int) -> tuple:
    """A rule on the reference triangle exact for degree 2·points − 2: Gauss–Legendre on the square
    collapsed by (u, v) ↦ (u (1 − v), v)."""
    t, w = np.polynomial.legendre.leggauss(points)
    t, w = 0.5 * (t + 1), 0.5 * w
    u, v = np.meshgrid(t, t, indexing="ij")
    wu, wv = np.meshgrid(w, w, indexing="ij")
    p = np.column_stack([(u * (1 - v)).ravel(), v.ravel()])
    return p, (wu * wv * (1 - v)).ravel()


def edge_values(radius: float, a, b, k: int) -> np.ndarray:
    """Φ's documented interpolant on the straight edge a → b at t = i/k, i = 0..k: exact at the ends,
    the moments against Legendre P_0..P_{k−2} in t exact (a high Gauss rule for ∫ Φ p)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    t = np.arange(k + 1) / k
    ends = polar_map(radius, *a), polar_map(radius, *b)
    if k == 1:
        return np.array(ends)
    g, w = np.polynomial.legendre.leggauss(30)
    g, w = 0.5 * (g + 1), 0.5 * w
    phi = polar_map(radius, *(a[:, None] + g[None, :] * (b - a)[:, None]))                  # (30, 2)
    # Lagrange basis in t at the Gauss points
    L = np.array([np.prod([(g - t[m]) / (t[i] - t[m]) for m in range(k + 1) if m != i], axis=0)
                  for i in range(k + 1)]).T                                                  # (30, k + 1)
    P = np.column_stack([np.polynomial.legendre.legval(2 * g - 1, np.eye(k - 1)[j]) for j in range(k - 1)])
    M = (P * w[:, None]).T @ L                                                               # moments of the basis
    rhs = (P * w[:, None]).T @ phi - M[:, [0, k]] @ np.array(ends)
    inner = np.linalg.solve(M[:, 1:k], rhs)
    return np.vstack([ends[0], inner, ends[1]])


class Body:
    """One body: the square's triangles, P_k nodes numbered globally, the isoparametric node positions.

    Parameters
    ----------
    vertices : ndarray (nv, 2)
        The square's vertices (the library's mesh before curving).
    triangles : ndarray (nt, 3)
        Vertex numbers per triangle.
    radius, k : the arc's radius, the degree.
    gamma_y : float
        The square's y on Γ (1 for both bodies).
    """

    def __init__(self, vertices, triangles, radius: float, k: int, gamma_y: float = 1.0):
        if k not in (1, 2, 3):
            raise ValueError("the reference is written for k = 1, 2, 3")
        self.k, self.radius = k, float(radius)
        vertices, triangles = np.asarray(vertices, float), np.asarray(triangles, int)
        ref = lattice(k)
        index, self.square_nodes, self.cells = {}, [], []
        for tri in triangles:
            A, B, C = vertices[tri]
            pts = A + ref[:, :1] * (B - A) + ref[:, 1:] * (C - A)
            cell = []
            for p in pts:
                key = tuple(np.round(p * 3 * k, 6))  # exact lattice coordinates, as a key
                if key not in index:
                    index[key] = len(self.square_nodes)
                    self.square_nodes.append(p)
                cell.append(index[key])
            self.cells.append(cell)
        self.square_nodes, self.cells = np.array(self.square_nodes), np.array(self.cells)
        self.positions = self._curve(vertices, triangles)
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        p = self.square_nodes
        on_boundary = (np.isclose(p[:, 0], lo[0]) | np.isclose(p[:, 0], hi[0]) | np.isclose(p[:, 1], lo[1])
                       | np.isclose(p[:, 1], hi[1]))
        on_gamma = np.isclose(p[:, 1], gamma_y) & ~np.isclose(p[:, 0], lo[0]) & ~np.isclose(p[:, 0], hi[0])
        self.gamma_nodes = np.flatnonzero(on_gamma)[np.argsort(p[on_gamma, 0])]
        self.interior = np.flatnonzero(~on_boundary)

    def _curve(self, vertices, triangles) -> np.ndarray:
        """Node positions of the documented interpolant of Φ (module docstring)."""
        k, ref = self.k, lattice(self.k)
        X = np.full((len(self.square_nodes), 2), np.nan)
        for tri, cell in zip(triangles, self.cells):
            corners = vertices[tri]
            for i, j in combinations(range(3), 2):  # each edge: the lattice nodes on it, in order
                a, b = corners[i], corners[j]
                on_edge = [n for n, r in zip(cell, ref) if np.isclose(_edge_param(r, i, j, k)[0], 0.0)]
                values = edge_values(self.radius, a, b, k)
                for n in on_edge:
                    t = _edge_param(ref[list(cell).index(n)], i, j, k)[1]
                    X[n] = values[int(round(t * k))]
        if k == 3:  # the centroid node: the triangle's mean of Φ exact (moment against P_0)
            p, w = duffy_rule(12)
            N, _ = lagrange(k, p)
            centre = [m for m, r in enumerate(ref) if np.allclose(r, 1 / 3)][0]
            for tri, cell in zip(triangles, self.cells):
                A, B, C = vertices[tri]
                q = A + p[:, :1] * (B - A) + p[:, 1:] * (C - A)
                target = w @ polar_map(self.radius, q[:, 0], q[:, 1])
                others = [m for m in range(len(cell)) if m != centre]
                X[cell[centre]] = (target - (w @ N[:, others]) @ X[cell[others]]) / (w @ N[:, centre])
        assert not np.isnan(X).any()
        return X

    def stiffness(self, points: int = 14) -> sp.csr_matrix:
        """K = ∫ ∇u·∇v on the isoparametric body, by :func:`duffy_rule` with ``points``."""
        p, w = duffy_rule(points)
        _, dN = lagrange(self.k, p)                                              # (q, m, 2)
        rows, cols, vals = [], [], []
        for cell in self.cells:
            J = np.einsum("ma,qmb->qab", self.positions[cell], dN)               # J[q] = ∂X/∂ξ
            det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
            grad = np.linalg.solve(np.transpose(J, (0, 2, 1)), np.transpose(dN, (0, 2, 1)))  # J^{-T} ∇ξ N
            ke = np.einsum("q,qdm,qdn->mn", w * np.abs(det), grad, grad)
            rows.append(np.repeat(cell, len(cell)))
            cols.append(np.tile(cell, len(cell)))
            vals.append(ke.ravel())
        n = len(self.square_nodes)
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))

    def schur(self, points: int = 14) -> np.ndarray:
        """S = K_ΓΓ − K_ΓI K_II⁻¹ K_IΓ on the Γ nodes (u = 0 on the rest of the boundary)."""
        K = self.stiffness(points)
        I, G = self.interior, self.gamma_nodes
        KIG = K[I][:, G].toarray()
        return K[G][:, G].toarray() - KIG.T @ spla.splu(K[I][:, I].tocsc()).solve(KIG)

    def gamma_abscissae(self) -> np.ndarray:
        """The arc lengths (square's x) of the Γ nodes, in the order of :attr:`gamma_nodes`."""
        return self.square_nodes[self.gamma_nodes, 0]


def _edge_param(r, i: int, j: int, k: int) -> tuple:
    """(distance of the reference point r from edge i → j in barycentrics, its parameter t along it)."""
    bary = np.array([1 - r[0] - r[1], r[0], r[1]])
    other = 3 - i - j
    return bary[other], bary[j] / max(bary[i] + bary[j], 1e-300)


def library_square(mesh) -> tuple:
    """(vertices, triangles) of an NGSolve mesh of the square: the documented input, nothing curved."""
    import ngsolve

    vertices = np.array([mesh[v].point for v in mesh.vertices])
    triangles = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ngsolve.VOL)])
    return vertices, triangles


def reference_schur(side, body: Body, points: int = 14) -> np.ndarray:
    """The reference S in the library's Γ basis: S_lib = Tᵀ S_nodal T, T the library's Γ-dof basis
    at the reference's Γ nodes (both span continuous P_k on the same partition of Γ, u = 0 at ∂Γ)."""
    trace = side.trace
    T = np.asarray(trace.gamma.trace_basis(trace, body.gamma_abscissae()))
    return T.T @ body.schur(points) @ T


# --- the projection coupling ----------------------------------------------------------------------

class Curve:
    """A side's discrete Γ from :class:`Body`: per Γ cell the degree-k polynomial of its edge (in the
    arc length of the square, linear along the edge), and the averaged unit normals at the vertices."""

    def __init__(self, body: Body):
        k = self.k = body.k
        x = body.gamma_abscissae()
        nodes = np.concatenate([[0.0], x, [1.0]])
        ends = body.positions[[np.flatnonzero(np.isclose(body.square_nodes[:, 0], e)
                                              & np.isclose(body.square_nodes[:, 1], 1.0))[0] for e in (0.0, 1.0)]]
        positions = np.vstack([ends[0], body.positions[body.gamma_nodes], ends[1]])
        self.breakpoints = nodes[::k]
        self.cells = [(nodes[e * k:(e + 1) * k + 1], positions[e * k:(e + 1) * k + 1]) for e in range(len(self.breakpoints) - 1)]
        tangents = [(self._derivative(e, self.breakpoints[e]), self._derivative(e, self.breakpoints[e + 1]))
                    for e in range(len(self.cells))]
        turn = lambda t: np.array([-t[1], t[0]]) / np.hypot(*t)  # noqa: E731 (from Ω1 into Ω2)
        normals = np.zeros((len(self.breakpoints), 2))
        for e, (start, end) in enumerate(tangents):
            normals[e] += turn(start)
            normals[e + 1] += turn(end)
        self.normals = normals / np.linalg.norm(normals, axis=1)[:, None]

    def _cell(self, x: float) -> int:
        return int(np.clip(np.searchsorted(self.breakpoints, x, side="right") - 1, 0, len(self.cells) - 1))

    def point(self, x: float, e: int | None = None) -> np.ndarray:
        e = self._cell(x) if e is None else e
        s, p = self.cells[e]
        return np.array([sum(p[i] * np.prod([(x - s[m]) / (s[i] - s[m]) for m in range(len(s)) if m != i])
                             for i in range(len(s)))]).reshape(2)

    def _derivative(self, e: int, x: float) -> np.ndarray:
        """p'(x) on cell e: the derivative of the Lagrange form, exactly."""
        s, p = self.cells[e]
        d = np.zeros(2)
        for i in range(len(s)):
            others = [m for m in range(len(s)) if m != i]
            d += p[i] * sum(np.prod([(x - s[m]) / (s[i] - s[m]) for m in others if m != j]) / (s[i] - s[j])
                            for j in others)
        return d

    def speed(self, x: float) -> float:
        """|p'(x)|, the arc-length element of the discrete Γ."""
        return float(np.hypot(*self._derivative(self._cell(x), x)))

    @property
    def dim(self) -> int:
        """The number of Γ nodes off ∂Γ (the free ones, the library's Γ dofs)."""
        return self.k * (len(self.breakpoints) - 1) - 1

    def basis(self, x: float) -> np.ndarray:
        """The nodal P_k basis of the free Γ nodes at x (Lagrange in x on x's cell, equispaced)."""
        e = self._cell(x)
        s, _ = self.cells[e]
        out = np.zeros(self.dim + 2)
        for i in range(len(s)):
            out[e * self.k + i] = np.prod([(x - s[m]) / (s[i] - s[m]) for m in range(len(s)) if m != i])
        return out[1:-1]

    def normal(self, x: float) -> np.ndarray:
        e = self._cell(x)
        g = self.breakpoints
        u = (x - g[e]) / (g[e + 1] - g[e])
        n = (1 - u) * self.normals[e] + u * self.normals[e + 1]
        return n / np.linalg.norm(n)


def project(slave: Curve, master: Curve, x: float):
    """The master parameter y ∈ [0, 1] whose point lies on the slave's normal line at x; None if the
    line misses the master's curve (a bracketed root: no Newton, no extrapolation)."""
    p, n = slave.point(x), slave.normal(x)

    def f(y):
        d = master.point(y) - p
        return float(d[0] * n[1] - d[1] * n[0])

    f0, f1 = f(0.0), f(1.0)
    for end, value in ((0.0, f0), (1.0, f1)):
        if abs(value) <= 1e-14:  # the curves' common endpoint on the arc, up to round-off
            return end
    if f0 * f1 > 0:
        return None
    return so.brentq(f, 0.0, 1.0, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)


def projection_coupling(slave: Curve, master: Curve, mu, g_h) -> tuple:
    """(B_slave, B_master) of the documented projection coupling in the curves' nodal bases, by
    adaptive quadrature (scipy's ``quad_vec``, Gauss–Kronrod 21, to 1e-14):
    B_s[j, d] = ∫ μ_j L^s_d |p_s'| dx, B_m[j, d] = ∫ μ_j (L^m_d ∘ P) |p_s'| dx, on the pieces cut at the
    slave's and G_h's breakpoints and at P⁻¹ of the master's vertices (bracketed roots); where the
    slave's normal misses the master's curve the master contributes nothing. ``mu``: x ↦ (dim M,)."""
    ends = [project(slave, master, e) for e in (0.0, 1.0)]
    assert None not in ends  # both curves pass through the arc's endpoints: P(0) = 0, P(1) = 1
    cuts = set(np.concatenate([slave.breakpoints, np.asarray(g_h, float)]).tolist())
    for target in master.breakpoints:
        if ends[0] < target < ends[1]:
            cuts.add(so.brentq(lambda x: project(slave, master, x) - target, 0.0, 1.0,  # noqa: B023
                               xtol=1e-16, rtol=4 * np.finfo(float).eps, maxiter=200))
    cuts = np.array(sorted(cuts))
    m, ns, nm = len(mu(0.5)), slave.dim, master.dim

    def integrand(x):
        weight = mu(x) * slave.speed(x)
        y = project(slave, master, x)
        phi_m = np.zeros(nm) if y is None else master.basis(y)
        return np.concatenate([np.outer(weight, slave.basis(x)).ravel(), np.outer(weight, phi_m).ravel()])

    total = sum(si.quad_vec(integrand, a, b, epsabs=1e-16, epsrel=1e-14, norm="max", limit=400)[0]
                for a, b in zip(cuts[:-1], cuts[1:]))
    return total[:m * ns].reshape(m, ns), total[m * ns:].reshape(m, nm)


# --- β_h from the reference sides -----------------------------------------------------------------

def reference_sides(model, family: str, k: int, n1: int, n2: int, gamma, points: int = 14) -> list:
    """The library's pair on the arc with each side's S_i replaced by the reference's (its trace,
    couplings and Grams are the library's: the pencil is the same, only the bodies' S_i differ)."""
    from dataclasses import replace

    from infsup_contact.solvers.side_cache import SideCache

    sides = SideCache().pair(model, family, k, n1, n2, gamma=gamma)
    out = []
    for side, n, which in zip(sides, (n1, n2), (1, 2)):
        square = model.subdomain_mesh(family, n, which, gamma=gamma).mesh
        body = Body(*library_square(square), gamma.radius, k)
        out.append(replace(side, schur=reference_schur(side, body, points), steklov=None))
    return out


def reference_cache(sides):
    """A side cache that hands out ``sides`` (for ``beta_rows(..., side_cache=...)``)."""
    from infsup_contact.solvers.side_cache import SideCache

    class Fixed(SideCache):
        def pair(self, *args, **kwargs):
            return list(sides)

    return Fixed()
