"""The producers stage: other codes' exporters run, their systems certified in each norm.

A producer (``examples/producers/<code>/export.py``) obeys one contract: run by its code's
own interpreter as ``export.py --out DIR --space SPACE --N ... [--offset K]`` it writes
``DIR/levels.yaml`` (``norm: H``, the multipliers described on Γ, G the L² mass) and the
level matrices, prints nothing on stdout and exits 0. This module runs it for each space and
offset, certifies the manifest in each requested norm (``H`` as written; ``L2``, ``h-L2`` on
copies with ``norm`` changed and the multiplier description left out) by the library call
``verdict --system`` makes, and returns one table row per (producer, space, offset, norm).
A producer whose interpreter or code is missing gives one row ``status: not installed`` with
its install command, never a failure, and its predicted claims the verdict NOT RUN.
:func:`installation` is what the workflow reruns the stage on (rules/producers.smk): each
code's interpreter and the version it reports, so installing or upgrading a code reruns it.
"""
from __future__ import annotations

import functools
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from .. import progress
from ..errors import InputError
from ..yaml_limits import load as yaml_load

COLUMNS = ("producer", "version", "space", "offset", "norm", "status", "verdict", "kernel_dim", "beta_levels",
           "kernel_levels", "h_levels", "slope", "slope_lo", "slope_hi", "evidence", "seconds", "install", "system",
           "dim_M_levels", "stabilisation", "norm_as_written")
MODE_COLUMNS = ("producer", "space", "offset", "level", "h", "beta", "in_kernel", "x", "mu")
"""The finest level's worst mode of each export in norm ``H`` (sampled on Γ): the census' mode plots."""
MODE_FILE = "mode-H.csv"
"""Where :func:`producer_rows` leaves it, in the export's folder."""
NO_CELL = "-"
"""The space, norm and level cells of a row of a producer that did not run."""
H_ONLY_KEYS = ("gamma",)
H_LEVEL_KEYS = ("multipliers", "traces")
EXPORT_TIMEOUT = 600.0
"""Seconds an exporter may take for all its levels (far above what the exporters take for N = 4..32)."""
PAPER_REF = "beyond the paper (Certifying production codes)"
"""The paper_ref of every producer claim."""


def installed_version(python: str, distribution: str, probe: str | None = None) -> str | None:
    """The producer's code version as its own interpreter sees it, or None (interpreter or
    distribution missing). ``probe``: Python code printing it, for a code installed without
    package metadata (Debian's python3-getfem); default the distribution's metadata."""
    if not Path(python).is_file():
        return None
    probe = probe or f"import importlib.metadata as m; print(m.version({distribution!r}))"
    try:
        done = subprocess.run([python, "-c", probe], capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return done.stdout.strip() if done.returncode == 0 and done.stdout.strip() else None


@functools.lru_cache(maxsize=None)
def _cached_version(python: str, distribution: str, probe: str | None) -> str | None:
    return installed_version(python, distribution, probe)


def installation(codes: dict, root: Path = Path(".")) -> dict:
    """Each code's interpreter and the version it reports (``"not installed"`` where none):
    the params of rule ``producers``, so that a change (``make producers-<code>``, an upgrade,
    another interpreter) reruns the stage. One probe per code and process (cached): Snakemake
    evaluates params more than once while it builds the DAG."""
    out = {}
    for name, spec in codes.items():
        python = _python(spec, root)
        version = _cached_version(python, spec["distribution"], spec.get("version"))
        out[name] = f"{python} {version if version is not None else 'not installed'}"
    return out


def _python(spec: dict, root: Path) -> str:
    """A code's interpreter: relative paths are to the repository root."""
    return spec["python"] if Path(spec["python"]).is_absolute() else str(root / spec["python"])


def run_export(python: str, script: Path, out: Path, space: str, ns, offset: int) -> float:
    """Run one export by the contract; its seconds. :class:`InputError` naming the exporter
    when it exits non-zero, prints on stdout or writes no manifest."""
    cmd = [python, str(script), "--out", str(out), "--space", space, "--N", *map(str, ns), "--offset", str(offset)]
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=EXPORT_TIMEOUT)
    seconds = time.perf_counter() - t0
    sys.stderr.write(done.stderr)
    last = (done.stderr.strip().splitlines() or [""])[-1]
    if done.returncode != 0:
        raise InputError(str(script), f"exit {done.returncode} for --space {space} --offset {offset}: {last}")
    if done.stdout.strip():
        raise InputError(str(script), f"printed on stdout (the contract: nothing): {done.stdout.strip()[:80]!r}")
    if not (out / "levels.yaml").is_file():
        raise InputError(str(script), f"exit 0 but no {out / 'levels.yaml'}")
    return seconds


def norm_copy(manifest: Path, norm: str) -> Path:
    """The manifest itself for ``H``; for another norm a copy beside it with ``norm`` changed
    and the Γ description (``gamma``, per level ``multipliers``) left out."""
    import yaml

    if norm == "H":
        return manifest
    data = yaml_load(manifest.read_text())
    data["norm"] = norm
    for key in H_ONLY_KEYS:
        data.pop(key, None)
    for level in data.get("levels", []):
        for key in H_LEVEL_KEYS:
            level.pop(key, None)
    path = manifest.with_name(f"levels-{norm}.yaml")
    path.write_text(yaml.safe_dump(data, sort_keys=False, allow_unicode=True))
    return path


def certify(manifest: Path, criterion: dict, modes: list | None = None) -> dict:
    """The verdict of ``verdict --system`` on ``manifest`` and its per-level β_h and kernel
    dimensions against dim M_h (``dim_M_levels``: the multipliers m certified, the constrained
    rows removed); a manifest the certifier refuses gives ``status: refused: <its line>``.
    ``modes``: a list that receives each level's worst mode (the levels describe their multipliers)."""
    from ..systems.levels import system_verdict
    from ..systems.manifest import load_manifest
    from ..systems.readers import SystemFileError

    t0 = time.perf_counter()
    try:
        loaded = load_manifest(manifest)
        head, rows = system_verdict(loaded, tol=criterion["slope_tolerance"],
                                    floor=criterion["beta_floor"], confidence=criterion["confidence"], modes=modes)
    except (SystemFileError, InputError) as err:
        return dict(status=f"refused: {' '.join(str(err).split())}", verdict="", seconds=time.perf_counter() - t0)
    return dict(status="ok", verdict=head["verdict"], kernel_dim=int(head["kernel_dim"]),
                beta_levels=" ".join(f"{r['beta']:.6g}" for r in rows),
                kernel_levels=" ".join(str(int(r["kernel_detected"])) for r in rows),
                dim_M_levels=" ".join(str(int(r["m"])) for r in rows),
                stabilisation=str(head.get("stabilisation", "")),  # a manifest with C (where certified): its class
                # the norm the manifest states: the stage's "H" row of a `norm: given` manifest is no H^-1/2 pencil
                norm_as_written=loaded.norm,
                h_levels=" ".join(f"{r['h']:g}" for r in rows),
                slope=_num(head.get("slope")), slope_lo=_num(head.get("slope_lo")), slope_hi=_num(head.get("slope_hi")),
                evidence=" ".join(str(head["evidence"]).split()), system=head["system"],
                seconds=time.perf_counter() - t0)


def _num(value) -> float:
    """A finite float or NaN: an unbounded slope interval (−inf, inf) is said in the evidence."""
    try:
        value = float(value)
    except (TypeError, ValueError):
        return float("nan")
    return value if np.isfinite(value) else float("nan")


def producer_rows(name: str, spec: dict, cfg: dict, workdir: Path, root: Path = Path(".")) -> list:
    """Every row of one producer (``cfg``: the config's ``producers`` section; ``spec`` its
    entry under ``codes``): exports under ``workdir/<name>/<space>_k<offset>``."""
    python = _python(spec, root)
    base = dict(producer=name, install=spec["install"])
    version = installed_version(python, spec["distribution"], spec.get("version"))
    if version is None:
        return [dict(base, version="", space=NO_CELL, offset=0, norm=NO_CELL, status="not installed",
                     verdict="", evidence=f"{spec['distribution']} not importable by {spec['python']}: "
                     f"run `{spec['install']}`")]
    out = []
    script = root / spec["export"]
    for space in progress.steps(spec["spaces"], f"{name} space"):
        for offset in progress.steps(spec.get("offsets", cfg["offsets"]), "offset"):  # a code's own: DOLFINx ties matching meshes only
            target = workdir / name / f"{space}_k{offset}"
            _empty_dir(target, workdir)
            ns = spec.get("N", cfg["N"])  # a code's own levels (GetFEM: its pre-asymptotic coarse level)
            progress.note(f"{name} export.py, N={' '.join(map(str, ns))}")
            seconds = run_export(python, script, target, space, ns, offset)
            for norm in progress.steps(cfg["norms"], "verdict --system, norm"):
                modes = [] if norm == "H" and _described(target / "levels.yaml") else None
                row = certify(norm_copy(target / "levels.yaml", norm), cfg["criterion"], modes)
                if modes and row["status"] == "ok":  # the finest level's, for the census' mode plots (study/census.py)
                    _write_mode(target / MODE_FILE, modes[-1], dict(producer=name, space=space, offset=int(offset)))
                row["seconds"] = row["seconds"] + (seconds if norm == cfg["norms"][0] else 0.0)
                out.append(dict(base, version=version, space=space, offset=int(offset), norm=norm, **row))
    return out


def _described(manifest: Path) -> bool:
    """Whether every level describes its multipliers on Γ (what a mode is evaluated with)."""
    levels = yaml_load(manifest.read_text()).get("levels") or []
    return bool(levels) and all(isinstance(lv, dict) and lv.get("multipliers") for lv in levels)


def _write_mode(path: Path, mode, keys: dict) -> None:
    """One level's worst mode sampled on Γ (:func:`~infsup_contact.solvers.modes.mode_on_gamma`),
    written atomically as :data:`MODE_COLUMNS` (a face's Γ: ``x`` the first coordinate, ``y`` the second)."""
    import pandas as pd

    from ..io import write_csv_atomic
    from ..solvers.modes import mode_on_gamma

    x, mu = mode_on_gamma(mode)
    cols = {"x": x} if np.ndim(x) == 1 else {"x": x[:, 0], "y": x[:, 1]}
    head = dict(keys, level=int(mode.keys["level"]), h=float(mode.keys["h"]), beta=float(mode.beta),
                in_kernel=bool(mode.in_kernel))
    write_csv_atomic(path, pd.DataFrame({**{k: [v] * len(mu) for k, v in head.items()}, **cols, "mu": mu}))


def producers_modes(table, workdir: Path):
    """The modes :func:`producer_rows` left for the table's certified ``H`` rows (:data:`MODE_COLUMNS`;
    none where the manifest did not describe its multipliers): only the rows of this table, so a
    space dropped from the config leaves no stale mode behind."""
    import pandas as pd

    from ..io import read_table

    parts = []
    for r in table[(table.status == "ok") & (table.norm == "H")].itertuples():
        path = Path(workdir) / r.producer / f"{r.space}_k{r.offset}" / MODE_FILE
        if path.is_file():
            parts.append(read_table(path, "producer_modes"))
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=list(MODE_COLUMNS))


def _empty_dir(path: Path, workdir: Path) -> None:
    """A fresh export directory (the exporters refuse a non-empty one). Only a folder strictly
    inside ``workdir`` is ever deleted: a code name or space that is a path (``/home``, ``..``;
    the config checks refuse them first) is an :class:`InputError`, nothing deleted."""
    import shutil

    root = Path(workdir).resolve()
    target = Path(path).resolve()
    if target == root or root not in target.parents or Path(path).is_symlink():
        raise InputError("producers.codes", "a code name and spaces that are plain names (the export folder "
                         f"must lie inside {workdir})", got=str(path))
    if target.exists():
        shutil.rmtree(target)
    target.parent.mkdir(parents=True, exist_ok=True)


def producers_table(cfg: dict, workdir: Path, root: Path = Path(".")):
    """The producers table (:data:`COLUMNS`), the producers' rows in the config's order. The producers
    run side by side (one thread each: most of an export's wall time is the other code's start-up,
    its libraries read from disk, in a process of its own, so their waits overlap); each writes under
    its own ``workdir/<name>``, and the rows are the same as one after the other (only ``seconds``
    differs)."""
    from concurrent.futures import ThreadPoolExecutor

    import pandas as pd

    codes = list(cfg["codes"].items())
    with ThreadPoolExecutor(max_workers=max(1, len(codes))) as pool:
        runs = [pool.submit(producer_rows, name, spec, cfg, Path(workdir), root) for name, spec in codes]
        rows = [r for run in runs for r in run.result()]
    frame = pd.DataFrame(rows)
    for col in COLUMNS:
        if col not in frame:
            frame[col] = np.nan if col in ("kernel_dim", "slope", "slope_lo", "slope_hi", "seconds") else ""
    for col in ("beta_levels", "kernel_levels", "h_levels", "evidence", "system", "verdict", "version", "dim_M_levels",
                "stabilisation", "norm_as_written"):
        frame[col] = frame[col].fillna("").astype(str)
    return frame[list(COLUMNS)]


def producers_claims(frame, cfg: dict):
    """One ledger claim per (producer, space) with a prediction in the config
    (``codes.<name>.predictions.<space>``: ``verdicts`` per norm, optionally ``kernel``, the
    dimension of the kernel of Bᵀ on every level), over every offset and norm it ran in.
    PASS when every certificate is the predicted one; FAIL when a decided certificate
    (STABLE/UNSTABLE) differs; INCONCLUSIVE when one is INCONCLUSIVE or refused. A producer
    that is not installed keeps its predicted claims, each with the verdict NOT RUN and its
    table row's evidence (the install command): the ledger says what was not checked."""
    import pandas as pd

    from ..criteria.claims import FAIL, INCONCLUSIVE, NOT_RUN, PASS, row

    out = []
    for name, spec in cfg["codes"].items():
        missing = frame[(frame.producer == name) & (frame.status == "not installed")]
        for space, pred in (spec.get("predictions") or {}).items():
            if len(missing):
                out.append(row(f"producer-{name}-{space}", PAPER_REF, _statement(f"{name} {space}", pred),
                               (NOT_RUN, f"not run: {missing.evidence.iloc[0]}")))
                continue
            rows = frame[(frame.producer == name) & (frame.space == space)]
            if rows.empty:
                continue
            wrong, open_, seen = [], [], []
            for r in rows.itertuples():
                where = f"offset {r.offset} {r.norm}"
                expect = pred["verdicts"].get(r.norm)
                if r.status != "ok":
                    open_.append(f"{where}: {r.status}")
                    continue
                kernels = [int(k) for k in str(r.kernel_levels).split()]
                seen.append(f"{where} {r.verdict} kernel {kernels}")
                if r.verdict == INCONCLUSIVE:
                    open_.append(f"{where}: INCONCLUSIVE ({r.evidence[:90]})")
                elif r.verdict != expect or ("kernel" in pred and any(k != pred["kernel"] for k in kernels)):
                    wrong.append(f"{where}: {r.verdict} kernel {kernels}")
            verdict = FAIL if wrong else INCONCLUSIVE if open_ else PASS
            evidence = "; ".join(wrong or open_ or seen)
            statement = _statement(rows.system.iloc[0] or f"{name} {space}", pred, sorted(set(rows.offset)))
            out.append(row(f"producer-{name}-{space}", PAPER_REF, statement, (verdict, evidence)))
    return pd.DataFrame(out, columns=["claim_id", "paper_ref", "statement", "evidence", "verdict", "predicted"])


def _statement(system: str, pred: dict, offsets=None) -> str:
    """A producer claim's statement: the config's prediction (verdict per norm, kernel) and why;
    ``offsets`` those it ran on (none named for a producer that did not run)."""
    kernel = f", kernel of B^T of dim {pred['kernel']} on every level" if "kernel" in pred else ""
    where = f" (offsets {list(offsets)})" if offsets is not None else ""
    return (f"{system}: verdicts " + ", ".join(f"{n} {v}" for n, v in pred["verdicts"].items()) + kernel
            + f"{where}; {pred['why']}")
