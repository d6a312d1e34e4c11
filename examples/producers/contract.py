"""The producers' contract, shared by every ``examples/producers/<code>/export.py``.

Each exporter runs in its own code's interpreter (Kratos in ``.venv``, DOLFINx in
``.venv-dolfinx``, GetFEM in Debian's ``/usr/bin/python3``), none of which has ``infsup_contact``
installed, so this module needs numpy, scipy and PyYAML only. An exporter puts this folder on
``sys.path`` and calls :func:`run` with its spaces and its ``export`` function::

    python export.py --out DIR --space SPACE --N 4 8 16 32 [--offset K]
    python export.py --list-spaces

``export(args)`` assembles the levels (:func:`level_entry` writes each one's matrices) and
returns the manifest's name; :func:`run` writes ``DIR/levels.yaml`` in the ``norm: H`` form
(README, "Certify a discretization from another code"). Bad arguments: one line on stderr, exit 2;
nothing on stdout but ``--list-spaces``' lines.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

N_MAX = 512
"""Largest N accepted (N = 512 at k = 2 is about 2 million body dofs; larger is a typo)."""
GAMMA = {"shape": "segment", "length": 1.0}
"""The paper's Γ = (0, 1) × {1}."""


class ArgumentError(Exception):
    """A bad command line: one line on stderr, exit 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise ArgumentError(message)


def parse_args(argv, spaces: dict, n_min: int = 1, offsets=None, offset_reason: str = ""):
    """The contract's command line; :class:`ArgumentError` naming the flag for anything else.
    ``offsets``: the --offset values the producer can mesh (None: any with N + offset in
    n_min..:data:`N_MAX`), ``offset_reason`` said when another is given."""
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
    if args.space not in spaces:
        raise ArgumentError(f"--space {args.space!r} is not one of {', '.join(spaces)}")
    if offsets is not None and args.offset not in offsets:
        raise ArgumentError(f"--offset {args.offset}: {offset_reason}")
    bad = [n for n in args.N if not n_min <= n <= N_MAX or not n_min <= n + args.offset <= N_MAX]
    if bad:
        raise ArgumentError(f"--N {bad[0]} --offset {args.offset}: N and N + offset must be in {n_min}..{N_MAX}")
    if sorted(set(args.N)) != args.N:
        raise ArgumentError(f"--N {' '.join(map(str, args.N))}: give distinct N in increasing order")
    if args.out.exists() and not args.out.is_dir():
        raise ArgumentError(f"--out {args.out}: exists and is not a directory")
    if (args.out / "levels.yaml").exists():  # another system's manifest and matrices: not overwritten
        raise ArgumentError(f"--out {args.out}: holds a system already (levels.yaml); give a new or empty directory")
    return args


def write_atomic(path: Path, writer) -> None:
    """Write through a temporary file and rename (a killed run leaves no half file); the
    temporary name keeps the suffix (``mmwrite`` appends ``.mtx`` to a name without it)."""
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    writer(tmp)
    os.replace(tmp, path)


def level_entry(out: Path, n: int, A, B, G, multipliers: dict, traces=None) -> dict:
    """Write one level's A, B, G (MatrixMarket, 17 digits) into ``out``; its manifest entry."""
    import scipy.io

    entry = {"h": 1.0 / n}
    for key, mat in (("A", A), ("B", B), ("G", G)):
        name = f"{key}{n}.mtx"
        write_atomic(out / name, lambda t, M=mat: scipy.io.mmwrite(t, M, precision=17))
        entry[key] = name
    entry["multipliers"] = multipliers
    if traces is not None:
        entry["traces"] = traces
    return entry


def write_manifest(out: Path, name: str, levels: list, gamma: dict = GAMMA) -> Path:
    """``out/levels.yaml`` in the ``norm: H`` form, written atomically."""
    import yaml

    manifest = {"name": name, "norm": "H", "gamma": gamma, "levels": levels}
    target = out / "levels.yaml"
    write_atomic(target, lambda t: t.write_text(yaml.safe_dump(manifest, sort_keys=False, default_flow_style=None)))
    return target


def describe_traces(coords: np.ndarray, n1: int, k: int) -> list:
    """The bodies' trace bases on Γ for the certifier's distance to the exact mortar coupling
    (``traces``): per body continuous P_k on its Γ nodes (the dofs at y = 1 among ``coords``,
    Ω1's the first ``n1``), ``columns`` the column of B (A's dof) of each trace function left to
    right, −1 at Γ's ends (Dirichlet dofs: B's columns there are zeroed), sign −1 for Ω1 and
    +1 for Ω2 (B = [−B1 | B2])."""
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


def run(argv, spaces: dict, export, describe=lambda spec: spec[-1], **limits) -> int:
    """The exporter's ``main``: parse (``limits`` as :func:`parse_args` takes them), list the
    spaces or call ``export(args)`` (the manifest's path), map bad arguments and an unwritable
    --out to one line and exit 2."""
    try:
        args = parse_args(sys.argv[1:] if argv is None else argv, spaces, **limits)
    except ArgumentError as err:
        print(f"export.py: {err}", file=sys.stderr)
        return 2
    if args.list_spaces:
        for sid, spec in spaces.items():
            print(f"{sid}\t{describe(spec)}")
        return 0
    try:
        args.out.mkdir(parents=True, exist_ok=True)
        export(args)
    except OSError as err:
        print(f"export.py: --out {args.out}: {err.strerror or err}", file=sys.stderr)
        return 2
    return 0
