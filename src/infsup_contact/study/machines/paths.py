"""Verdicts no machine can flip: the same checks under every code path of both BLAS libraries.

OpenBLAS (numpy's and scipy's BLAS) and MKL (PARDISO's Schur complements on the 3D face,
:mod:`infsup_contact.la.pardiso`; ``cblas_dtrsm``) pick their kernels by CPU, so round-off
differs between machines. The kernel dimension and every verdict must not: they rest on
decisions with a stated margin (:mod:`infsup_contact.solvers.kernel`). :data:`PATHS` names the
code paths one CPU can be made to take — OpenBLAS's core types (``OPENBLAS_CORETYPE``) and
MKL's code branches (``MKL_CBWR``) — each with its environment and the CPU it needs
(:func:`runnable`). This module runs a small sweep (the segment's and a face's) in this process,
whichever path it was started with, and compares the tables of several processes:

* ``kernel_dim``, ``kernel_decision`` (and the other :data:`EXACT` columns) and every verdict
  must be identical;
* β_h and β above the kernel must agree wherever the pencil resolves them
  (``gap_over_roundoff`` = β²/η >= 10**GAP_DECADES, η = n ε λ_max): to a relative
  10**GAP_DECADES/gap_over_roundoff (:func:`beta_tolerance`). An eigenvalue error of η would
  move β by η/(2β²) = 1/(2·gap); the pencil's real error is larger — the Cholesky reduction
  by G carries its condition number (up to ~2e3 for the H^{-1/2}_00 Gram at k = 4, N = 64)
  and S comes through a sparse LU — so the tolerance allows 10**GAP_DECADES times η.
  Measured between SkylakeX and Haswell: at most 218/gap over the 49,920 rows of the full
  config's β table (T3, k = 4, unstructured 12:12, β = 0.63: 6e-12 relative), at most 0.13/gap
  on the sweep here. Below the resolved level β's digits are round-off and machine
  dependent, as are timings and margins.

MKL's switch is ``MKL_CBWR``, not ``MKL_ENABLE_INSTRUCTIONS`` (measured with :func:`mkl_probe`,
MKL 2026.2 on an AMD EPYC with AVX-512): MKL_ENABLE_INSTRUCTIONS = SSE4_2, AVX, AVX2, AVX512
or AVX10 left every digit of a PARDISO Schur complement, its solves and a dgemm as without it,
and MKL loaded the same ``libmkl_def`` — it only caps a dispatch that on a non-Intel CPU never
leaves the generic branch, and it says nothing of what it did. ``MKL_CBWR`` is reported back
(``MKL_CBWR_Get``, :func:`~infsup_contact.la.mkl.cbwr_branch`) and changes the digits: COMPATIBLE
(SSE2, ``libmkl_vml_cmpt``) and AUTO (deterministic reductions, static scheduling) each give
PARDISO's S and solves other digits than the default (S₀₀ = 1.7793580495149135, …106, …102): three
distinct results, while every OpenBLAS core type leaves MKL's digits as they are. Its
instruction-set branches (AVX2, AVX512) are for Intel processors: on this AMD CPU MKL refuses
them (``MKL_CBWR_Set`` returns −3, MKL_CBWR_ERR_UNSUPPORTED_BRANCH; ``MKL_CBWR=AVX2`` runs AUTO),
so those paths need ``GenuineIntel`` besides their flags and are skipped here with that reason.

``tests/study/test_machines.py`` runs the sweep and the kernel, verdict and 3D kernel tests under
every path this CPU can take; the DAG target ``verify-machines`` compares the CI profile's
ledgers and kernel tables (:data:`~.ledgers.LEDGER_TABLES`).
"""
from __future__ import annotations

import hashlib
import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ...errors import InputError

SWITCHES = ("OPENBLAS_CORETYPE", "MKL_CBWR", "MKL_ENABLE_INSTRUCTIONS")
"""The variables that select a library's code path: a path's environment drops every one it does
not set, so a path is the same wherever the check was started from."""
AVX512_FLAGS = frozenset({"avx512f", "avx512dq", "avx512bw", "avx512vl"})
"""The AVX-512 subsets of Skylake-SP, which OpenBLAS's SkylakeX kernels and MKL's AVX512 branch use."""


@dataclass(frozen=True)
class MachinePath:
    """One code path of one library, as one CPU can be made to take it.

    Attributes
    ----------
    library : str
        ``openblas`` or ``mkl``.
    setting : str
        The core type (OpenBLAS) or code branch (MKL) selected, ``default`` for none.
    env : dict
        The variables of :data:`SWITCHES` this path sets (the others are removed).
    flags : frozenset
        CPU flags (/proc/cpuinfo; SSE3 is listed as ``pni``) its kernels execute.
    vendor : str
        The CPU vendor (``vendor_id``) the library takes the path on; empty: any.
    """

    library: str
    setting: str
    env: dict = field(default_factory=dict)
    flags: frozenset = frozenset()
    vendor: str = ""

    @property
    def name(self) -> str:
        """``library:setting``, as reports and tables name the path."""
        return f"{self.library}:{self.setting}"

    @property
    def wildcard(self) -> str:
        """``library-setting``: the name in file names and Snakemake wildcards."""
        return f"{self.library}-{self.setting}"


def _openblas(core: str, flags: set) -> MachinePath:
    return MachinePath("openblas", core, {"OPENBLAS_CORETYPE": core}, frozenset(flags))


def _mkl(branch: str, flags: set = frozenset(), vendor: str = "") -> MachinePath:
    return MachinePath("mkl", branch, {} if branch == "default" else {"MKL_CBWR": branch}, frozenset(flags), vendor)


PATHS = (
    _openblas("Prescott", {"sse3"}),
    _openblas("Sandybridge", {"avx"}),
    _openblas("Haswell", {"avx2", "fma"}),
    _openblas("SkylakeX", AVX512_FLAGS),
    _openblas("Zen", {"avx2", "fma"}),
    _mkl("default"),
    _mkl("AUTO"),
    _mkl("COMPATIBLE"),
    _mkl("AVX2", {"avx2", "fma"}, vendor="GenuineIntel"),
    _mkl("AVX512", AVX512_FLAGS | {"avx512cd"}, vendor="GenuineIntel"),
)
"""The machine paths the cross-machine checks run under, OpenBLAS's x86-64 kernel families and
MKL's code branches (``default``: no ``MKL_CBWR``, MKL dispatches as on any machine; ``AUTO``:
that dispatch with deterministic reductions). Each path sets one library's switch and leaves the
other library at its own choice."""
PATH_NAMES = tuple(p.name for p in PATHS)


def machine_path(name: str) -> MachinePath:
    """The path called ``name`` (``openblas:Haswell`` or its wildcard ``openblas-Haswell``)."""
    for p in PATHS:
        if name in (p.name, p.wildcard):
            return p
    raise InputError("machine path", "one of " + ", ".join(PATH_NAMES), got=name)


def machine_env(name: str, base: dict | None = None) -> dict:
    """The environment that runs a check on path ``name``: ``base`` (default this process's)
    without the :data:`SWITCHES`, plus the path's own."""
    path = machine_path(name)
    env = {k: v for k, v in (os.environ if base is None else base).items() if k not in SWITCHES}
    return dict(env, **path.env)
SWEEP_N = (4, 8)
"""Matching meshes of the β sweep (with the union partition of the 17:16 pair)."""
FACE_SWEEP = {1: ((14, 14), (14, 16)), 2: ((7, 7), (7, 8))}
"""Hexahedral pairs of the face sweep (membranes3d) by k: the smallest whose sides' Schur
complements come from PARDISO (n · n_Γ above :data:`~infsup_contact.la.schur.SOLVES_MAX_WORK`),
a matching and a non-matching pair each; G_h = Ω2's partition only (the union of the
non-matching pairs, kernels of 336 to 448 modes, would take two thirds of the sweep's time)."""
VERDICT_N = (4, 8, 16)
"""Matching meshes of each verdict (a slope interval needs three)."""
VERDICT_CRITERION = dict(tol=0.15, floor=1e-3, confidence=0.95)
"""The verdict's criterion: the CLI's defaults (``infsup-contact verdict``)."""


def _cpuinfo(key: str, path: str) -> str:
    """The first ``key : value`` of /proc/cpuinfo ("" when the file or key is absent: not Linux on x86)."""
    try:
        text = Path(path).read_text()
    except OSError:
        return ""
    for line in text.splitlines():
        if line.split(":", 1)[0].strip() == key:
            return line.split(":", 1)[1].strip()
    return ""


def cpu_flags(path: str = "/proc/cpuinfo") -> set:
    """The CPU's feature flags (empty when the file is absent: not Linux on x86)."""
    flags = set(_cpuinfo("flags", path).split())
    return flags | ({"sse3"} if "pni" in flags else set())


def cpu_vendor(path: str = "/proc/cpuinfo") -> str:
    """The CPU's ``vendor_id`` (``GenuineIntel``, ``AuthenticAMD``; empty when unknown)."""
    return _cpuinfo("vendor_id", path)


def runnable(name: str, flags: set | None = None, vendor: str | None = None,
             mkl: bool | None = None) -> tuple[bool, str]:
    """Whether this CPU takes path ``name``, and the reason when it does not.

    Parameters
    ----------
    name : str
        A path of :data:`PATHS` (its name or wildcard).
    flags, vendor : set, str, optional
        The CPU's flags and vendor (default: :func:`cpu_flags`, :func:`cpu_vendor`).
    mkl : bool, optional
        Whether MKL loads (default: :func:`infsup_contact.la.mkl.available`); an MKL path needs it.
    """
    path = machine_path(name)
    flags = cpu_flags() if flags is None else flags
    vendor = cpu_vendor() if vendor is None else vendor
    if path.library == "mkl":
        if mkl is None:
            from ...la.mkl import available

            mkl = available()
        if not mkl:
            return False, f"{path.name} needs MKL (the mkl wheel's mkl_rt), which could not be loaded"
    missing = sorted(path.flags - flags)
    if missing:
        return False, f"{path.name} kernels need {', '.join(missing)}, which this CPU lacks (/proc/cpuinfo)"
    if path.vendor and vendor != path.vendor:
        return False, (f"{path.name}: MKL takes its {path.setting} branch on {path.vendor} CPUs only; "
                       f"this one is {vendor or 'unknown'} (MKL refuses the branch and runs AUTO)")
    return True, ""


def openblas_corenames() -> dict:
    """The kernel set OpenBLAS chose in this process, for numpy's and scipy's copies."""
    from ...la.openblas import corenames

    return corenames()


PROBE_N, PROBE_N_GAMMA = 1000, 100
"""Size of the probe's SPD matrix and of its Schur block (:func:`mkl_probe`): PARDISO's
supernodal route (interior far above :data:`~infsup_contact.la.pardiso.MIN_INTERIOR`)."""


def mkl_probe() -> dict:
    """What MKL does in this process: its code branch and the digits of one PARDISO result.

    Returns
    -------
    dict
        ``branch`` (:func:`~infsup_contact.la.mkl.cbwr_branch`: the one ``MKL_CBWR`` asked for
        when MKL took it), ``auto_branch``, ``digest`` (SHA-256 of PARDISO's Schur complement
        :func:`~infsup_contact.la.pardiso.gamma_schur` and a solve of its full factorization
        on a fixed random SPD matrix of size :data:`PROBE_N`: equal digests are equal digits),
        ``s00`` (S's first entry, all digits)
        and ``libraries`` (the MKL libraries loaded, /proc/self/maps: ``libmkl_def`` is the
        generic branch). Empty when MKL does not load.
    """
    import scipy.sparse as sp

    from ...la import mkl
    from ...la.pardiso import Factor, gamma_schur

    if not mkl.available():
        return {}
    rng = np.random.default_rng(20011)
    R = sp.random(PROBE_N, PROBE_N, density=8.0 / PROBE_N, random_state=rng)
    A = sp.csr_matrix(R @ R.T + sp.diags(0.1 + rng.random(PROBE_N)))
    # MKL's digits only: S (phase 12) and a full factorization's solve (phase 33); SchurFactor's
    # own solve takes S's Cholesky factor from scipy's LAPACK, i.e. from OpenBLAS
    S = gamma_schur(A, PROBE_N_GAMMA)
    full = Factor(A)
    x = full.solve(np.ones(PROBE_N))
    full.handle.release()
    try:
        maps = Path("/proc/self/maps").read_text()
    except OSError:
        maps = ""
    return dict(branch=mkl.cbwr_branch(), auto_branch=mkl.cbwr_auto_branch(),
                digest=hashlib.sha256(S.tobytes() + x.tobytes()).hexdigest()[:16], s00=repr(float(S[0, 0])),
                libraries=sorted(set(re.findall(r"(libmkl_\w+)\.so", maps))))


def expected_mkl_branch(name: str) -> str:
    """The branch :func:`~infsup_contact.la.mkl.cbwr_branch` reports on path ``name`` where it
    took effect: its own on an MKL path (``OFF`` for ``default``), ``OFF`` on an OpenBLAS path."""
    path = machine_path(name)
    return path.env.get("MKL_CBWR", "OFF")


def sweep_rows() -> pd.DataFrame:
    """β rows of the paper's five cases, k = 1..4, both norms: matching N = 4, 8 (every
    multiplier mesh is the same partition there) and the union partition of the 17:16 pair;
    and :func:`face_sweep_rows`. Column ``model`` tells them apart."""
    from ...discretization.spaces.registry import PAPER_CASES, SPACES
    from ...solvers.infsup import beta_rows

    rows = []
    for k in range(1, 5):
        cases = [c for c in PAPER_CASES if SPACES[c].valid_for(k)]
        for n1, n2, mm in [(n, n, "omega2") for n in SWEEP_N] + [(17, 16, "union")]:
            rows += beta_rows("structured", k, n1, n2, cases, mm, norms=("H", "L2"))
    return pd.concat([pd.DataFrame(rows).assign(model="membranes"), face_sweep_rows()], ignore_index=True)


def face_sweep_rows() -> pd.DataFrame:
    """β rows on the 3D face (membranes3d, hexahedra): the paper's cases defined for k = 1, 2,
    both norms, G_h = Ω2's partition, on the pairs of :data:`FACE_SWEEP` — every side's Schur
    complement from MKL PARDISO, so MKL's path reaches the kernel columns (measured, k = 2, 7:8:
    the default, AUTO and COMPATIBLE branches give both sides' S other bits and move β in its
    15th digit, below the 12 the table keeps)."""
    from ...discretization.spaces.registry import PAPER_CASES, SPACES
    from ...models import make_model
    from ...solvers.infsup import beta_rows_all
    from ...solvers.request import MeshOptions

    model, rows = make_model("membranes3d"), []
    for k, pairs in FACE_SWEEP.items():
        cases = [c for c in PAPER_CASES if SPACES[c].valid_for(k)]
        for n1, n2 in pairs:
            rows += beta_rows_all("structured", k, n1, n2, cases, ("omega2",), norms=("H", "L2"),
                                  model=model, mesh=MeshOptions(element="hex"))
    return pd.DataFrame(rows).assign(model=model.name)


def verdict_rows() -> pd.DataFrame:
    """The stability verdict of each case, k and norm over matching N = 4, 8, 16."""
    from ...discretization.spaces.registry import PAPER_CASES, SPACES
    from ..verdict import verdict_rows as one

    out = []
    for k in range(1, 5):
        for case in (c for c in PAPER_CASES if SPACES[c].valid_for(k)):
            for norm in ("H", "L2"):
                r = one(case, k, "structured", VERDICT_N, norm, **VERDICT_CRITERION)
                out.append(dict(case=case, k=k, norm=norm, verdict=r["verdict"], kernel_dim=r["kernel_dim"]))
    return pd.DataFrame(out)


def main(out_dir: str) -> None:
    """Write this process's sweep, verdicts, OpenBLAS core names and MKL probe to ``out_dir``."""
    from ...io import write_atomic, write_csv_atomic

    out = Path(out_dir)
    write_csv_atomic(out / "sweep.csv", sweep_rows().drop(columns=["t_assemble", "t_interface", "t_eig"]))
    write_csv_atomic(out / "verdicts.csv", verdict_rows())
    write_atomic(out / "openblas.json", json.dumps(openblas_corenames()))
    write_atomic(out / "mkl.json", json.dumps(mkl_probe()))


def cli(argv=None) -> int:
    """``python -m infsup_contact.study.machines.paths OUT_DIR``: :func:`main`; ``--probe``: print the
    libraries' state (a path's evidence) only. A missing or unusable OUT_DIR is one line on
    stderr naming it, exit 2."""
    import sys

    from ...command_line import OneLineParser, run_study
    from ...errors import InputError

    argv = sys.argv[1:] if argv is None else list(argv)
    if argv == ["--probe"]:
        print(json.dumps(dict(openblas=openblas_corenames(), mkl=mkl_probe())))
        return 0
    p = OneLineParser(prog="python -m infsup_contact.study.machines.paths", description=main.__doc__)
    p.add_argument("out_dir", help="directory for sweep.csv, verdicts.csv, openblas.json and mkl.json (created)")

    def check(args):
        out = Path(args.out_dir)
        if not args.out_dir.strip() or (out.exists() and not out.is_dir()):
            raise InputError("out_dir", "a directory to write into (created if missing)", got=args.out_dir)

    return run_study(p, argv, check, lambda args: main(args.out_dir))


if __name__ == "__main__":
    raise SystemExit(cli())
