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

import argparse
import json
import os
import sys
import time
from contextlib import contextmanager
from pathlib import Path

SPACES = {
    "dual": "Kratos' default: dual P1 multipliers on every slave node (the Dirichlet ends kept), "
            "B scaled by Kratos' automatic scale factor YOUNG_MODULUS/NODAL_H (= 1/h here)",
    "dual-unscaled": "the same with scale_factor_parameters {manual_scale_factor: true} (B then carries no "
                     "scale factor, whatever scale_factor says)",
    "dual-ends-fixed": "unscaled, SCALAR_LAGRANGE_MULTIPLIER fixed at Γ's two end nodes and Kratos' elimination "
                       "builder (a user's fix for the Dirichlet ends)",
}
MAX_N = 512  # a level of N = 512 has ~5e5 dofs: far past what a certificate of this problem needs


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (the contract)
        sys.stderr.write(f"export.py: {message}\n")
        sys.exit(2)


def _args(argv):
    p = _Parser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path)
    p.add_argument("--space", choices=sorted(SPACES))
    p.add_argument("--N", type=int, nargs="+")
    p.add_argument("--offset", type=int, default=0)
    p.add_argument("--list-spaces", action="store_true")
    a = p.parse_args(argv)
    if a.list_spaces:
        return a
    for key in ("out", "space", "N"):
        if getattr(a, key) is None:
            p.error(f"--{key} is required (or --list-spaces)")
    if any(n < 2 or n > MAX_N for n in a.N) or sorted(set(a.N)) != a.N:
        p.error(f"--N: increasing integers in 2..{MAX_N} (found {' '.join(map(str, a.N))})")
    if not 0 <= a.offset <= 8:
        p.error(f"--offset: an integer in 0..8 (found {a.offset})")
    if a.out.exists() and (not a.out.is_dir() or any(a.out.iterdir())):
        p.error(f"--out {a.out}: not a new or empty directory")
    return a


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


def main(argv=None) -> int:
    a = _args(sys.argv[1:] if argv is None else argv)
    if a.list_spaces:
        for key, text in SPACES.items():
            print(f"{key}\t{text}")
        return 0
    with _stdout_to_stderr():
        import kratos_model
        a.out.mkdir(parents=True, exist_ok=True)
        levels = []
        for n in a.N:
            t0 = time.perf_counter()
            levels.append(kratos_model.write_level(a.out, n, a.offset, a.space))
            print(f"export.py: N = {n}: {time.perf_counter() - t0:.2f} s", file=sys.stderr)
        _write_manifest(a.out, a.space, a.offset, levels, kratos_model.version())
    return 0


def _write_manifest(out: Path, space: str, offset: int, levels, version: str) -> None:
    """levels.yaml in the ``norm: H`` form, written atomically (JSON values are YAML)."""
    lines = [f"name: {json.dumps(f'kratos-{version} mesh-tying {space} P1 (offset {offset})')}",
             "norm: H", "gamma: {shape: segment, length: 1.0}", "levels:"]
    for lv in levels:
        lines.append(f"  - h: {lv['h']!r}")
        for key in ("A", "B", "G"):
            lines.append(f"    {key}: {lv[key]}")
        lines.append(f"    multipliers: {json.dumps(lv['multipliers'])}")
    tmp = out / ".levels.yaml.tmp"
    tmp.write_text("\n".join(lines) + "\n")
    os.replace(tmp, out / "levels.yaml")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    sys.exit(main())
