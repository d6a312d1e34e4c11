"""The multiplier spaces on QUAD8 faces: serendipity HEX20 bodies (k = 2) on matching meshes.

One row per (space, N, norm): dim M_h, dim W_h = (3N − 1)(N − 1), the measured kernel of Bᵀ, the
proven one (:meth:`~infsup_contact.discretization.face.shapes.serendipity.SerendipitySquare.proven_kernel`:
the dimension count, and for tensor spaces the serendipity structure W = P2_0 ⊗ P1_0 + P1_0 ⊗ P2_0),
β_h, and the stability verdict of the space's series in that norm
(:func:`~infsup_contact.criteria.stability.stability_verdict`, the criterion of ``infsup-contact verdict``).
The spaces: every registered one the QUAD8 face builds (``--case all``). No file is written: the
table goes to the caller (``python -m infsup_contact.study.face.hex20 --N 4 6 8``: CSV on stdout).
"""
from __future__ import annotations

import time

from ...criteria.stability import stability_verdict
from ...errors import InputError

NS = (4, 6, 8)
CRITERION = {"tol": 0.15, "floor": 1e-3, "confidence": 0.95}
"""The verdict's criterion: slope tolerance, β floor, confidence (``infsup-contact verdict``'s defaults)."""
COLUMNS = ("case", "N", "norm", "dim_M", "dim_W", "kernel_dim", "structural_kernel_dim", "kernel_decision",
           "beta", "verdict", "seconds")


def quad8_cases(k: int = 2) -> list:
    """The registered ids the QUAD8 face builds for k (the paper's tensor spaces, the duals, the QUAD8 ones)."""
    import numpy as np

    from ...discretization.face.shapes.serendipity import SERENDIPITY
    from ...discretization.face.partitions.tensor_grid import TensorPartition
    from ...discretization.spaces.registry import ids_built_on

    x = np.linspace(0.0, 1.0, 3)
    return ids_built_on(k, SERENDIPITY, TensorPartition(x, x))


def hex20_table(ns=NS, norms=("H", "L2"), cases=None, criterion=None) -> list[dict]:
    """Rows of :data:`COLUMNS` for N in ``ns`` (at least three distinct N >= 2: the verdict's
    slope), every QUAD8 space (or ``cases``), both norms; ``seconds`` = wall time of the N's
    β request (both sides factorized once, every space and norm)."""
    from ...models import model_of_dim
    from ...solvers.infsup import beta_rows_all
    from ...solvers.request import MeshOptions
    from ...solvers.side_cache import SideCache

    membranes3d = model_of_dim(3)  # the registry's 3D membranes, asked for (not imported by module)
    ns = sorted({int(n) for n in ns})
    if len(ns) < 3 or ns[0] < 2:
        raise InputError("N", "at least three distinct integers >= 2", got=ns)
    cases = quad8_cases() if cases is None else list(cases)
    crit = dict(CRITERION, **(criterion or {}))
    cache, rows = SideCache(), []
    for n in ns:
        t0 = time.perf_counter()
        found = beta_rows_all("structured", 2, n, n, cases, norms=tuple(norms), model=membranes3d,
                              side_cache=cache, mesh=MeshOptions(element="hex20"))
        seconds = time.perf_counter() - t0
        rows += [dict(r, N=n, seconds=seconds) for r in found]
    out = []
    for case in cases:
        for norm in norms:
            series = [r for r in rows if r["case"] == case and r["norm"] == norm]
            verdict = stability_verdict(series, **crit)["verdict"]
            out += [{c: (verdict if c == "verdict" else r[c]) for c in COLUMNS} for r in series]
    return out


def main(argv=None) -> int:
    """``python -m infsup_contact.study.face.hex20 [--N 4 6 8] [--case ID ...]``: the table as CSV."""
    import argparse
    import sys

    import pandas as pd

    from ...command_line import OneLineParser, run_study

    p = OneLineParser(prog="python -m infsup_contact.study.face.hex20", description=__doc__.splitlines()[0],
                      formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, nargs="+", default=list(NS), help="cells per direction (>= 3 values >= 2)")
    p.add_argument("--case", nargs="+", default=None, help="registered ids (default: every QUAD8-face space)")

    def check(args):
        if len(set(args.N)) < 3 or min(args.N) < 2:
            raise InputError("N", "at least three distinct integers >= 2", got=args.N)
        allowed = quad8_cases()
        for case in args.case or ():
            if case not in allowed:
                raise InputError("case", ", ".join(allowed), got=case)

    def run(args):
        pd.DataFrame(hex20_table(args.N, cases=args.case), columns=list(COLUMNS)).to_csv(sys.stdout, index=False)

    return run_study(p, argv, check, run)


if __name__ == "__main__":
    raise SystemExit(main())
