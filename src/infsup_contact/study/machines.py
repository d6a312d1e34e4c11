"""Verdicts no machine can flip: the same β sweep under every OpenBLAS core type.

OpenBLAS picks its kernels by CPU (``OPENBLAS_CORETYPE`` overrides the choice), so round-off
differs between machines. The kernel dimension and every verdict must not: they rest on
decisions with a stated margin (:mod:`infsup_contact.solvers.kernel`). This module runs a
small sweep in this process — whichever core type it was started with — and compares the
tables of several processes:

* ``kernel_dim``, ``kernel_decision`` and every verdict must be identical;
* β_h and β above the kernel must agree wherever the pencil resolves them
  (``gap_over_roundoff`` = β²/η >= 10**GAP_DECADES, η = n ε λ_max): to a relative
  10**GAP_DECADES/gap_over_roundoff (:func:`beta_tolerance`). An eigenvalue error of η would
  move β by η/(2β²) = 1/(2·gap); the pencil's real error is larger — the Cholesky reduction
  by G carries its condition number (up to ~2e3 for the H^{-1/2}_00 Gram at k = 4, N = 64)
  and S comes through a sparse LU — so the tolerance allows 10**GAP_DECADES times η.
  Measured between SkylakeX and Haswell: at most 218/gap over the 49,920 rows of the full
  config's β table (T3, k = 4, unstructured 12:12, β = 0.63: 6e-12 relative), at most 0.13/gap
  on the sweep here. Below the resolved level β's digits are round-off and machine
  dependent, as are timings.

``tests/test_machines.py`` runs it under every core type this CPU can execute; the DAG target
``verify-machines`` compares the CI profile's full ledgers.
"""
from __future__ import annotations

import ctypes
import glob
import os
from pathlib import Path

import numpy as np
import pandas as pd

CORE_TYPES = ("Prescott", "Sandybridge", "Haswell", "SkylakeX", "Zen")
"""The OpenBLAS core types the cross-machine checks run under (x86-64 kernel families)."""
REQUIRED_FLAGS = {
    "Prescott": {"sse3"},
    "Sandybridge": {"avx"},
    "Haswell": {"avx2", "fma"},
    "SkylakeX": {"avx512f", "avx512dq", "avx512bw", "avx512vl"},
    "Zen": {"avx2", "fma"},
}
"""CPU flags (/proc/cpuinfo; SSE3 is listed as ``pni``) each core type's kernels execute."""
MKL_INSTRUCTIONS = {"Prescott": "SSE4_2", "Sandybridge": "AVX", "Haswell": "AVX2", "SkylakeX": "AVX512",
                    "Zen": "AVX2"}
"""MKL's code path (``MKL_ENABLE_INSTRUCTIONS``, its highest instruction set) matched to each
core type: the face's Schur complement comes from MKL PARDISO (models/pardiso.py), whose
round-off follows its own kernel choice, not OpenBLAS's. MKL has no SSE3-only path: Prescott
gets its lowest, SSE4.2."""


def machine_env(core: str, base: dict | None = None) -> dict:
    """The environment that runs a check as on a CPU of ``core`` type: OpenBLAS's core type and
    MKL's matching instruction set (:data:`MKL_INSTRUCTIONS`)."""
    return dict(os.environ if base is None else base, OPENBLAS_CORETYPE=core,
                MKL_ENABLE_INSTRUCTIONS=MKL_INSTRUCTIONS[core])
SWEEP_N = (4, 8)
"""Matching meshes of the β sweep (with the union partition of the 17:16 pair)."""
VERDICT_N = (4, 8, 16)
"""Matching meshes of each verdict (a slope interval needs three)."""
VERDICT_CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
"""The verdict's criterion: the CLI's defaults (``infsup-contact verdict``)."""


def cpu_flags(path: str = "/proc/cpuinfo") -> set:
    """The CPU's feature flags (empty when the file is absent: not Linux on x86)."""
    try:
        text = Path(path).read_text()
    except OSError:
        return set()
    for line in text.splitlines():
        if line.startswith("flags"):
            flags = set(line.split(":", 1)[1].split())
            return flags | ({"sse3"} if "pni" in flags else set())
    return set()


def runnable(core: str, flags: set | None = None) -> tuple[bool, str]:
    """Whether this CPU executes ``core``'s kernels, and the reason when it does not."""
    flags = cpu_flags() if flags is None else flags
    missing = sorted(REQUIRED_FLAGS[core] - flags)
    if missing:
        return False, f"{core} kernels need {', '.join(missing)}, which this CPU lacks (/proc/cpuinfo)"
    return True, ""


def openblas_corenames() -> dict:
    """The kernel set OpenBLAS chose in this process, for numpy's and scipy's copies."""
    import numpy
    import scipy

    out = {}
    for name, mod, sym in (("numpy", numpy, "scipy_openblas_get_corename64_"),
                           ("scipy", scipy, "scipy_openblas_get_corename")):
        libs = glob.glob(os.path.join(os.path.dirname(os.path.dirname(mod.__file__)), f"{name}.libs", "*openblas*"))
        for lib in libs:
            fn = getattr(ctypes.CDLL(lib), sym, None)
            if fn is not None:
                fn.restype = ctypes.c_char_p
                out[name] = fn().decode()
    return out


def sweep_rows() -> pd.DataFrame:
    """β rows of the paper's five cases, k = 1..4, both norms: matching N = 4, 8 (every
    multiplier mesh is the same partition there) and the union partition of the 17:16 pair."""
    from ..discretization.registry import PAPER_CASES, SPACES
    from ..solvers.infsup import beta_rows

    rows = []
    for k in range(1, 5):
        cases = [c for c in PAPER_CASES if SPACES[c].valid_for(k)]
        for n1, n2, mm in [(n, n, "omega2") for n in SWEEP_N] + [(17, 16, "union")]:
            rows += beta_rows("structured", k, n1, n2, cases, mm, norms=("H", "L2"))
    return pd.DataFrame(rows)


def verdict_rows() -> pd.DataFrame:
    """The stability verdict of each case, k and norm over matching N = 4, 8, 16."""
    from ..discretization.registry import PAPER_CASES, SPACES
    from .verdict import verdict_rows as one

    out = []
    for k in range(1, 5):
        for case in (c for c in PAPER_CASES if SPACES[c].valid_for(k)):
            for norm in ("H", "L2"):
                r = one(case, k, "structured", VERDICT_N, norm, **VERDICT_CRITERION)
                out.append(dict(case=case, k=k, norm=norm, verdict=r["verdict"], kernel_dim=r["kernel_dim"]))
    return pd.DataFrame(out)


KEYS = ["case", "k", "N1", "N2", "multiplier_mesh", "norm"]
EXACT = ["kernel_dim", "structural_kernel_dim", "kernel_detected", "kernel_decision", "kernel_check", "dim_M"]


def compare(sweeps: dict, verdicts: dict) -> list:
    """Differences between the tables of several core types (empty: they agree).

    Parameters
    ----------
    sweeps, verdicts : dict
        core type → :func:`sweep_rows` / :func:`verdict_rows` of a process run under it.

    Returns
    -------
    list of str
        One line per disagreement: an exact column or a verdict that differs, or a resolved
        β that differs by more than :func:`beta_tolerance`.
    """
    (ref_core, ref), *others = sweeps.items()
    problems = []
    for core, frame in others:
        both = ref.merge(frame, on=KEYS, suffixes=("", "_other"))
        if len(both) != len(ref) or len(frame) != len(ref):
            problems.append(f"{core}: {len(frame)} rows vs {len(ref)} under {ref_core}")
        for col in EXACT:
            bad = both[both[col] != both[f"{col}_other"]]
            problems += [f"{core} vs {ref_core}: {col} {r[col]} != {r[col + '_other']} at "
                         f"{dict((c, r[c]) for c in KEYS)}" for _, r in bad.iterrows()]
        for col in ("beta", "smallest_nonzero"):
            a, b = both[col].to_numpy(float), both[f"{col}_other"].to_numpy(float)
            rel = np.abs(a - b) / np.maximum(np.abs(a), np.finfo(float).tiny)
            tol = beta_tolerance(both.gap_over_roundoff.to_numpy(float), both.gap_over_roundoff_other.to_numpy(float))
            bad = both[rel > tol]
            problems += [f"{core} vs {ref_core}: {col} {r[col]:.12g} vs {r[col + '_other']:.12g} at "
                         f"{dict((c, r[c]) for c in KEYS)}" for _, r in bad.iterrows()]
    (ref_core, ref), *others = verdicts.items()
    for core, frame in others:
        both = ref.merge(frame, on=["case", "k", "norm"], suffixes=("", "_other"))
        bad = both[(both.verdict != both.verdict_other) | (both.kernel_dim != both.kernel_dim_other)]
        problems += [f"{core} vs {ref_core}: verdict {r.verdict} != {r.verdict_other} for {r.case} k={r.k} {r.norm}"
                     for r in bad.itertuples()]
    return problems


def beta_tolerance(gap_a, gap_b) -> np.ndarray:
    """Relative tolerance of β between two runs: 10**GAP_DECADES/gap_over_roundoff (module
    docstring) where both resolve it, inf (digits of round-off) where either does not."""
    from ..solvers.kernel import GAP_DECADES

    gap = np.minimum(np.asarray(gap_a, float), np.asarray(gap_b, float))
    with np.errstate(divide="ignore"):
        return np.where(gap >= 10.0 ** GAP_DECADES, 10.0 ** GAP_DECADES / gap, np.inf)


def max_beta_difference(sweeps: dict) -> tuple[float, float]:
    """Largest relative difference of β between the core types over the resolved rows, and
    the largest of those differences over its tolerance (<= 1: inside it)."""
    (_, ref), *others = sweeps.items()
    worst, worst_scaled = 0.0, 0.0
    for _, frame in others:
        both = ref.merge(frame, on=KEYS, suffixes=("", "_other"))
        tol = beta_tolerance(both.gap_over_roundoff, both.gap_over_roundoff_other)
        ok = np.isfinite(tol)
        a, b = both.beta.to_numpy(float)[ok], both.beta_other.to_numpy(float)[ok]
        if len(a):
            rel = np.abs(a - b) / np.maximum(np.abs(a), np.finfo(float).tiny)
            worst, worst_scaled = max(worst, float(rel.max())), max(worst_scaled, float((rel / tol[ok]).max()))
    return worst, worst_scaled


def main(out_dir: str) -> None:
    """Write this process's sweep, verdicts and OpenBLAS core names to ``out_dir``."""
    import json

    from ..io import write_atomic, write_csv_atomic

    out = Path(out_dir)
    write_csv_atomic(out / "sweep.csv", sweep_rows().drop(columns=["t_assemble", "t_interface", "t_eig"]))
    write_csv_atomic(out / "verdicts.csv", verdict_rows())
    write_atomic(out / "openblas.json", json.dumps(openblas_corenames()))


def cli(argv=None) -> int:
    """``python -m infsup_contact.study.machines OUT_DIR``: :func:`main`; a missing or unusable
    OUT_DIR is one line on stderr naming it, exit 2."""
    from ..cli.common import OneLineParser, run_study
    from ..errors import InputError

    p = OneLineParser(prog="python -m infsup_contact.study.machines", description=main.__doc__)
    p.add_argument("out_dir", help="directory for sweep.csv, verdicts.csv and openblas.json (created)")

    def check(args):
        out = Path(args.out_dir)
        if not args.out_dir.strip() or (out.exists() and not out.is_dir()):
            raise InputError("out_dir", "a directory to write into (created if missing)", got=args.out_dir)

    return run_study(p, argv, check, lambda args: main(args.out_dir))


if __name__ == "__main__":
    raise SystemExit(cli())
