"""Export the two membranes of Bathe & Brezzi (2001) §3 tied by NGSolve's ``ContactBoundary``.

Run by the suite's own interpreter (NGSolve 6.2 is one of its dependencies; ``make env``)::

    .venv/bin/python examples/producers/ngsolve/export.py --out DIR --space T3-k1 --N 4 8 16 32 --offset 1
    .venv/bin/python examples/producers/ngsolve/export.py --list-spaces

One NGSolve mesh holds two separately meshed bodies that share no vertex: Ω1 = (0, 1)² with
N + K segments on Γ (region ``omega1``, its side at y = 1 the boundary ``gamma1``) and
Ω2 = (0, 1) × (1, 2) with N (``omega2``, ``gamma2``), each the suite's structured triangles
(diagonal lower-left to upper-right). u1, u2: continuous P_k (``H1`` on one body each, u = 0
on ``dir``, ∂Ω_i \\ Γ); λ an NGSolve space on ``gamma2`` only: ``H1(definedon=gamma2)`` for
continuous P_s (with ``dirichlet="dir"`` Γ's end vertices are Dirichlet dofs: Theorem 3's
space once they are eliminated), ``SurfaceL2(definedon=gamma2)`` for discontinuous P_s.

The tying is NGSolve's contact machinery, not a hand-written integral:
``ContactBoundary(gamma2, gamma1)`` with the integrator μ (u2 − u1.Other()) + λ (v2 − v1.Other())
on the product space, ``Update(bf=a)`` adding its special elements to the bilinear form. NGSolve
integrates on the first ("master") boundary's segments with its rule of order ``intorder``
(NGSolve's default, 4) and evaluates ``.Other()`` at the closest point of the second ("minion")
boundary: here the integration side is Ω2's Γ, the multipliers' (the paper's slave). On
non-matching meshes u1's trace has kinks inside an Ω2 segment, which that rule does not see.

Exported: A = the (u1, u2) block of the assembled matrix on NGSolve's free dofs (Dirichlet dofs
eliminated, so A = diag(K1, K2) is SPD), B = its (λ, u) block (sign as written: +u2 − u1),
G = ∫_Γ λ μ assembled by NGSolve. The manifest describes the multipliers and both bodies'
Γ traces in the general form (NGSolve's own basis evaluated at the equispaced Lagrange nodes of
each segment: hierarchical H1 bubbles and SurfaceL2's Legendre functions included), so the
certifier measures ``coupling_distance`` against the exact mortar coupling itself.
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # examples/producers: the contract

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402
from contract import level_entry, run, write_manifest  # noqa: E402

# id: (body degree k, multiplier degree s, continuous, μ = 0 at Γ's ends, description)
SPACES = {
    "T3-k1": (1, 1, True, True, "Thm 3, k = 1: P1 bodies, H1(definedon=gamma2) P1 multipliers, Gamma's ends Dirichlet (eliminated)"),
    "T3-k2": (2, 2, True, True, "Thm 3, k = 2: P2 bodies, H1(definedon=gamma2) P2 multipliers, Gamma's ends Dirichlet (eliminated)"),
    "R5.2-k1": (1, 1, True, False, "Rem 5.2, k = 1: P1 bodies, H1(definedon=gamma2) P1 multipliers, no end condition"),
    "R5.2-k2": (2, 2, True, False, "Rem 5.2, k = 2: P2 bodies, H1(definedon=gamma2) P2 multipliers, no end condition"),
    "T4-k2": (2, 0, False, False, "Thm 4, k = 2: P2 bodies, SurfaceL2 P0 multipliers"),
    "R5.4-k1": (1, 0, False, False, "Rem 5.4, k = 1: P1 bodies, SurfaceL2 P0 multipliers"),
    "R5.4-k2": (2, 1, False, False, "Rem 5.4, k = 2: P2 bodies, SurfaceL2 P1 multipliers (Legendre basis)"),
    "T5-k2": (2, 1, True, False, "Thm 5, k = 2: P2 bodies, H1(definedon=gamma2) P1 multipliers"),
}
INTORDER = 4
"""``ContactBoundary.Update``'s ``intorder``, NGSolve's default: exact for μ φ (degree s + k ≤ 4)
on a segment where φ is one polynomial."""


def _square(n: int, y0: float):
    """The suite's structured n × n triangles of (0, 1) × (y0, y0 + 1): vertices, triangles
    (counter-clockwise) and the boundary chains named by side."""
    s = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(s, y0 + s, indexing="xy")
    points = np.column_stack([X.ravel(), Y.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="xy")
    ll = (j * (n + 1) + i).ravel()
    lr, ul, ur = ll + 1, ll + n + 1, ll + n + 2
    triangles = np.vstack([np.column_stack([ll, lr, ur]), np.column_stack([ll, ur, ul])])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    chains = {"bottom": idx[0, :], "right": idx[:, -1], "top": idx[-1, ::-1], "left": idx[::-1, 0]}
    return points, triangles, chains


def two_bodies(n1: int, n2: int):
    """One NGSolve mesh of the two bodies, no vertex shared (Γ meshed twice: n1 and n2 segments)."""
    import ngsolve
    from netgen import meshing

    points, tris, edges, offset = [], [], {"gamma1": [], "gamma2": [], "dir": []}, 0
    for body, n, y0, gamma_side in ((1, n1, 0.0, "top"), (2, n2, 1.0, "bottom")):
        pts, tri, chains = _square(n, y0)
        points.append(pts)
        tris.append(tri + offset)
        for side, chain in chains.items():
            name = f"gamma{body}" if side == gamma_side else "dir"
            edges[name] += [(a + offset, b + offset) for a, b in zip(chain[:-1], chain[1:])]
        offset += len(pts)
    ngmesh = meshing.Mesh(dim=2)
    xy = np.vstack(points)
    ngmesh.AddPoints(np.column_stack([xy, np.zeros(len(xy))]))
    for body, tri in enumerate(tris, start=1):
        ngmesh.AddElements(dim=2, index=ngmesh.AddRegion(f"omega{body}", dim=2), data=tri.astype(np.int32), base=0)
    for name, segs in edges.items():
        ngmesh.AddElements(dim=1, index=ngmesh.AddRegion(name, dim=1), data=np.array(segs, np.int32), base=0)
    return ngsolve.Mesh(ngmesh)


def spaces(mesh, space: str):
    """(V1, V2, Q): compressed NGSolve spaces of u1, u2 and λ."""
    import ngsolve

    k, s, continuous, drop_ends, _ = SPACES[space]
    V1, V2 = (ngsolve.Compress(ngsolve.H1(mesh, order=k, definedon=f"omega{b}", dirichlet="dir")) for b in (1, 2))
    gamma2 = mesh.Boundaries("gamma2")
    if continuous:
        Q = ngsolve.H1(mesh, order=s, definedon=gamma2, dirichlet="dir" if drop_ends else "")
    else:
        Q = ngsolve.SurfaceL2(mesh, order=s, definedon=gamma2)
    return V1, V2, ngsolve.Compress(Q)


def _csr(mat) -> sp.csr_matrix:
    """An assembled NGSolve matrix as scipy CSR (copies: NGSolve's arrays die with the form)."""
    data, cols, rows = (np.array(a, copy=True) for a in mat.CSR())
    return sp.csr_matrix((data, cols, rows), shape=(mat.height, mat.width))


def assemble(mesh, V1, V2, Q, intorder: int = INTORDER):
    """The product space's matrix with the contact term, and G on Q (both on all dofs)."""
    import ngsolve
    from ngsolve import dx, ds, grad

    X = V1 * V2 * Q
    (u1, u2, lam), (v1, v2, mu) = X.TnT()
    a = ngsolve.BilinearForm(X)
    a += grad(u1) * grad(v1) * dx("omega1") + grad(u2) * grad(v2) * dx("omega2")
    cb = ngsolve.ContactBoundary(mesh.Boundaries("gamma2"), mesh.Boundaries("gamma1"))
    cb.AddIntegrator(mu * (u2 - u1.Other()) + lam * (v2 - v1.Other()))
    cb.Update(bf=a, intorder=intorder)
    a.Assemble()
    lm, mm = Q.TnT()
    g = ngsolve.BilinearForm(Q)
    g += lm * mm * ds("gamma2")
    g.Assemble()
    return _csr(a.mat), _csr(g.mat)


def assemble_level(n: int, space: str, offset: int = 0, intorder: int = INTORDER) -> dict:
    """A, B, G, the descriptions and the number of Ω1's dofs (A's first block) of one level: Ω1
    with n + offset segments on Γ, Ω2 with n."""
    k, s, *_ = SPACES[space]
    mesh = two_bodies(n + offset, n)
    V1, V2, Q = spaces(mesh, space)
    K, G_full = assemble(mesh, V1, V2, Q, intorder)
    free = [np.flatnonzero(np.array(V.FreeDofs(), bool)) for V in (V1, V2, Q)]
    u = np.concatenate([free[0], V1.ndof + free[1]])
    lam = V1.ndof + V2.ndof + free[2]
    col = -np.ones(V1.ndof + V2.ndof, int)  # NGSolve's dof -> column of B (A's dof), -1 eliminated
    col[u] = np.arange(len(u))
    row = -np.ones(Q.ndof, int)
    row[free[2]] = np.arange(len(free[2]))
    traces = [dict(gamma_form(mesh, V, f"gamma{b}", k, col[off:off + V.ndof]), sign=sign)
              for b, V, off, sign in ((1, V1, 0, -1), (2, V2, V1.ndof, 1))]
    for t in traces:
        t["columns"] = t.pop("numbers")
    mult = gamma_form(mesh, Q, "gamma2", s, row)
    numbers = np.asarray(mult.pop("numbers"))  # the general form's dofs name B's rows directly
    mult["dofs"] = np.where(np.asarray(mult["dofs"]) >= 0, numbers[np.asarray(mult["dofs"])], -1).tolist()
    return {"A": K[u][:, u], "B": K[lam][:, u], "G": G_full[free[2]][:, free[2]], "multipliers": mult,
            "traces": traces, "n1": len(free[0])}


def _nodes(s: int) -> np.ndarray:
    """Equispaced Lagrange nodes on [0, 1] (the midpoint at s = 0): the manifest's local shapes."""
    return np.array([0.5]) if s == 0 else np.linspace(0.0, 1.0, s + 1)


def gamma_form(mesh, V, region: str, s: int, number) -> dict:
    """The general ``norm: H`` form of V's basis on the boundary ``region`` of Γ: per segment
    left to right the live functions (``dofs``: consecutive numbers, −1 for none) and their
    values at the segment's Lagrange nodes (``coefficients``: a degree-s polynomial is its
    values there), read off NGSolve's own basis. ``number[d]``: the B row/column of V's dof d
    (−1: eliminated); returned as ``numbers`` (the form's j-th function's)."""
    import ngsolve

    t = _nodes(s)
    ir = ngsolve.IntegrationRule(points=[(float(ti),) for ti in t], weights=[1.0] * len(t))
    elements = [e for e in mesh.Elements(ngsolve.BND) if e.mat == region]
    mips = mesh.MapToAllElements(ir, mesh.Boundaries(region))  # region's elements in mesh order
    x = np.asarray(ngsolve.x(mips)).reshape(len(elements), len(t))
    seg_order = np.argsort(x.mean(axis=1))
    gf = ngsolve.GridFunction(V)
    live = sorted({d for e in elements for d in V.GetDofNrs(e) if d >= 0 and number[d] >= 0})
    values = {}
    for d in live:  # one unit vector per Γ dof: V's basis function d along the region
        gf.vec[:] = 0.0
        gf.vec[d] = 1.0
        values[d] = np.asarray(gf(mips)).reshape(len(elements), len(t))
    index = {}  # V's dof -> the form's function number, first met left to right
    dofs = -np.ones((len(elements), s + 1), int)
    coef = np.zeros((len(elements), s + 1, s + 1))
    breakpoints = [0.0]
    for i, e in enumerate(seg_order):
        order = np.argsort(x[e])  # the segment's nodes left to right (its orientation is NGSolve's)
        ends = [v.point[0] for v in (mesh[vv] for vv in elements[e].vertices)]
        breakpoints.append(max(ends))
        mine = [d for d in V.GetDofNrs(elements[e]) if d >= 0 and number[d] >= 0]
        for a, d in enumerate(mine):
            dofs[i, a] = index.setdefault(d, len(index))
            coef[i, a] = values[d][e, order]
    numbers = np.empty(len(index), int)
    for d, j in index.items():
        numbers[j] = number[d]
    return {"breakpoints": breakpoints, "degree": int(s), "dofs": dofs.tolist(), "coefficients": coef.tolist(),
            "numbers": [int(c) for c in numbers]}


def ng_version() -> str:
    """NGSolve's release (its package metadata)."""
    import ngsolve

    return str(ngsolve.__version__)


def export(args) -> Path:
    """Every level's matrices and ``levels.yaml`` into ``args.out`` (the contract's writers)."""
    k, s, continuous, drop_ends, _ = SPACES[args.space]
    levels = []
    for n in args.N:
        lv = assemble_level(n, args.space, args.offset)
        levels.append(level_entry(args.out, n, lv["A"], lv["B"], lv["G"], lv["multipliers"], lv["traces"]))
    kind = "continuous" if continuous else "discontinuous"
    return write_manifest(args.out, f"ngsolve-{ng_version()} {args.space} P{k} bodies, {kind} P{s} multipliers on "
                          f"Omega2's Gamma, Omega1 N+{args.offset} / Omega2 N segments, ContactBoundary "
                          f"u2 - u1.Other() (intorder {INTORDER})", levels)


def main(argv=None) -> int:
    return run(argv, SPACES, export)


if __name__ == "__main__":
    sys.exit(main())
