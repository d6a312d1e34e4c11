"""The mortar coupling by normal projection on a curved Γ, as production codes compute it.

On the arc (:mod:`.arc`) each side's discretized Γ is its own degree-k curve through its vertices,
and two non-matching curves do not coincide. Mortar codes (Puso & Laursen 2004; Yang, Laursen &
Meng 2005; Popp et al. 2010) integrate on the side that carries the multipliers (the *slave*),
and evaluate the other side (the *master*) at the point its curve meets the slave's normal:

    B_slave[j, d]  = ∫_{Γ_h^s} μ_j φ^s_d dS,      B_master[j, d] = ∫_{Γ_h^s} μ_j (φ^m_d ∘ P) dS,

with P(x) the master point on the line through the slave point x along the slave's averaged
nodal normal, interpolated linearly along each slave cell (continuous, so P is continuous and
increasing). The slave is the side whose trace G_h is (Ω2 for ``omega2`` and ``union``, Ω1 for
``omega1``); μ lives on the slave's parameter (arc length at its vertices). The integral is
split where the integrand is not smooth — the slave's vertices, G_h's breakpoints and the
pre-images P⁻¹ of the master's vertices — and each piece gets a Gauss rule
:data:`EXTRA_POINTS` points above the polynomial degree of μ φ (the curves' Jacobian and P are
not polynomials: the rule is accurate, not exact; the tests bound its error). Where the slave's
normal misses the master's curve (near ∂Γ, where the curves meet at an angle) the master side
contributes nothing. On matching meshes the two curves are the same and P is the identity.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..gamma.quadrature import gauss_legendre
from .arc import Arc

EXTRA_POINTS = 6
"""Gauss points per piece beyond those exact for the polynomial degree of μ φ."""
NEWTON_STEPS = 60
BISECTION_STEPS = 64


@dataclass(frozen=True)
class SideCurve:
    """The discrete Γ of one side: per trace cell [s_e, s_{e+1}] (arc length at its vertices) the
    degree-k curve of its curved boundary element, as polynomials in u = (x − s_e)/(s_{e+1} − s_e).

    Attributes
    ----------
    breakpoints : ndarray (n + 1,)
        The side's trace partition.
    coefficients : ndarray (n, 2, k + 1)
        Per cell and coordinate, the power coefficients in u (exact: the element map is a
        degree-k polynomial, fitted through k + 1 points).
    normals : ndarray (n + 1, 2)
        The averaged unit normals at the vertices (pointing from Ω1 into Ω2).
    """

    breakpoints: np.ndarray
    coefficients: np.ndarray
    normals: np.ndarray

    def _cell(self, x):
        g = self.breakpoints
        e = np.clip(np.searchsorted(g, x, side="right") - 1, 0, len(g) - 2)
        h = g[e + 1] - g[e]
        return e, (x - g[e]) / h, h

    def point(self, x: np.ndarray) -> tuple:
        """(points (n, 2), d point / dx (n, 2)) at parameters ``x`` (extrapolated past the ends)."""
        e, u, h = self._cell(np.asarray(x, float))
        c = self.coefficients[e]                                       # (n, 2, k + 1)
        powers = u[:, None] ** np.arange(c.shape[2])[None, :]
        dpowers = np.zeros_like(powers)
        dpowers[:, 1:] = np.arange(1, c.shape[2])[None, :] * powers[:, :-1]
        return np.einsum("ndk,nk->nd", c, powers), np.einsum("ndk,nk->nd", c, dpowers) / h[:, None]

    def normal(self, x: np.ndarray) -> np.ndarray:
        """The averaged nodal normals interpolated linearly on each cell, normalized."""
        e, u, _ = self._cell(np.asarray(x, float))
        n = (1 - u)[:, None] * self.normals[e] + u[:, None] * self.normals[e + 1]
        return n / np.linalg.norm(n, axis=1)[:, None]


def curve_nodes(k: int) -> np.ndarray:
    """The k + 1 points of [0, 1] (Chebyshev–Lobatto) at which a cell's curve is sampled and fitted."""
    return 0.5 - 0.5 * np.cos(np.pi * np.arange(k + 1) / max(k, 1))


def side_curve(trace, k: int) -> SideCurve:
    """The :class:`SideCurve` of a side's trace, read from its (deformed) mesh's element maps."""
    mesh = trace.fes.mesh
    g = np.asarray(trace.breakpoints, float)
    u = curve_nodes(k)
    cell_points = []
    for (x_first, x_second, _, el), left, right in zip(trace.elements, g[:-1], g[1:]):
        trafo = mesh.GetTrafo(el)
        # the reference coordinate t runs from the second vertex (0) to the first (1)
        cell_points.append(np.array([np.asarray(trafo((left + ui * (right - left) - x_second)
                                                      / (x_first - x_second)).point)[:2] for ui in u]))
    return fit_curve(g, cell_points, k)


def fit_curve(g: np.ndarray, cell_points, k: int) -> SideCurve:
    """The :class:`SideCurve` on the partition ``g`` through each cell's points (k + 1, 2) at
    :func:`curve_nodes` (the curve's coordinates: along Γ, then along the normal from Ω1 to Ω2)."""
    u = curve_nodes(k)
    coefficients, tangents = [], []
    for pts in cell_points:
        c = np.polynomial.polynomial.polyfit(u, pts, k).T               # (2, k + 1)
        coefficients.append(c)
        d = c[:, 1:] * np.arange(1, k + 1)
        tangents.append((d.sum(axis=1), d[:, 0]))                         # dp/du at u = 1 and u = 0
    unit = lambda t: np.array([-t[1], t[0]]) / np.hypot(*t)  # noqa: E731  (tangent turned to the normal)
    normals = np.zeros((len(g), 2))
    for e, (end, start) in enumerate(tangents):
        normals[e] += unit(start)
        normals[e + 1] += unit(end)
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    return SideCurve(np.asarray(g, float), np.array(coefficients), normals)


def project(slave: SideCurve, master: SideCurve, x: np.ndarray) -> np.ndarray:
    """P(x): the master parameter y with (p_m(y) − p_s(x)) × n_s(x) = 0 (Newton from y = x)."""
    p, _ = slave.point(x)
    n = slave.normal(x)
    y = np.array(x, float)
    for _ in range(NEWTON_STEPS):
        q, dq = master.point(y)
        f = (q[:, 0] - p[:, 0]) * n[:, 1] - (q[:, 1] - p[:, 1]) * n[:, 0]
        df = dq[:, 0] * n[:, 1] - dq[:, 1] * n[:, 0]
        step = f / df
        y = y - step
        if np.all(np.abs(step) <= 4 * np.finfo(float).eps):
            break
    return y


def preimages(slave: SideCurve, master: SideCurve, targets: np.ndarray) -> np.ndarray:
    """The slave parameters x ∈ (0, 1) with P(x) = target, for the targets P hits (bisection: P
    is continuous and increasing)."""
    lo_val, hi_val = project(slave, master, np.array([0.0, 1.0]))
    t = np.asarray(targets, float)
    t = t[(t > lo_val) & (t < hi_val)]
    lo, hi = np.zeros_like(t), np.ones_like(t)
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        below = project(slave, master, mid) < t
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


@dataclass(frozen=True)
class ProjectedArc(Arc):
    """The arc as side ``side`` of a pair coupled by projection sees it: the two sides' curves and
    partitions (:func:`project_pair`), and the coupling points of the module docstring."""

    curves: tuple = field(default=(), compare=False, repr=False)
    side: int = 0
    rules: dict = field(default_factory=dict, compare=False, repr=False)
    """The slave's points, weights and master points per (slave, G_h, degree), shared by the pair's
    two views: both sides' B_i of a space integrate over the same points."""

    def slave_of(self, g_h) -> int:
        """0 (Ω1) when G_h is Ω1's trace and not Ω2's, else 1 (Ω2)."""
        p1, p2 = (c.breakpoints for c in self.curves)
        same = lambda a, b: len(a) == len(b) and np.allclose(a, b, rtol=0, atol=1e-12)  # noqa: E731
        return 0 if same(g_h, p1) and not same(g_h, p2) else 1

    def coupling_points(self, trace, space, degree: int) -> tuple:
        g_h = np.asarray(space.breakpoints, float)
        slave = self.slave_of(g_h)
        key = (slave, g_h.tobytes(), degree)
        if key not in self.rules:
            if len(self.rules) >= 16:
                self.rules.clear()
            self.rules[key] = self._rule(slave, g_h, degree)
        x, w, y, inside = self.rules[key]
        return (x, x, w) if self.side == slave else (x, y, w * inside)

    def _rule(self, slave: int, g_h, degree: int) -> tuple:
        """(x, w, P(x) clipped to Γ, whether the normal meets the master's curve) of the module docstring."""
        s, m = self.curves[slave], self.curves[1 - slave]
        cuts = self.common_refinement(s.breakpoints, g_h, preimages(s, m, m.breakpoints))
        t, w = gauss_legendre(degree // 2 + 1 + EXTRA_POINTS)
        a, b = cuts[:-1, None], cuts[1:, None]
        x = (0.5 * (a + b) + 0.5 * (b - a) * t[None, :]).ravel()
        w = (0.5 * (b - a) * w[None, :]).ravel() * np.linalg.norm(s.point(x)[1], axis=1)  # dS = |p_s'| dx
        y = project(s, m, x)
        inside = (y >= 0.0) & (y <= 1.0)  # the normal misses the master's curve: no master there
        return x, w, np.clip(y, 0.0, 1.0), inside

    def proven_kernel(self, space, k: int, traces, dim_w: int) -> int:
        """The segment's count where P = id (a flat Γ; matching meshes, whose curves are one, the
        deformation being interpolated edge by edge); else only dim M − n1 − n2 (the rank of Bᵀ is
        at most the number of Γ dofs): the projected traces do not share W1 ∩ W2."""
        p1, p2 = (t.partition for t in traces)
        if not self.curved or len(p1) == len(p2) and np.allclose(p1, p2, rtol=0, atol=1e-12):
            return super().proven_kernel(space, k, traces, dim_w)
        return max(space.dim - sum(len(t.gamma_dofs) for t in traces), 0)

    def paired(self, sides: list) -> list:
        return sides


def project_pair(arc: Arc, sides: list) -> list:
    """The two sides with traces whose Γ is the :class:`ProjectedArc` of the pair (fresh caches:
    the master's basis is asked at projected points)."""
    k = int(sides[0].trace.fes.globalorder)
    curves, rules = tuple(side_curve(s.trace, k) for s in sides), {}
    out = []
    for i, s in enumerate(sides):
        view = ProjectedArc(boundary=arc.boundary, y=arc.y, radius=arc.radius, coupling=arc.coupling,
                            curves=curves, side=i, rules=rules)
        out.append(replace(s, trace=replace(s.trace, gamma=view, basis_cache={}, sparse_cache={})))
    return out
