"""Export FreeFEM's shipped mortar tutorial, and the paper's membranes as FreeFEM assembles them.

FreeFEM is a binary with its own language, not a Python package, so this exporter is run by the
suite's interpreter (``.venv/bin/python``: numpy, scipy, PyYAML; the contract needs nothing
else) and drives ``FreeFem++`` (Debian ``freefem++``, ``make producers-freefem``)::

    .venv/bin/python examples/producers/freefem/export.py --out DIR --space tutorial --N 8 16 32 64
    .venv/bin/python examples/producers/freefem/export.py --list-spaces

**The tutorial** (``tutorial*``): FreeFEM's ``examples/tutorial/mortar-DN-4.edp`` as Debian's
``freefem++-doc`` ships it, read at run time from :data:`TUTORIAL` (never a copy of ours), with
its parameters set and a dump of its matrices injected where it builds its system ``M``
(:func:`patch_tutorial`): the disk cut into four quarters, P1 on each (u = g on the circle by
FreeFEM's ``tgv`` = 1e30), P0 multipliers on the skeleton (the four radii, a ``meshL``) refined
by ``trunc(Thm, 1, split=4)``, coupled by ``Csd[sd]`` (the jump, signed per quarter), and the
(2,2) block ``DD`` = 1e-10 × the multipliers' mass. Exported: A = diag(Asd), B = [Csdᵀ], C = DD
(``C<N>.mtx``), G = the L² mass of the P0 multipliers (``norm: given``: the skeleton is a star of
four segments, not Γ = a segment, so ``norm: H`` cannot describe it). ``meshsize`` = 1/N (the
shipped 0.025 is N = 40); ``--offset 1`` switches on the tutorial's own ``noconforme`` (each
quarter re-meshed by ``adaptmesh`` at its own size, the coupling integrated on a 4× finer
skeleton). Spaces: as shipped, ``split=1`` and the skeleton twice as coarse as the bodies.

**The membranes** (the paper's spaces): ``membranes.edp``, Ω1 = ``square(N + K)``, Ω2 = (0,1)×(1,2)
with N, multipliers on a ``meshL`` of Γ with Ω2's N segments, b(μ, v) integrated on a ``meshL`` with
lcm(N + K, N) segments (both partitions' breakpoints: exact), u = 0 off Γ by ``tgv``; T3's
μ = 0 at Γ's ends by unit rows of G and zero rows of B. ``norm: H`` with the multipliers and
the traces described.
"""
from __future__ import annotations

import math
import re
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # examples/producers: the contract
sys.path.insert(0, str(HERE))

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402
from contract import (ArgumentError, describe_traces, level_entry, parse_args, run, write_atomic,  # noqa: E402
                      write_manifest)
from freefem_io import FreeFemError, read_arrays, read_matrix, run_script, version  # noqa: E402

TUTORIAL = Path("/usr/share/doc/freefem++/examples/tutorial/mortar-DN-4.edp")
"""The shipped tutorial (Debian ``freefem++-doc``)."""

# id: ("tutorial", split, skeleton coarsening, labels fixed, description) or ("membranes", k, s, continuous, μ = 0 at ends, description)
SPACES = {
    "tutorial": ("tutorial", 4, 1, False, "mortar-DN-4.edp as shipped: P1 quarters, P0 multipliers on the skeleton split=4, C = 1e-10 mass"),
    "tutorial-labels": ("tutorial", 4, 1, True, "mortar-DN-4.edp with the skeleton's integrals unlabelled (int1d(Thm) for int1d(Thm,1)): the coupling it means, split=4"),
    "tutorial-split1": ("tutorial", 1, 1, True, "mortar-DN-4.edp unlabelled and split=1: P0 multipliers on the bodies' own skeleton edges"),
    "tutorial-coarse2": ("tutorial", 1, 2, True, "mortar-DN-4.edp unlabelled, the skeleton built with Ng/2 and split=1: P0 on two body edges"),
    "T3-k1": ("membranes", 1, 1, True, True, "Thm 3, k = 1: P1 bodies, continuous P1 multipliers, mu = 0 at Gamma's ends (unit rows of G)"),
    "T3-k2": ("membranes", 2, 2, True, True, "Thm 3, k = 2: P2 bodies, continuous P2 multipliers, mu = 0 at Gamma's ends (unit rows of G)"),
    "R5.2-k1": ("membranes", 1, 1, True, False, "Rem 5.2, k = 1: P1 bodies, continuous P1 multipliers, no end condition"),
    "R5.2-k2": ("membranes", 2, 2, True, False, "Rem 5.2, k = 2: P2 bodies, continuous P2 multipliers, no end condition"),
    "T4-k2": ("membranes", 2, 0, False, False, "Thm 4, k = 2: P2 bodies, P0 multipliers"),
    "R5.4-k1": ("membranes", 1, 0, False, False, "Rem 5.4, k = 1: P1 bodies, P0 multipliers"),
    "T5-k2": ("membranes", 2, 1, True, False, "Thm 5, k = 2: P2 bodies, continuous P1 multipliers"),
}
OFFSETS = (0, 1)
OFFSET_REASON = "0 or 1 (membranes: Omega1 with N + 1 segments on Gamma; tutorial: its own noconforme option)"
TUTORIAL_DUMP = """
// ---- injected by infsup-contact's examples/producers/freefem/export.py: the system M's blocks ----
for (int sd = 0; sd < nbsd; ++sd) {
  {ofstream f("A" + sd + ".txt"); f.precision(17); f << Asd[sd];}
  {ofstream f("C" + sd + ".txt"); f.precision(17); f << Csd[sd];}
}
{ofstream f("DD.txt"); f.precision(17); f << DD;}
{ofstream f("M.txt"); f.precision(17); f << M;}
varf vInfsupG(u, v) = int1d(Thm)(u * v);
matrix InfsupG = vInfsupG(Lh, Lh);
{ofstream f("G.txt"); f.precision(17); f << InfsupG;}
exit(0);
"""


class TutorialChanged(Exception):
    """The shipped tutorial no longer has a line the patch sets (another FreeFEM release)."""


def _replace_once(text: str, pattern: str, new: str) -> str:
    """``text`` with the one match of the regex ``pattern`` replaced; :class:`TutorialChanged` otherwise."""
    hits = len(re.findall(pattern, text))
    if hits != 1:
        raise TutorialChanged(f"{TUTORIAL}: expected one line matching {pattern!r}, found {hits} "
                              "(another FreeFEM release: update examples/producers/freefem/export.py)")
    return re.sub(pattern, lambda _: new, text)


def patch_tutorial(text: str, n: int, split: int, coarse: int, noconforme: bool, fix_labels: bool = False) -> str:
    """The shipped tutorial with meshsize = 1/n, ``split``, the skeleton built with Ng/``coarse``
    segments per radius, ``noconforme`` set, and the dump of its system's blocks (then ``exit``)
    injected before it solves. Everything else runs as shipped. ``fix_labels``: the skeleton's
    integrals over all its cells (``int1d(Thm)``, ``int1d(Thmm, ...)``) where the tutorial asks for
    label 1 (``int1d(Thm,1)``): a ``meshL`` from ``buildmeshL(gi(Ng))`` has its cells labelled 0 in
    this FreeFEM, so the labelled integrals are empty — the skeleton's normal, the signs ``epssd``
    and the coupling ``Csd`` come out zero."""
    if fix_labels:
        for pattern, new in ((r"int1d\(Thm,1\)\(\( -nx", "int1d(Thm)(( -nx"), (r"\+int1d\(Thm,1\)\(u\*v\)", "+int1d(Thm)(u*v)"),
                             (r"int1d\(Thmm,1,qforder=3\)", "int1d(Thmm,qforder=3)")):
            text = _replace_once(text, pattern, new)
    # 1/(1/n) may round below n and Ng = 1./meshsize truncates: the factor keeps Ng = n exactly
    text = _replace_once(text, r"real meshsize=0\.025;", f"real meshsize=1./{n}*(1-1e-12);")
    text = _replace_once(text, r"bool noconforme=0;", f"bool noconforme={int(noconforme)};")
    text = _replace_once(text, r"Thm=trunc\(Thm,1,split=4\);", f"Thm=trunc(Thm,1,split={split});")
    if coarse != 1:
        text = _replace_once(text, r"meshL Thm=buildmeshL\(gi\(Ng\)\);",
                             f"int[int] NgSkeleton(nbsd); NgSkeleton = {n // coarse};\n"
                             "meshL Thm=buildmeshL(gi(NgSkeleton));")
    return _replace_once(text, r"set\(M,solver=sparsesolver\);", TUTORIAL_DUMP + "set(M,solver=sparsesolver);")


def tutorial_level(n: int, space: str, offset: int, work: Path) -> dict:
    """A, B, C, G (and FreeFEM's own M) of one level of a tutorial space."""
    _, split, coarse, fix_labels, _ = SPACES[space]
    if not TUTORIAL.is_file():
        raise FreeFemError(f"{TUTORIAL} missing: run `make producers-freefem` (Debian freefem++-doc)")
    script = work / "mortar-DN-4.edp"
    script.write_text(patch_tutorial(TUTORIAL.read_text(), n, split, coarse, bool(offset), fix_labels))
    run_script(script, work)
    blocks = [(read_matrix(work / f"A{sd}.txt"), read_matrix(work / f"C{sd}.txt")) for sd in range(4)]
    A = sp.block_diag([a for a, _ in blocks], format="csr")
    B = sp.hstack([c.T for _, c in blocks], format="csr")
    return {"A": A, "B": B, "C": read_matrix(work / "DD.txt"), "G": read_matrix(work / "G.txt"),
            "M": read_matrix(work / "M.txt")}


def membranes_level(n: int, space: str, offset: int, work: Path) -> dict:
    """A, B, G, the multiplier description and the bodies' traces of one membranes level."""
    _, k, s, continuous, drop, _ = SPACES[space]
    n1 = n + offset
    header = (f"int N1 = {n1}, N2 = {n}, NI = {math.lcm(n1, n)};\nmacro Pk P{k} //\nmacro Ps P{s} //\n"
              f"bool dropends = {int(drop)};\n")
    script = work / "membranes.edp"
    script.write_text(header + (HERE / "membranes.edp").read_text())
    run_script(script, work)
    A1, A2 = read_matrix(work / "A1.txt"), read_matrix(work / "A2.txt")
    B1, B2 = read_matrix(work / "B1.txt"), read_matrix(work / "B2.txt")
    x1, y1 = read_arrays(work / "x1.txt")
    x2, y2 = read_arrays(work / "x2.txt")
    xl, vertices = read_arrays(work / "xl.txt")
    coords = np.column_stack([np.concatenate([x1, x2]), np.concatenate([y1, y2])])
    return {"A": sp.block_diag([A1, A2], format="csr"), "B": sp.hstack([-B1.T, B2.T], format="csr"),
            "G": read_matrix(work / "G.txt"), "coords": coords, "n1": A1.shape[0],
            "multipliers": describe_multipliers(xl, np.sort(vertices), s, continuous)}


def assemble_level(n: int, space: str, offset: int = 0) -> dict:
    """One membranes level assembled in a temporary folder (what the tests rebuild the exact
    coupling from: ``coords``, A's dof coordinates, and ``n1``, Ω1's number of dofs)."""
    with tempfile.TemporaryDirectory(prefix="freefem-") as tmp:
        return membranes_level(n, space, offset, Path(tmp))


def traces_with_ends(coords: np.ndarray, n1: int, k: int) -> list:
    """The contract's trace description, with B's columns at Γ's ends kept: FreeFEM's ``tgv``
    fixes those dofs in A only, B's entries there stay (the certifier drops them with the
    penalty rows), so the trace functions there are B's columns, not −1."""
    out = describe_traces(coords, n1, k)
    for trace, (lo, hi) in zip(out, ((0, n1), (n1, len(coords)))):
        cols = lo + np.flatnonzero(np.isclose(coords[lo:hi, 1], 1.0))
        trace["columns"] = [int(c) for c in cols[np.argsort(coords[cols, 0], kind="stable")]]
    return out


def describe_multipliers(xl: np.ndarray, breakpoints: np.ndarray, s: int, continuous: bool) -> dict:
    """The ``norm: H`` description: continuous P_s with all its nodes (T3's end rows are
    constrained in B and G, which the certifier sets aside), or P0 (``xl``: the cell midpoints);
    ``rows`` FreeFEM's dof numbers left to right."""
    rows = [int(r) for r in np.argsort(xl, kind="stable")]
    if continuous:
        return {"basis": "lagrange", "degree": s, "breakpoints": breakpoints.tolist(), "ends": "keep", "rows": rows}
    return {"basis": "discontinuous", "degree": 0, "breakpoints": breakpoints.tolist(), "rows": rows}


def export(args) -> Path:
    """Every level's matrices and ``levels.yaml`` into ``args.out``."""
    kind = SPACES[args.space][0]
    levels = []
    with tempfile.TemporaryDirectory(prefix="freefem-") as tmp:
        for n in args.N:
            work = Path(tmp) / f"N{n}"
            work.mkdir()
            if kind == "tutorial":
                lv = tutorial_level(n, args.space, args.offset, work)
                entry = level_entry(args.out, n, lv["A"], lv["B"], lv["G"], None)
                entry.pop("multipliers")
                write_atomic(args.out / f"C{n}.mtx", lambda t, M=lv["C"]: _mmwrite(t, M))
                entry["C"] = f"C{n}.mtx"
            else:
                lv = membranes_level(n, args.space, args.offset, work)
                entry = level_entry(args.out, n, lv["A"], lv["B"], lv["G"], lv["multipliers"],
                                    traces_with_ends(lv["coords"], lv["n1"], SPACES[args.space][1]))
            levels.append(entry)
    name = f"freefem-{version()} {args.space}: {SPACES[args.space][-1]}"
    if kind == "tutorial":
        mode = "noconforme=1 (adaptmesh per quarter)" if args.offset else "conforming"
        return write_given_manifest(args.out, f"{name}, {mode}, meshsize 1/N", levels)
    return write_manifest(args.out, f"{name}, Omega1 N+{args.offset} / Omega2 N segments, exact coupling", levels)


def _mmwrite(target, mat) -> None:
    import scipy.io

    scipy.io.mmwrite(target, mat, precision=17)


def write_given_manifest(out: Path, name: str, levels: list) -> Path:
    """``levels.yaml`` with ``norm: given`` (G the multipliers' L² mass; no Γ segment to describe)."""
    import yaml

    manifest = {"name": name, "norm": "given", "levels": levels}
    target = out / "levels.yaml"
    write_atomic(target, lambda t: t.write_text(yaml.safe_dump(manifest, sort_keys=False, default_flow_style=None)))
    return target


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        args = parse_args(argv, SPACES, n_min=2, offsets=OFFSETS, offset_reason=OFFSET_REASON)
        if not args.list_spaces and SPACES[args.space][:3:2] == ("tutorial", 2) and any(n % 2 for n in args.N):
            raise ArgumentError(f"--N {' '.join(map(str, args.N))}: --space {args.space} needs even N "
                                "(its skeleton has N/2 segments per radius)")
    except ArgumentError as err:
        print(f"export.py: {err}", file=sys.stderr)
        return 2
    try:
        return run(argv, SPACES, export, n_min=2, offsets=OFFSETS, offset_reason=OFFSET_REASON)
    except (FreeFemError, TutorialChanged) as err:
        print(f"export.py: {err}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
