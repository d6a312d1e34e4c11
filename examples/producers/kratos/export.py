"""Export Kratos Multiphysics' mortar mesh tying of the two membranes as a foreign system.

Run by the interpreter Kratos is installed in (``make producers-kratos`` installs it into the
suite's ``.venv``)::

    python export.py --out DIR --space dual --N 4 8 16 32 [--offset K]
    python export.py --list-spaces

The problem is Bathe & Brezzi's two membranes: Ω1 = (0,1)×(0,1) meshed with N+K segments a
side, Ω2 = (0,1)×(1,2) with N, Γ = (0,1)×{1}, u = 0 on ∂Ω_i \\ Γ, a scalar Laplacian
(``LaplacianElement2D3N`` of the ConvectionDiffusionApplication, unknown TEMPERATURE,
conductivity 1) tied on Γ by the ContactStructuralMechanicsApplication's ``MeshTyingProcess``
(``MeshTyingMortarCondition2D2N``, SCALAR_LAGRANGE_MULTIPLIER on the slave nodes, slave = Γ's
side of Ω1). The matrices are Kratos' own block builder's LHS after its Dirichlet treatment,
split by dof type: A = TEMPERATURE × TEMPERATURE, B = multiplier × TEMPERATURE. Kratos
assembles no multiplier mass (its multiplier block is zero), so G is the L² mass of the basis
Kratos integrates with (the dual P1 basis, identified from B: see README.md), with Gauss-Legendre.
Nothing else goes to stdout: Kratos' banner and log are sent to stderr.
"""
from __future__ import annotations

import os
import sys
import time
from contextlib import contextmanager
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # examples/producers: the contract
from contract import run, write_manifest  # noqa: E402

SPACES = {
    "dual": "Kratos' default: dual P1 multipliers on every slave node (the Dirichlet ends kept), "
            "B scaled by Kratos' automatic scale factor YOUNG_MODULUS/NODAL_H (= 1/h here)",
    "dual-unscaled": "the same with scale_factor_parameters {manual_scale_factor: true} (B then carries no "
                     "scale factor, whatever scale_factor says)",
    "dual-ends-fixed": "unscaled, SCALAR_LAGRANGE_MULTIPLIER fixed at Γ's two end nodes and Kratos' elimination "
                       "builder (a user's fix for the Dirichlet ends)",
}


@contextmanager
def _stdout_to_stderr():
    """Kratos prints its banner and log on fd 1 from C++: point fd 1 at stderr meanwhile."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def export(args) -> Path:
    """Every level through Kratos (its banner and log on stderr) and ``levels.yaml``."""
    with _stdout_to_stderr():
        import kratos_model

        levels = []
        for n in args.N:
            t0 = time.perf_counter()
            lv = kratos_model.write_level(args.out, n, args.offset, args.space)
            levels.append({"h": lv["h"], "A": lv["A"], "B": lv["B"], "G": lv["G"], "multipliers": lv["multipliers"]})
            print(f"export.py: N = {n}: {time.perf_counter() - t0:.2f} s", file=sys.stderr)
        name = f"kratos-{kratos_model.version()} mesh-tying {args.space} P1 (offset {args.offset})"
    return write_manifest(args.out, name, levels)


def main(argv=None) -> int:
    return run(argv, SPACES, export, describe=lambda text: text, n_min=2, offsets=range(0, 9),
               offset_reason="an integer in 0..8")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    sys.exit(main())
