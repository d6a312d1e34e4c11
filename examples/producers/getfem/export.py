"""Export the two membranes of Bathe & Brezzi (2001) §3 as GetFEM assembles them, non-matching.

Run by the system interpreter that Debian's ``python3-getfem`` installs into
(``make producers-getfem``)::

    /usr/bin/python3 examples/producers/getfem/export.py --out DIR --space R5.2-k1 --N 4 8 16 32 --offset 1
    /usr/bin/python3 examples/producers/getfem/export.py --list-spaces

Two meshes (``Mesh('regular simplices')``): Ω1 = (0, 1)² with N + K segments on Γ (the
master), Ω2 = (0, 1) × (1, 2) with N (the slave, carrying the multipliers). One
``Model`` holds u1 (P_k on Ω1), u2 (P_k on Ω2) and λ, a multiplier ``MeshFem`` on Ω2 kept
only on Γ (``add_filtered_fem_variable``; for T3 a ``MeshFem('partial')`` without Γ's end
dofs). The tying is the GWFL term ``λ (u2 − Interpolate(u1, to1))`` on Γ of Ω2 with the
identity transformation ``add_interpolate_transformation_from_expression(.., 'X')``:
integrated with the slave's face quadrature only (``IM_TRIANGLE(2k)``), so on non-matching
meshes u1's kinks inside a slave segment are integrated inexactly — exactly what GetFEM
assembles. u_i = 0 on ∂Ω_i \\ Γ by ``add_Dirichlet_condition_with_simplification`` (unit
rows and zeroed columns in the tangent matrix, B's entries on them zeroed too).

Exported: A = the (u1, u2) block of ``md.tangent_matrix()``, B the (λ, u) block
(sign as GetFEM has it: +u2 − u1), G = ``asm_generic('lambda*Test_lambda')`` on Γ, the L²
mass of the multipliers.
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # examples/producers: the contract

import getfem as gf
import numpy as np
import scipy.sparse as sp
from contract import describe_traces, level_entry, run, write_manifest  # noqa: E402

# id: (body degree k, multiplier degree s, continuous, μ = 0 at Γ's ends, description)
SPACES = {
    "T3-k1": (1, 1, True, True, "Thm 3, k = 1: P1 bodies, continuous P1 multipliers without Γ's end dofs (MeshFem partial)"),
    "T3-k2": (2, 2, True, True, "Thm 3, k = 2: P2 bodies, continuous P2 multipliers without Γ's end dofs (MeshFem partial)"),
    "R5.2-k1": (1, 1, True, False, "Rem 5.2, k = 1: P1 bodies, continuous P1 multipliers (filtered on Γ), no end condition"),
    "R5.2-k2": (2, 2, True, False, "Rem 5.2, k = 2: P2 bodies, continuous P2 multipliers (filtered on Γ), no end condition"),
    "T4-k2": (2, 0, False, False, "Thm 4, k = 2: P2 bodies, discontinuous P0 multipliers"),
    "R5.4-k1": (1, 0, False, False, "Rem 5.4, k = 1: P1 bodies, discontinuous P0 multipliers"),
    "R5.4-k2": (2, 1, False, False, "Rem 5.4, k = 2: P2 bodies, discontinuous P1 multipliers"),
    "T5-k2": (2, 1, True, False, "Thm 5, k = 2: P2 bodies, continuous P1 multipliers"),
}
GAMMA, DIRICHLET, ENDS = 1, 2, 3


def membrane(n: int, y0: float):
    """(0, 1) × (y0, y0 + 1), n × n squares in two triangles, with the regions Γ (its side
    at y = 1), the Dirichlet boundary (the other sides) and Γ's two lateral neighbours."""
    m = gf.Mesh("regular simplices", np.linspace(0.0, 1.0, n + 1), np.linspace(y0, y0 + 1.0, n + 1))
    faces = m.outer_faces()
    mid = np.array([m.pts()[:, m.pid_in_faces(f[:, None])].mean(axis=1) for f in faces.T])
    on_gamma = np.isclose(mid[:, 1], 1.0)
    m.set_region(GAMMA, faces[:, on_gamma])
    m.set_region(DIRICHLET, faces[:, ~on_gamma])
    return m


def spmat_to_scipy(M) -> sp.csr_matrix:
    """A GetFEM ``Spmat`` as scipy CSR (its own CSC arrays, no dense copy)."""
    M.to_csc()
    jc, ir = M.csc_ind()
    return sp.csc_matrix((M.csc_val(), ir, jc), shape=tuple(M.size())).tocsr()


def multiplier_fem(m2, s: int, continuous: bool, drop_ends: bool):
    """(the multiplier ``MeshFem`` on Ω2 and the model variable's kind, the Lagrange ``MeshFem``
    it is built from, its basic dofs in the model's λ order)."""
    mfl = gf.MeshFem(m2, 1)
    if continuous:
        mfl.set_classical_fem(s)
    else:
        mfl.set_classical_discontinuous_fem(s)
    dofs = mfl.basic_dof_on_region(GAMMA)  # a filtered variable keeps these, in this order
    if not drop_ends:
        return mfl, "filtered", mfl, dofs
    # T3: the dofs on Γ but not at its ends, as a partial MeshFem (GetFEM's way to keep a dof subset)
    x = mfl.basic_dof_nodes()[0, dofs]
    keep = dofs[~(np.isclose(x, 0.0) | np.isclose(x, 1.0))]
    return gf.MeshFem("partial", mfl, keep), "partial", mfl, keep


def assemble_level(n: int, space: str, offset: int = 0) -> dict:
    """A, B, G, the multiplier description, the body dofs' coordinates (A's order) and the
    number of Ω1's dofs (A's first block) of one level."""
    k, s, continuous, drop_ends, _ = SPACES[space]
    m1, m2 = membrane(n + offset, 0.0), membrane(n, 1.0)
    mf1, mf2 = gf.MeshFem(m1, 1), gf.MeshFem(m2, 1)
    mf1.set_classical_fem(k)
    mf2.set_classical_fem(k)
    mfl, kind, base, lam_dofs = multiplier_fem(m2, s, continuous, drop_ends)
    im = gf.Integ(f"IM_TRIANGLE({2 * k})")
    mim1, mim2 = gf.MeshIm(m1, im), gf.MeshIm(m2, im)

    md = gf.Model("real")
    md.add_fem_variable("u1", mf1)
    md.add_fem_variable("u2", mf2)
    if kind == "partial":
        md.add_fem_variable("lambda", mfl)
    else:
        md.add_filtered_fem_variable("lambda", mfl, GAMMA)
    md.add_Laplacian_brick(mim1, "u1")
    md.add_Laplacian_brick(mim2, "u2")
    md.add_Dirichlet_condition_with_simplification("u1", DIRICHLET)
    md.add_Dirichlet_condition_with_simplification("u2", DIRICHLET)
    md.add_interpolate_transformation_from_expression("to1", m2, m1, "X")
    md.add_linear_term(mim2, "lambda*(u2 - Interpolate(u1, to1))", GAMMA)
    md.assembly("build_matrix")
    K = spmat_to_scipy(md.tangent_matrix())
    G_full = spmat_to_scipy(gf.asm_generic(mim2, 2, "lambda*Test_lambda", GAMMA, md))

    u = np.concatenate([np.arange(a, a + b) for a, b in (md.interval_of_variable(v) for v in ("u1", "u2"))])
    a, b = md.interval_of_variable("lambda")
    lam = np.arange(a, a + b)
    A, B, G = K[u][:, u], K[lam][:, u], G_full[lam][:, lam]
    coords = np.hstack([mf1.basic_dof_nodes(), mf2.basic_dof_nodes()]).T
    return {"A": A, "B": B, "G": G, "coords": coords, "n1": int(md.interval_of_variable("u1")[1]),
            "multipliers": describe_multipliers(m2, base, lam_dofs, s, continuous, drop_ends)}


def describe_multipliers(m2, base, lam_dofs, s: int, continuous: bool, drop_ends: bool) -> dict:
    """The ``norm: H`` description of λ's basis (normH spec), its breakpoints being Γ's
    vertices in Ω2's mesh, ``rows`` the model's λ numbering left to right (``lam_dofs``: the
    basic dofs of ``base`` in the model's λ order)."""
    pts = m2.pts()
    breakpoints = np.unique(pts[0, np.isclose(pts[1], 1.0)])
    x = base.basic_dof_nodes()[0, lam_dofs]
    if continuous:
        rows = [int(r) for r in np.argsort(x, kind="stable")]
        return {"basis": "lagrange", "degree": s, "breakpoints": breakpoints.tolist(),
                "ends": "drop" if drop_ends else "keep", "rows": rows}
    # discontinuous: per Γ segment left to right, within it by the node's x (P0: its one dof)
    seg = _dg_segments(base, lam_dofs, breakpoints)
    order = np.lexsort((x, seg))
    return {"basis": "discontinuous", "degree": s, "breakpoints": breakpoints.tolist(),
            "rows": [int(i) for i in order]}


def _dg_segments(mfl, model_dofs, breakpoints) -> np.ndarray:
    """The Γ segment each discontinuous dof belongs to, from the x-midpoint of its element's
    kept nodes (a DG node on a breakpoint has a twin of the neighbouring element there)."""
    nodes = mfl.basic_dof_nodes()
    seg = np.empty(len(model_dofs), int)
    where = {int(d): i for i, d in enumerate(model_dofs)}
    for cv in mfl.linked_mesh().cvid():
        dofs = [int(d) for d in mfl.basic_dof_from_cv(cv) if int(d) in where]
        if not dofs:
            continue
        xm = nodes[0, dofs].mean()
        for d in dofs:
            seg[where[d]] = np.clip(np.searchsorted(breakpoints, xm, side="right") - 1, 0, len(breakpoints) - 2)
    return seg


def export(args) -> Path:
    """Every level's matrices and ``levels.yaml`` into ``args.out`` (the contract's writers)."""
    k, s, continuous, drop_ends, _ = SPACES[args.space]
    levels = []
    for n in args.N:
        lv = assemble_level(n, args.space, args.offset)
        levels.append(level_entry(args.out, n, lv["A"], lv["B"], lv["G"], lv["multipliers"],
                                  describe_traces(lv["coords"], lv["n1"], k)))
    kind = "continuous" if continuous else "discontinuous"
    return write_manifest(args.out, f"getfem-{gf_version()} {args.space} P{k} bodies, {kind} P{s} multipliers on the "
                          f"slave side, Omega1 N+{args.offset} / Omega2 N segments, Interpolate(u1, X) tying", levels)


def gf_version() -> str:
    """GetFEM's release (Debian's package ships no dist-info, so ``importlib.metadata`` finds
    nothing: GetFEM's own ``getfem_env``)."""
    return str(gf.getfem_env("release"))


def main(argv=None) -> int:
    gf.util_trace_level(0)  # the bricks' trace lines would go to stdout
    return run(argv, SPACES, export)


if __name__ == "__main__":
    sys.exit(main())
