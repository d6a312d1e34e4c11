"""CalculiX input decks for the 3D membranes: Ω1 = (0,1)³ (master) and Ω2 = (0,1)²×(1,2) (slave,
the multipliers' side), N × N × N serendipity bricks each (C3D20 / DC3D20), Γ = (0,1)² × {1}.

Two decks per mesh: the contact deck (C3D20, ``*CONTACT PAIR, TYPE=<mortar>`` slave = Ω2's face
z = 1, master = Ω1's), run only as far as CalculiX's mortar coupling is assembled (our dump,
``INFSUP_CCX_DUMP``; ``INFSUP_CCX_DUMP_STOP`` ends the run there), and the heat deck (DC3D20, conductivity
1, u = 0 on ∂Ω_i∖Γ): CalculiX's conduction matrix, the Laplace stiffness of the paper's membranes,
written by ``*HEAT TRANSFER, STEADY STATE, SOLVER=MATRIXSTORAGE`` (``.con`` and ``.dof``).
Needs numpy only.
"""
from __future__ import annotations

import numpy as np

# C3D20 nodes on the reference brick (CalculiX's order: corners z = -1, corners z = +1, the mid-edges
# of the bottom, of the top, then the vertical ones)
C3D20 = np.array([
    (-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1),
    (0, -1, -1), (1, 0, -1), (0, 1, -1), (-1, 0, -1), (0, -1, 1), (1, 0, 1), (0, 1, 1), (-1, 0, 1),
    (-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)])
BOTTOM, TOP = "S1", "S2"
"""CalculiX's face labels of the brick's z = -1 face (nodes 1-2-3-4) and z = +1 face (5-8-7-6)."""


def body(n: int, z0: float, first_node: int, first_elem: int):
    """One body (0,1)² × (z0, z0 + 1) of n³ C3D20 bricks: (node ids, coordinates (·, 3), element ids,
    connectivity (·, 20)). Nodes live on the half-step grid, those with at most one odd index
    (vertices and edge midpoints: serendipity, no face or cell centres)."""
    m = 2 * n + 1
    ijk = np.stack(np.meshgrid(np.arange(m), np.arange(m), np.arange(m), indexing="ij"), -1).reshape(-1, 3)
    keep = (ijk % 2).sum(axis=1) <= 1
    number = -np.ones(m ** 3, dtype=np.int64)
    ids = first_node + np.arange(keep.sum())
    number[np.flatnonzero(keep)] = ids
    coords = ijk[keep] / (2.0 * n) + np.array([0.0, 0.0, z0])
    cells = np.stack(np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 3)
    grid = 2 * cells[:, None, :] + 1 + C3D20[None, :, :]  # (cell, node, ijk) on the half-step grid
    conn = number[(grid[..., 0] * m + grid[..., 1]) * m + grid[..., 2]]
    assert (conn >= 0).all()
    return ids, coords, first_elem + np.arange(len(cells)), conn


def mesh(n1: int, n2: int):
    """Both bodies, Ω1 with n1³ bricks, Ω2 with n2³: dict with ``ids``, ``coords`` (node id i at row
    i - 1), ``body`` (1 or 2 per node) and per body its element ids and connectivity."""
    ids1, x1, e1, c1 = body(n1, 0.0, 1, 1)
    ids2, x2, e2, c2 = body(n2, 1.0, ids1[-1] + 1, e1[-1] + 1)
    return {"ids": np.concatenate([ids1, ids2]), "coords": np.vstack([x1, x2]),
            "body": np.repeat([1, 2], [len(ids1), len(ids2)]), "elements": ((e1, c1), (e2, c2))}


def boundary_nodes(m: dict, clamped: bool) -> np.ndarray:
    """Node ids held fixed: clamped, every node of ∂Ω_i∖Γ (the paper's u_i = 0, ∂Γ included);
    otherwise the far faces only (z = 0 of Ω1, z = 2 of Ω2)."""
    x, b = m["coords"], m["body"]
    far = np.isclose(x[:, 2], np.where(b == 1, 0.0, 2.0))
    side = np.isclose(x[:, 0], 0) | np.isclose(x[:, 0], 1) | np.isclose(x[:, 1], 0) | np.isclose(x[:, 1], 1)
    return m["ids"][far | (side if clamped else False)]


def _lines(values, per_line: int = 8) -> str:
    """Comma-separated values, at most ``per_line`` per line (CalculiX's line length)."""
    values = [str(v) for v in values]
    return "\n".join(", ".join(values[i:i + per_line]) for i in range(0, len(values), per_line))


def _elements(m: dict, etype: str) -> list:
    """The ``*ELEMENT`` blocks of both bodies (ELSET E1, E2); 20 nodes take two lines (15 + 5)."""
    out = []
    for side, (eids, conn) in enumerate(m["elements"], start=1):
        out.append(f"*ELEMENT, TYPE={etype}, ELSET=E{side}")
        for e, c in zip(eids, conn):
            out.append(f"{e}, " + ", ".join(map(str, c[:15])) + ",\n" + ", ".join(map(str, c[15:])))
    return out


def _common(m: dict, etype: str) -> list:
    """Nodes, elements, the material (E = 1, ν = 0, conductivity 1) and the sections."""
    out = ["*HEADING", "infsup-contact: the 3D membranes of Bathe & Brezzi (2001), HEX20", "*NODE, NSET=NALL"]
    out += [f"{i}, {x:.17g}, {y:.17g}, {z:.17g}" for i, (x, y, z) in zip(m["ids"], m["coords"])]
    out += _elements(m, etype)
    out += ["*MATERIAL, NAME=M", "*ELASTIC", "1., 0.", "*CONDUCTIVITY", "1.",
            "*SOLID SECTION, ELSET=E1, MATERIAL=M", "*SOLID SECTION, ELSET=E2, MATERIAL=M"]
    return out


def face_elements(m: dict, side: int) -> np.ndarray:
    """The element ids of body ``side`` with a face on Γ (z = 1)."""
    eids, conn = m["elements"][side - 1]
    z = m["coords"][conn - 1, 2]
    return eids[np.isclose(z, 1.0).sum(axis=1) == 8]


def boundary_vertices(m: dict, n2: int) -> np.ndarray:
    """Ω2's nodes at the vertices of its face on Γ that lie on ∂Γ (the slave's boundary vertices)."""
    x, b = m["coords"], m["body"]
    side = np.isclose(x[:, 0], 0) | np.isclose(x[:, 0], 1) | np.isclose(x[:, 1], 0) | np.isclose(x[:, 1], 1)
    vertex = np.isclose(x[:, :2] * n2, np.rint(x[:, :2] * n2)).all(axis=1)
    return m["ids"][(b == 2) & np.isclose(x[:, 2], 1.0) & side & vertex]


def boundary_mpcs(m: dict, n2: int) -> list:
    """The slave's ∂Γ vertices held by one-node MPCs (u_x + u_y = 0, with u_y = u_z = 0 as SPCs: the
    vertex fixed). ccx 2.20 gives a slave node in an MPC no multiplier and modifies its neighbours'
    duals (checkspcmpc.f, gendualcoeffs.f); MPCs tying it to another node are refused
    (catsmpcslavno.f), SPCs alone leave the multiplier."""
    nodes = boundary_vertices(m, n2)
    eq = ["*EQUATION"] + [line for s in nodes for line in ("2", f"{s}, 1, 1., {s}, 2, 1.")]
    return eq + ["*NSET, NSET=SLAVEBOUNDARY", _lines(nodes)]


def contact_deck(m: dict, mortar: str, clamped: bool, mpc_boundary: int = 0) -> str:
    """The contact deck: ``*CONTACT PAIR, TYPE=mortar``, slave Ω2's face on Γ, master Ω1's, one
    ``*STATIC`` step without load (the bodies touch: the coupling is assembled in its first iteration).
    ``PRESSURE-OVERCLOSURE=HARD`` is reduced by ccx to its linear default for mortar contact (a
    warning); the coupling does not depend on it. ``mpc_boundary`` = N2 (Ω2's bricks per edge): the
    slave's ∂Γ vertices held by :func:`boundary_mpcs` (the fix); 0: not."""
    out = _common(m, "C3D20")
    out += ["*NSET, NSET=FIX", _lines(boundary_nodes(m, clamped))]
    out += ["*SURFACE, NAME=SSLAVE, TYPE=ELEMENT"] + [f"{e}, {BOTTOM}" for e in face_elements(m, 2)]
    out += ["*SURFACE, NAME=SMASTER, TYPE=ELEMENT"] + [f"{e}, {TOP}" for e in face_elements(m, 1)]
    out += ["*SURFACE INTERACTION, NAME=SI", "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD",
            f"*CONTACT PAIR, INTERACTION=SI, TYPE={mortar}", "SSLAVE, SMASTER",
            *(boundary_mpcs(m, mpc_boundary) if mpc_boundary else []),
            "*BOUNDARY", "FIX, 1, 3", *(["SLAVEBOUNDARY, 2, 3"] if mpc_boundary else []),
            "*STEP", "*STATIC", "*END STEP", ""]
    return "\n".join(out)


def heat_deck(m: dict) -> str:
    """The conduction deck: DC3D20, temperature 0 on ∂Ω_i∖Γ, the two bodies uncoupled: CalculiX's
    conduction matrix is diag(K1, K2), K_i = ∫ ∇φ·∇φ (27 Gauss points: exact on the bricks)."""
    out = _common(m, "DC3D20")
    out += ["*NSET, NSET=FIX", _lines(boundary_nodes(m, True)), "*BOUNDARY", "FIX, 11, 11",
            "*STEP", "*HEAT TRANSFER, STEADY STATE, SOLVER=MATRIXSTORAGE", "1., 1.", "*END STEP", ""]
    return "\n".join(out)
