"""``--dry-run``'s estimates against the measured cost of the requests the docs show.

    python -m infsup_contact.bench.estimates results/benchmarks/estimates.csv [--only NAME ...]

Each example (:data:`EXAMPLES`) is first run with ``--dry-run`` (its printed estimate read back:
3 significant digits of memory, 2 of time), then as a child process, ``infsup-contact ARGS``, with one BLAS/MKL thread;
``os.wait4`` gives the child's maximum resident set size and its CPU time (user + sys). The
time is compared with the CPU time, not the wall time: the benchmark runs on machines shared
with other work, where the wall time of a one-thread process grows with the load and its CPU
time hardly does (the load average before and after each run is written beside it). Examples
that read a foreign system first write it (``setup``, not measured) into a scratch directory.

Rows: ``example``, ``command``, the estimate (``est_mib``, ``est_s``), the measurement
(``rss_mib``, ``cpu_s``, ``wall_s``), ``mem_ratio`` = est_mib / rss_mib and ``time_ratio`` =
est_s / cpu_s, ``load_before``/``load_after`` (1-minute load average). docs/performance.md's
table "Estimates" is generated from it (workflow/scripts/docs_performance.py); rule
``bench_estimates`` (``snakemake bench_estimates``, not part of reproduce-all: minutes of CPU).
"""
from __future__ import annotations

import argparse
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

MIB = 1024 ** 2
ROOT = Path(__file__).resolve().parents[3]


@dataclass(frozen=True)
class Example:
    """One documented request: ``infsup-contact ARGS`` after the (unmeasured) ``setup`` commands,
    each a list of argv words; ``{tmp}`` stands for the scratch directory."""

    name: str
    args: tuple
    setup: tuple = ()


_FACE = ("beta", "--model", "membranes3d", "--case", "all")
EXAMPLES = (
    Example("hex k=1 N=16", _FACE + ("--k", "1", "--N1", "16", "--N2", "16")),
    Example("hex k=2 N=8 (docs/models.md)", _FACE + ("--k", "2", "--N1", "8", "--N2", "8")),
    Example("hex k=2 N=16 (issue 50)", _FACE + ("--k", "2", "--N1", "16", "--N2", "16")),
    Example("hex k=2 N=24, both norms", _FACE + ("--k", "2", "--N1", "24", "--N2", "24", "--norm", "all")),
    Example("hex k=2 N=32, both norms (~4 GB)", _FACE + ("--k", "2", "--N1", "32", "--N2", "32", "--norm", "all")),
    Example("tet k=2 N=8 (docs/models.md)", _FACE + ("--element", "tet", "--k", "2", "--N1", "8", "--N2", "8")),
    Example("hex20 k=2 N=8 (docs/models.md)", _FACE + ("--element", "hex20", "--k", "2", "--N1", "8", "--N2", "8")),
    Example("Stokes P2-P1 16..128 (examples/stokes_skfem.py)", ("verdict", "--system", "{tmp}/levels.yaml"),
            setup=(("{python}", "examples/stokes_skfem.py", "write", "P2-P1", "16", "32", "64", "128",
                    "--out", "{tmp}"),)),
    Example("verdict --system: membranes3d export T3 k=2 N=4,6,8", ("verdict", "--system", "{tmp}/levels.yaml"),
            setup=(("{cli}", "export", "--model", "membranes3d", "--case", "T3", "--k", "2", "--N", "4", "6", "8",
                    "--out", "{tmp}"),)),
)

COLUMNS = ("example", "command", "est_mib", "rss_mib", "mem_ratio", "est_s", "cpu_s", "wall_s", "time_ratio",
           "load_before", "load_after")


def _cli() -> str:
    return str(Path(sys.executable).parent / "infsup-contact")


def _env() -> dict:
    # one thread everywhere: the estimate models the CLI's default (one BLAS thread), and the
    # CPU time of a one-thread process is its wall time on a quiet machine
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT / "src"), env.get("PYTHONPATH")]))
    return env


def _fill(words, tmp: str) -> list:
    return [w.format(tmp=tmp, python=sys.executable, cli=_cli()) for w in words]


_BYTES = {"B": 1, "KiB": 1024, "MiB": MIB, "GiB": 1024 * MIB, "TiB": 1024 ** 4}
_SECONDS = {"s": 1, "min": 60, "h": 3600, "days": 86400, "years": 365.25 * 86400}
_DRY = re.compile(r"estimated ~(?P<mem>[\d.e+]+) (?P<mu>\S+) peak memory, ~(?P<t>[\d.e+]+) (?P<tu>\S+)")


def parse_dry_run(line: str) -> tuple:
    """(bytes, seconds) of ``--dry-run``'s line, "… estimated ~1.07 GiB peak memory, ~21 s …"
    (:meth:`~infsup_contact.resources.Estimate.describe`: 3 and 2 significant digits)."""
    m = _DRY.search(line)
    if m is None or m["mu"] not in _BYTES or m["tu"].rstrip(" (") not in _SECONDS:
        raise ValueError(f"not a dry-run estimate: {line.strip()!r}")
    return float(m["mem"]) * _BYTES[m["mu"]], float(m["t"]) * _SECONDS[m["tu"]]


def estimate(args) -> tuple:
    """(bytes, seconds): what ``infsup-contact ARGS --dry-run`` prints, read from its output (as a
    user reads it; the CLI sits above this package's benchmarks)."""
    run = subprocess.run([_cli(), *args, "--dry-run"], env=_env(), capture_output=True, text=True, check=False)
    if run.returncode != 0:
        raise RuntimeError(f"{shlex.join(args)} --dry-run exited {run.returncode}: {run.stderr.strip()[-500:]}")
    return parse_dry_run(run.stdout)


def measure(argv) -> dict:
    """Run ``argv`` as a child: max RSS (MiB), CPU seconds (user + sys), wall seconds."""
    with tempfile.TemporaryFile() as log:  # a file, not a pipe: a chatty child never blocks on it
        t0 = time.perf_counter()
        proc = subprocess.Popen(argv, env=_env(), stdout=subprocess.DEVNULL, stderr=log)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        log.seek(0)
        err = log.read().decode(errors="replace")
    if proc.returncode not in (0, 1):  # 1: verdict's expectation not met, still measured
        raise RuntimeError(f"{shlex.join(argv)} exited {proc.returncode}: {err.strip()[-500:]}")
    return {"rss_mib": usage.ru_maxrss * 1024 / MIB, "cpu_s": usage.ru_utime + usage.ru_stime, "wall_s": wall}


def run_example(ex: Example) -> dict:
    """One row of the table: the estimate, then the measured run."""
    with tempfile.TemporaryDirectory(prefix="infsup-estimates-") as tmp:
        for words in ex.setup:
            subprocess.run(_fill(words, tmp), env=_env(), cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        args = _fill(ex.args, tmp)
        est_bytes, est_s = estimate(args)
        load_before = os.getloadavg()[0]
        got = measure([_cli(), *args])
        load_after = os.getloadavg()[0]
    est_mib = est_bytes / MIB
    command = "infsup-contact " + " ".join(ex.args).replace("{tmp}", "DIR")
    return {"example": ex.name, "command": command, "est_mib": est_mib, "rss_mib": got["rss_mib"],
            "mem_ratio": est_mib / got["rss_mib"], "est_s": est_s, "cpu_s": got["cpu_s"], "wall_s": got["wall_s"],
            "time_ratio": est_s / got["cpu_s"], "load_before": load_before, "load_after": load_after}


def fit_large_route_3d(points, components: int = 1) -> tuple:
    """(a, b, c, d) of ``resources.LARGE_ROUTE_3D`` (before its margin) from measured requests
    ``points`` = [(k, N, peak bytes, CPU seconds), ...] of one degree on the large route: non-negative
    least squares on relative residuals of bytes − process − MKL = a Σnd + b m² and seconds − start =
    c Σnd + d m³ (m = (k N + 1)²), the way the constants were fitted. At least two sizes."""
    import numpy as np
    from scipy.optimize import nnls

    from .. import resources as R

    rows_b, rows_t, rhs_b, rhs_t = [], [], [], []
    for k, n, peak, cpu in points:
        nd = 2 * components * R.face_side_dofs(n, k)
        m = float(R._large_route_dim(k, n, components))
        mem = peak - R.PROCESS_BYTES["beta"] - R.MKL_BYTES
        rows_b.append([nd / mem, m * m / mem])
        rhs_b.append(1.0)
        rows_t.append([nd / (cpu - R.START_SECONDS), m ** 3 / (cpu - R.START_SECONDS)])
        rhs_t.append(1.0)
    (a, b), _ = nnls(np.array(rows_b), np.array(rhs_b))
    (c, d), _ = nnls(np.array(rows_t), np.array(rhs_t))
    return float(a), float(b), float(c), float(d)


def main(argv=None) -> int:
    import pandas as pd

    from ..io import write_atomic

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("output", help="the CSV to write (results/benchmarks/estimates.csv)")
    p.add_argument("--only", nargs="+", metavar="NAME", help="examples whose name starts with NAME (default: all)")
    args = p.parse_args(argv)
    chosen = [ex for ex in EXAMPLES if not args.only or any(ex.name.startswith(o) for o in args.only)]
    if not chosen:
        p.error(f"--only {' '.join(args.only)}: no example starts so (examples: {'; '.join(e.name for e in EXAMPLES)})")
    rows = []
    for ex in chosen:
        row = run_example(ex)
        print(f"[estimates] {ex.name}: memory {row['est_mib']:.0f} / {row['rss_mib']:.0f} MiB "
              f"= {row['mem_ratio']:.2f}; time {row['est_s']:.1f} / {row['cpu_s']:.1f} s CPU = {row['time_ratio']:.2f} "
              f"(wall {row['wall_s']:.1f} s, load {row['load_before']:.1f} → {row['load_after']:.1f})",
              file=sys.stderr, flush=True)
        rows.append(row)
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    write_atomic(args.output, pd.DataFrame(rows, columns=list(COLUMNS)).to_csv(index=False, float_format="%.4g"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
