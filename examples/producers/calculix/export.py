"""Export CalculiX's mortar coupling on the 3D membranes of Bathe & Brezzi (2001), HEX20 bodies.

Run by any interpreter with numpy, scipy and PyYAML (``.venv/bin/python``); it runs the ccx that
``make producers-calculix`` builds from Debian's calculix-ccx 2.20 source with our dump of the
mortar coupling (``.calculix/bin/ccx_infsup``, or the path in ``INFSUP_CCX``)::

    .venv/bin/python examples/producers/calculix/export.py --out DIR --space LINMORTAR --N 2 3 4 [--offset 1]
    .venv/bin/python examples/producers/calculix/export.py --list-spaces

Per level (``decks.py``): Ω1 = (0,1)³ with (N + K)³ C3D20 bricks (the master), Ω2 = (0,1)²×(1,2)
with N³ (the slave, the multipliers' side), Γ = (0,1)² × {1}. Two ccx runs:

* the contact deck ``*CONTACT PAIR, TYPE=LINMORTAR`` (or ``PGLINMORTAR``), far faces supported:
  our dump writes CalculiX's node-to-node coupling as bdfill assembles it in the first iteration
  (and ends the run there: ``INFSUP_CCX_DUMP_STOP``),
  ``Dd`` (slave rows × slave nodes) and ``Bd`` (slave rows × master nodes, stored as −∫ψφ: the
  sign of B = [−B1 | B2]), and for PGLINMORTAR the Petrov–Galerkin pair ``Dpgd``/``Bpgd``;
* the heat deck (DC3D20, conductivity 1, u = 0 on ∂Ω_i∖Γ, ``SOLVER=MATRIXSTORAGE``): CalculiX's
  conduction matrix = the Laplace stiffness diag(K1, K2) of the free dofs (``.con``, one
  triangle; ``.dof`` the node of each equation).

Exported: A = that matrix (symmetrized), B = the dumped coupling's rows of the Lagrange-multiplier
nodes (``islavact`` ≥ 0: LINMORTAR keeps the vertices of G_h, all of them, ∂Γ included — the SPCs
do not remove a slave node's multiplier in 2.20) restricted to A's dofs (columns of the
Dirichlet nodes dropped), rows in the order i + n_x j of the vertex (x_i, y_j), and G the L² mass
of the described basis (CalculiX has none): LINMORTAR the dual basis of Q1 (tensor products of
1D duals of P1, all vertices: the suite's ``LINDUAL-Q8``), PGLINMORTAR's constraint rows the
standard Q1 hats it tests with (``T5``). ``entry_rtol``: CalculiX projects the slave quadrature
points onto the master by Newton's method; its Bd entries on matching meshes are off by up to
~5e-7 of max|b| (measured against Dd, which is exact), so the manifest declares 1e-6.
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # examples/producers: the contract
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402

import decks  # noqa: E402
from contract import level_entry, run, write_atomic, write_manifest  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
CCX = Path(os.environ.get("INFSUP_CCX", ROOT / ".calculix" / "bin" / "ccx_infsup"))
ENTRY_RTOL = 1e-6
SPACES = {
    "LINMORTAR": ("LINMORTAR", "dual", "Dd", "Bd",
                  "CalculiX LINMORTAR: dual basis of Q1 on every vertex of Omega2's face (LINDUAL-Q8)"),
    "PGLINMORTAR": ("PGLINMORTAR", "lagrange", "Dpgd", "Bpgd",
                    "CalculiX PGLINMORTAR, its constraint rows: tested with the Q1 hats on every vertex (T5)"),
    "LINMORTAR-MPC": ("LINMORTAR", "dual-drop", "Dd", "Bd",
                      "CalculiX LINMORTAR with the slave's boundary vertices held by one-node MPCs: no multiplier "
                      "there, the neighbouring duals modified (LINDUAL0-Q8?)"),
}


class CcxError(Exception):
    """ccx failed or wrote no dump: one line on stderr, exit 1."""


def run_ccx(workdir: Path, job: str, deck: str, dump: Path | None = None) -> None:
    """Write ``job.inp`` in ``workdir`` and run the patched ccx there (one thread; with ``dump``
    our INFSUP_CCX_DUMP directory)."""
    (workdir / f"{job}.inp").write_text(deck)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_STIFFNESS="1", CCX_NPROC_EQUATION_SOLVER="1")
    if dump is not None:
        dump.mkdir()
        env.update(INFSUP_CCX_DUMP=str(dump), INFSUP_CCX_DUMP_STOP="1")  # ccx exits after the dump
    done = subprocess.run([str(CCX), "-i", job], cwd=workdir, env=env, capture_output=True, text=True, timeout=1800)
    errors = [line.strip() for line in done.stdout.splitlines() if "*ERROR" in line]
    if done.returncode != 0 or errors:
        raise CcxError(f"{CCX} -i {job} (exit {done.returncode}): {errors[0] if errors else done.stderr.strip()[-200:]}")


def read_node_matrix(path: Path) -> sp.csr_matrix:
    """A dumped nk × nk coupling (MatrixMarket, 1-based node numbers) as CSR on 0-based node ids."""
    import scipy.io

    if not path.is_file():
        raise CcxError(f"ccx wrote no {path.name}: is {CCX} the patched build (make producers-calculix)?")
    return sp.csr_matrix(scipy.io.mmread(str(path)))


def conduction_matrix(workdir: Path, job: str):
    """(A, node of each equation) from ccx's ``job.con`` (one triangle, 1-based) and ``job.dof``."""
    i, j, v = np.loadtxt(workdir / f"{job}.con", unpack=True, ndmin=2)
    nodes = np.array([int(float(s)) for s in (workdir / f"{job}.dof").read_text().split()])
    n = len(nodes)
    T = sp.coo_matrix((v, (i.astype(int) - 1, j.astype(int) - 1)), shape=(n, n)).tocsr()
    upper_and_lower = T + T.T
    return (upper_and_lower - sp.diags(T.diagonal())).tocsr(), nodes


def dual_mass_1d(t: np.ndarray, basis: str) -> np.ndarray:
    """The L² mass of P1 on the breakpoints ``t``: the hats (``lagrange``), their biorthogonal
    duals (``dual``, per interval ψ_a = 2φ_a − φ_b) or the duals of the interior nodes with the end
    ones added to their neighbours (``dual-drop``, Wohlmuth's modification: ψ = 1 on an end
    interval), exactly (products of P1 functions)."""
    n = len(t)
    G = np.zeros((n, n))
    C = np.array([[2.0, -1.0], [-1.0, 2.0]]) if basis != "lagrange" else np.eye(2)
    for e in range(n - 1):
        h = t[e + 1] - t[e]
        G[e:e + 2, e:e + 2] += C @ (h / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])) @ C.T
    if basis != "dual-drop":
        return G
    R = np.eye(n)[1:-1]  # interior duals, each end dual added to its neighbour's
    R[0, 0] = R[-1, -1] = 1.0
    return R @ G @ R.T


def multiplier_rows(m: dict, dump: Path, n2: int, interior: bool = False):
    """The multiplier nodes (islavact ≥ 0) in the order i + n_x j of their vertex (x_i, y_j) on Γ,
    checked to be exactly the (n2 + 1)² vertices of Ω2's face (``interior``: the (n2 − 1)² off ∂Γ)."""
    state = np.loadtxt(dump / "islavact.txt", dtype=np.int64, ndmin=2)
    lm = state[state[:, 1] >= 0, 0]
    xy = m["coords"][lm - 1, :2]
    ij = np.rint(xy * n2).astype(np.int64) - (1 if interior else 0)
    nx = n2 - 1 if interior else n2 + 1
    if len(lm) != nx ** 2 or (ij < 0).any() or (ij >= nx).any():
        raise CcxError(f"{len(lm)} multiplier nodes where {'the interior' if interior else 'all'} {nx ** 2} "
                       "vertices of Gamma were expected")
    return lm[np.argsort(ij[:, 0] + nx * ij[:, 1])]


def level(out: Path, spec: tuple, n2: int, offset: int) -> dict:
    """Run both decks for one level and write its matrices; the manifest entry."""
    mortar, basis, slave_key, master_key, _ = spec
    m = decks.mesh(n2 + offset, n2)
    with tempfile.TemporaryDirectory(prefix="infsup-ccx-") as tmp:
        work = Path(tmp)
        drop = basis == "dual-drop"
        run_ccx(work, "contact", decks.contact_deck(m, mortar, clamped=False, mpc_boundary=n2 if drop else 0),
                dump=work / "dump")
        run_ccx(work, "heat", decks.heat_deck(m))
        A, nodes = conduction_matrix(work, "heat")
        coupling = read_node_matrix(work / "dump" / f"{slave_key}.mtx") + read_node_matrix(work / "dump" / f"{master_key}.mtx")
        rows = multiplier_rows(m, work / "dump", n2, interior=drop)
    B = coupling[rows - 1][:, nodes - 1]  # node ids are 1-based; A's equations are the free nodes
    t = np.linspace(0.0, 1.0, n2 + 1)
    G = np.kron(dual_mass_1d(t, basis), dual_mass_1d(t, basis))  # row i + n_x j: x fastest
    form = {"basis": basis.removesuffix("-drop"), "degree": 1, "ends": "drop" if drop else "keep",
            "breakpoints": t.tolist()}
    return level_entry(out, n2, A, sp.csr_matrix(B), sp.csr_matrix(G), {"x": form, "y": {**form, "breakpoints": t.tolist()}})


def export(args) -> Path:
    """Every level of ``args.N``; the manifest (``norm: H``, Γ the unit square)."""
    spec = SPACES[args.space]
    levels = [level(args.out, spec, n, args.offset) for n in args.N]
    target = write_manifest(args.out, f"calculix-{args.space}-offset{args.offset}", levels,
                            gamma={"shape": "rectangle", "size": [1.0, 1.0]})
    import yaml  # the declared entry accuracy (see the module docstring), beside the contract's keys

    manifest = yaml.safe_load(target.read_text())
    manifest["entry_rtol"] = ENTRY_RTOL
    write_atomic(target, lambda tmp: tmp.write_text(yaml.safe_dump(manifest, sort_keys=False, default_flow_style=None)))
    return target


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if "--list-spaces" not in argv and not (CCX.is_file() and os.access(CCX, os.X_OK)):
        print(f"export.py: CalculiX's patched ccx not found at {CCX}: run `make producers-calculix` (or set INFSUP_CCX)",
              file=sys.stderr)
        return 2
    try:
        return run(argv, SPACES, export, n_min=1, offsets=(0, 1), offset_reason="CalculiX's export meshes Omega1 with N or N + 1 bricks per edge (0 or 1)")
    except CcxError as err:
        print(f"export.py: {err}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
