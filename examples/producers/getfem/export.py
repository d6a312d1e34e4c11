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

import argparse
import os
import sys
from pathlib import Path

import getfem as gf
import numpy as np
import scipy.io
import scipy.sparse as sp
import yaml

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
N_MAX = 512
"""Largest N accepted (larger is a typo here: N = 512 at k = 2 is 2.1 million dofs)."""
GAMMA, DIRICHLET, ENDS = 1, 2, 3


class ArgumentError(Exception):
    """A bad command line: one line on stderr, exit 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise ArgumentError(message)


def parse_args(argv):
    """The contract's command line; :class:`ArgumentError` for anything else."""
    p = _Parser(prog="export.py")
    p.add_argument("--out", type=Path)
    p.add_argument("--space")
    p.add_argument("--N", type=int, nargs="+")
    p.add_argument("--offset", type=int, default=0)
    p.add_argument("--list-spaces", action="store_true")
    args = p.parse_args(argv)
    if args.list_spaces:
        return args
    for key in ("out", "space", "N"):
        if getattr(args, key) is None:
            raise ArgumentError(f"--{key} is required (or --list-spaces)")
    if args.space not in SPACES:
        raise ArgumentError(f"--space {args.space!r} is not one of {', '.join(SPACES)}")
    bad = [n for n in args.N if not 1 <= n <= N_MAX or not 1 <= n + args.offset <= N_MAX]
    if bad:
        raise ArgumentError(f"--N {bad[0]} --offset {args.offset}: N and N + offset must be in 1..{N_MAX}")
    if sorted(set(args.N)) != args.N:
        raise ArgumentError(f"--N {' '.join(map(str, args.N))}: give distinct N in increasing order")
    if args.out.exists() and not args.out.is_dir():
        raise ArgumentError(f"--out {args.out}: exists and is not a directory")
    return args


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


def describe_traces(coords: np.ndarray, n1: int, k: int) -> list:
    """The bodies' trace bases on Γ for the certifier's distance to the exact mortar coupling
    (``traces``, normH spec): per body continuous P_k on its Γ nodes, ``columns`` the column of
    B (A's dof) of each trace function left to right, −1 at Γ's ends (Dirichlet dofs: B's
    columns there are zeroed), sign −1 for Ω1 and +1 for Ω2 (B = [−B1 | B2])."""
    out = []
    for lo, hi, sign in ((0, n1, -1), (n1, len(coords), 1)):
        cols = lo + np.where(np.isclose(coords[lo:hi, 1], 1.0))[0]
        x = coords[cols, 0]
        order = np.argsort(x, kind="stable")
        cols, x = cols[order], x[order]
        columns = np.where(np.isclose(x, 0.0) | np.isclose(x, 1.0), -1, cols)
        out.append({"basis": "lagrange", "degree": k, "breakpoints": x[::k].tolist(), "ends": "keep",
                    "columns": [int(c) for c in columns], "sign": sign})
    return out


def write_atomic(path: Path, writer) -> None:
    """Write through a temporary file and rename (a killed run leaves no half file); the
    temporary name keeps the suffix (``mmwrite`` appends ``.mtx`` to a name without it)."""
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    writer(tmp)
    os.replace(tmp, path)


def export(out: Path, space: str, ns, offset: int) -> Path:
    """Write every level's matrices and ``levels.yaml`` into ``out``; return the manifest path."""
    out.mkdir(parents=True, exist_ok=True)
    k, s, continuous, drop_ends, _ = SPACES[space]
    levels = []
    for n in ns:
        lv = assemble_level(n, space, offset)
        entry = {"h": 1.0 / n}
        for key in ("A", "B", "G"):
            name = f"{key}{n}.mtx"
            write_atomic(out / name, lambda t, M=lv[key]: scipy.io.mmwrite(t, M, precision=17))
            entry[key] = name
        entry["multipliers"] = lv["multipliers"]
        entry["traces"] = describe_traces(lv["coords"], lv["n1"], k)
        levels.append(entry)
    kind = "continuous" if continuous else "discontinuous"
    manifest = {
        "name": f"getfem-{gf_version()} {space} P{k} bodies, {kind} P{s} multipliers on the slave side, "
                f"Omega1 N+{offset} / Omega2 N segments, Interpolate(u1, X) tying",
        "norm": "H",
        "gamma": {"shape": "segment", "length": 1.0},
        "levels": levels,
    }
    target = out / "levels.yaml"
    write_atomic(target, lambda t: t.write_text(yaml.safe_dump(manifest, sort_keys=False, default_flow_style=None)))
    return target


def gf_version() -> str:
    """GetFEM's release (Debian's package ships no dist-info, so ``importlib.metadata`` finds
    nothing: GetFEM's own ``getfem_env``)."""
    return str(gf.getfem_env("release"))


def main(argv=None) -> int:
    try:
        args = parse_args(sys.argv[1:] if argv is None else argv)
    except ArgumentError as err:
        print(f"export.py: {err}", file=sys.stderr)
        return 2
    if args.list_spaces:
        for sid, spec in SPACES.items():
            print(f"{sid}\t{spec[-1]}")
        return 0
    gf.util_trace_level(0)  # the bricks' trace lines would go to stdout
    try:
        export(args.out, args.space, args.N, args.offset)
    except OSError as err:
        print(f"export.py: --out {args.out}: {err.strerror or err}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
