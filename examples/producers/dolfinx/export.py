"""Export the two membranes of Bathe & Brezzi (2001) §3 as DOLFINx assembles them.

Run by the DOLFINx interpreter (``make producers-dolfinx`` builds ``.venv-dolfinx``)::

    .venv-dolfinx/bin/python examples/producers/dolfinx/export.py --out DIR --space T3-k2 --N 4 8 16 32
    .venv-dolfinx/bin/python examples/producers/dolfinx/export.py --list-spaces

One mesh of (0, 1) × (0, 2) (``create_rectangle``, N × 2N squares, "right" diagonals), two
cell submeshes Ω1 (y < 1), Ω2 (y > 1) carrying P_k bodies, and the facet submesh Γ (y = 1)
carrying the multipliers. b(v, μ) = ∫_Γ (v2 − v1) μ is a mixed-dimensional interior-facet
integral over the parent mesh with entity maps, Ω1 on the "+" side. Everything is assembled
the way a DOLFINx user assembles a block system, one form per block with the boundary
conditions passed to ``assemble_matrix``:

* A = diag(K1, K2): u_i = 0 on ∂Ω_i \\ Γ by ``dirichletbc``, i.e. identity rows and zeroed
  columns (diagonal 1.0, DOLFINx's default);
* B = [−B1 | B2] (m × n): the columns of those Dirichlet dofs zeroed by the same bcs; for T3
  the multipliers' own condition μ = 0 at Γ's ends (a ``dirichletbc`` on the multiplier
  space) zeroes the two end rows;
* G (m × m): the L² mass of the multipliers, unit rows at the T3 end dofs.

Only matching meshes: a form lives on one mesh and its submeshes, and DOLFINx has no
supermesh of two unrelated meshes' Γ, so ``--offset K`` with K ≠ 0 is refused.
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # examples/producers: the contract

import dolfinx_solver  # noqa: F401  (must come first: loads mpi4py's libmpi before DOLFINx's bindings)
import numpy as np
import scipy.sparse as sp
import ufl
from dolfinx import __version__ as DOLFINX_VERSION
from dolfinx import fem, mesh
from dolfinx.cpp.fem import compute_integration_domains
from mpi4py import MPI
from contract import describe_traces, level_entry, run, write_manifest  # noqa: E402

# id: (body degree k, multiplier family, multiplier degree s, μ = 0 at Γ's ends, description)
SPACES = {
    "T3-k1": (1, "Lagrange", 1, True, "Thm 3, k = 1: P1 bodies, continuous P1 multipliers, μ = 0 at Γ's ends (dirichletbc)"),
    "T3-k2": (2, "Lagrange", 2, True, "Thm 3, k = 2: P2 bodies, continuous P2 multipliers, μ = 0 at Γ's ends (dirichletbc)"),
    "R5.2-k1": (1, "Lagrange", 1, False, "Rem 5.2, k = 1: P1 bodies, continuous P1 multipliers, no end condition"),
    "R5.2-k2": (2, "Lagrange", 2, False, "Rem 5.2, k = 2: P2 bodies, continuous P2 multipliers, no end condition"),
    "T4-k2": (2, "DG", 0, False, "Thm 4, k = 2: P2 bodies, discontinuous P0 multipliers"),
    "R5.4-k1": (1, "DG", 0, False, "Rem 5.4, k = 1: P1 bodies, discontinuous P0 multipliers"),
    "R5.4-k2": (2, "DG", 1, False, "Rem 5.4, k = 2: P2 bodies, discontinuous P1 multipliers"),
    "T5-k2": (2, "Lagrange", 1, False, "Thm 5, k = 2: P2 bodies, continuous P1 multipliers"),
}
GAMMA_TAG = 1


def interface_measure(msh, omega1_map):
    """dS over Γ with the Ω1 cell of every facet first ("+"): the one-sided ordering
    DOLFINx leaves to the user (``compute_integration_domains`` orders by cell index)."""
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = mesh.locate_entities(msh, tdim - 1, lambda x: np.isclose(x[1], 1.0))
    data = compute_integration_domains(fem.IntegralType.interior_facet, msh.topology._cpp_object,
                                       facets.astype(np.int32)).reshape(-1, 4).copy()
    in1 = omega1_map.sub_topology_to_topology(data[:, 0], inverse=True) >= 0
    data[~in1] = data[~in1][:, [2, 3, 0, 1]]
    if np.any(omega1_map.sub_topology_to_topology(data[:, 0], inverse=True) < 0):
        raise RuntimeError("an interface facet without an Ω1 cell")
    return ufl.Measure("dS", domain=msh, subdomain_data=[(GAMMA_TAG, data.ravel())]), facets


def dirichlet_bc(V, exclude_y1: bool):
    """u = 0 on the boundary facets of V's mesh off Γ (their closure: Γ's end vertices too)."""
    m = V.mesh
    tdim = m.topology.dim
    m.topology.create_connectivity(tdim - 1, tdim)
    bfacets = mesh.exterior_facet_indices(m.topology)
    mid = mesh.compute_midpoints(m, tdim - 1, bfacets)
    off_gamma = bfacets[~np.isclose(mid[:, 1], 1.0)] if exclude_y1 else bfacets
    dofs = fem.locate_dofs_topological(V, tdim - 1, off_gamma)
    return fem.dirichletbc(0.0, dofs, V)


def to_scipy(form, bcs):
    """``fem.assemble_matrix`` with the bcs, as scipy CSR (serial: no ghosts)."""
    return fem.assemble_matrix(form, bcs=bcs).to_scipy().tocsr()


def assemble_level(n: int, space: str) -> dict:
    """A, B, G, the multiplier description and the body dofs' coordinates (A's order) of one
    level (module docstring)."""
    k, family, s, ends_bc, _ = SPACES[space]
    comm = MPI.COMM_SELF
    msh = mesh.create_rectangle(comm, [np.array([0.0, 0.0]), np.array([1.0, 2.0])], [n, 2 * n],
                                mesh.CellType.triangle, diagonal=mesh.DiagonalType.right)
    tdim = msh.topology.dim
    cells1 = mesh.locate_entities(msh, tdim, lambda x: x[1] <= 1.0)
    cells2 = mesh.locate_entities(msh, tdim, lambda x: x[1] >= 1.0)
    sub1, map1 = mesh.create_submesh(msh, tdim, cells1)[:2]
    sub2, map2 = mesh.create_submesh(msh, tdim, cells2)[:2]
    dS, facets = interface_measure(msh, map1)
    gamma, mapg = mesh.create_submesh(msh, tdim - 1, facets)[:2]
    maps = [map1, map2, mapg]

    V1, V2 = fem.functionspace(sub1, ("Lagrange", k)), fem.functionspace(sub2, ("Lagrange", k))
    Q = fem.functionspace(gamma, (family, s))
    bc1, bc2 = dirichlet_bc(V1, True), dirichlet_bc(V2, True)
    bcq = []
    if ends_bc:  # μ = 0 at Γ's ends: a dirichletbc on the multipliers, as a DOLFINx user writes it
        ends = mesh.locate_entities_boundary(gamma, 0, lambda x: np.isclose(x[0], 0.0) | np.isclose(x[0], 1.0))
        bcq = [fem.dirichletbc(0.0, fem.locate_dofs_topological(Q, 0, ends), Q)]

    u1, v1 = ufl.TrialFunction(V1), ufl.TestFunction(V1)
    u2, v2 = ufl.TrialFunction(V2), ufl.TestFunction(V2)
    p, q = ufl.TrialFunction(Q), ufl.TestFunction(Q)
    K1 = to_scipy(fem.form(ufl.inner(ufl.grad(u1), ufl.grad(v1)) * ufl.dx), [bc1])
    K2 = to_scipy(fem.form(ufl.inner(ufl.grad(u2), ufl.grad(v2)) * ufl.dx), [bc2])
    B1 = to_scipy(fem.form(ufl.inner(u1("+"), q("+")) * dS(GAMMA_TAG), entity_maps=maps), [bc1] + bcq)
    B2 = to_scipy(fem.form(ufl.inner(u2("-"), q("-")) * dS(GAMMA_TAG), entity_maps=maps), [bc2] + bcq)
    G = to_scipy(fem.form(ufl.inner(p, q) * ufl.dx(domain=gamma)), bcq)

    A = sp.block_diag([K1, K2], format="csr")
    B = sp.hstack([-B1, B2], format="csr")
    coords = np.vstack([V1.tabulate_dof_coordinates(), V2.tabulate_dof_coordinates()])
    return {"A": A, "B": B, "G": G, "coords": coords, "n1": K1.shape[0],
            "multipliers": describe_multipliers(Q, family, s)}


def describe_multipliers(Q, family: str, s: int) -> dict:
    """The ``norm: H`` description of Q's basis (normH spec): the helper form, the breakpoints
    being Γ's vertices as DOLFINx placed them, ``rows`` DOLFINx's dof numbers left to right.
    Q is the whole P_s space (``ends: keep``), as in DOLFINx: the T3 condition μ = 0 at Γ's ends
    is a dirichletbc on Q, which leaves the end dofs' rows of B zero and of G unit rows; the
    certifier's constrained-row rule removes them (``removed_multipliers``, with a note)."""
    gamma = Q.mesh
    x = gamma.geometry.x[:, 0]
    breakpoints = np.unique(np.round(x, 15))
    cell_dofs = Q.dofmap.list  # (cells, dofs per cell)
    dof_x = Q.tabulate_dof_coordinates()[:, 0]
    if family == "DG":
        # per interval left to right, within it by the node's position (the constant: one dof)
        mid = mesh.compute_midpoints(gamma, 1, np.arange(cell_dofs.shape[0], dtype=np.int32))[:, 0]
        rows = [int(d) for c in np.argsort(mid) for d in sorted(cell_dofs[c], key=lambda d: dof_x[d])]
        return {"basis": "discontinuous", "degree": s, "breakpoints": breakpoints.tolist(), "rows": rows}
    order = np.argsort(dof_x, kind="stable")
    rows = [int(d) for d in order]
    return {"basis": "lagrange", "degree": s, "breakpoints": breakpoints.tolist(), "ends": "keep", "rows": rows}


def export(args) -> Path:
    """Every level's matrices and ``levels.yaml`` into ``args.out`` (the contract's writers)."""
    k, family, s, ends_bc, _ = SPACES[args.space]
    levels = []
    for n in args.N:
        lv = assemble_level(n, args.space)
        levels.append(level_entry(args.out, n, lv["A"], lv["B"], lv["G"], lv["multipliers"],
                                  describe_traces(lv["coords"], lv["n1"], k)))
    name = (f"dolfinx-{DOLFINX_VERSION} {args.space} P{k} bodies, {family} {s} multipliers on a facet submesh"
            + (" (mu = 0 at Gamma's ends by dirichletbc)" if ends_bc else ""))
    return write_manifest(args.out, name, levels)


def main(argv=None) -> int:
    return run(argv, SPACES, export, offsets=(0,), offset_reason=(
        "DOLFINx assembles a form over one mesh and its submeshes; non-matching Γ meshes would need a "
        "supermesh DOLFINx does not provide (only --offset 0)"))


if __name__ == "__main__":
    sys.exit(main())
