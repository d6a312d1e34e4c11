"""The census: one row per producer, space and offset, from the producers table and the config.

What each code ships, certified (``results/tables/producers.csv``, :mod:`.producers`) beside what
was predicted for it (the config's ``producers.codes.<code>.predictions``): per (code, space,
offset) the verdict in the first norm of :data:`NORM_ORDER` that ran (``H``: the inf-sup condition's
own norm) with the others' summarised, the kernel of Bᵀ against dim M_h per level, β_h per level,
the slope and its interval, the prediction's ``fix`` (one line: what makes the space stable), the
claim's verdict from the ledger, the commit since which the config holds the prediction
(:func:`prediction_commits`), and the class of a stabilised system (a manifest with a C block:
``stabilisation``, where the producers table has it, else ``-``). A code that is not installed
has its configured spaces and offsets as rows with the verdict NOT RUN and its install command. Everything is read from the tables and
the config: a new producer needs no code here.
"""
from __future__ import annotations

import math
import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd

CENSUS_COLUMNS = ("code", "version", "space", "offset", "matching", "norm", "status", "verdict", "predicted",
                  "other_norms", "kernel_levels", "dim_M_levels", "kernel_vs_dim", "h_levels", "beta_levels", "slope",
                  "slope_lo", "slope_hi", "fix", "claim", "predicted_in", "evidence", "stabilisation")
NORM_ORDER = ("H", "h-L2", "L2")
"""Which norm's verdict a census row shows: the first of these that ran (the others summarised)."""
NONE = "-"
"""An empty census cell: no prediction, no level, no commit to name."""
NOT_RUN = "NOT RUN"
NOT_GIVEN = "not given"
"""The fix cell of a space found or predicted UNSTABLE whose prediction gives no ``fix``."""
UNCOMMITTED = "uncommitted"
"""The predicted_in cell of a prediction no commit of the config's history holds as it is now."""
CONFIG = "config/config.yaml"


def matching(offset) -> str:
    """``matching`` for offset 0 (both bodies meshed alike on Γ), else ``non-matching``."""
    return "matching" if int(offset) == 0 else "non-matching"


def census_table(table: pd.DataFrame, claims: pd.DataFrame, cfg: dict, predicted_in: dict | None = None):
    """The census (:data:`CENSUS_COLUMNS`), in the producers table's order. ``cfg``: the config's
    ``producers`` section; ``predicted_in``: (code, space) → its commit (:func:`prediction_commits`;
    default none known)."""
    predicted_in = predicted_in or {}
    verdicts = dict(zip(claims.claim_id, claims.verdict)) if len(claims) else {}
    out = []
    for code, rows in table.groupby("producer", sort=False):
        spec = cfg["codes"].get(code, {})
        if (rows.status == "not installed").all():
            out += _not_run(code, spec, cfg, rows.iloc[0], verdicts, predicted_in)
            continue
        for (space, offset), group in rows.groupby(["space", "offset"], sort=False):
            pred = (spec.get("predictions") or {}).get(space)
            out.append(_row(code, space, int(offset), group, pred, verdicts, predicted_in))
    return pd.DataFrame(out, columns=list(CENSUS_COLUMNS))


def _row(code: str, space: str, offset: int, group: pd.DataFrame, pred, verdicts: dict, predicted_in: dict) -> dict:
    """One (code, space, offset): the verdict of its first norm of :data:`NORM_ORDER`, the others summarised."""
    ran = list(group.norm)
    if "norm_as_written" in group:  # a manifest that cannot describe its multipliers in H (FreeFEM's star-shaped
        # skeleton: `norm: given`, the L² mass) has no H certificate: its "H" row is that pencil, the next norm leads
        written = dict(zip(group.norm, group.norm_as_written.astype(object).fillna("H").astype(str)))
        ran = [n for n in ran if n != "H" or written.get(n) in ("H", "")] or ran
    norm = next((n for n in NORM_ORDER if n in ran), ran[0])
    r = group[group.norm == norm].iloc[0]
    ok = r.status == "ok"
    verdict = r.verdict if ok else "refused"
    kernels, dims = _split(r.kernel_levels), _split(r.dim_M_levels)
    others = [f"{o.norm} {o.verdict if o.status == 'ok' else 'refused'}" for o in group.itertuples() if o.norm != norm]
    return dict(code=code, version=_text(r.version), space=space, offset=offset, matching=matching(offset), norm=norm,
                status="ok" if ok else r.status, verdict=verdict, predicted=_predicted(pred, norm),
                other_norms=", ".join(others) or NONE, kernel_levels=" ".join(kernels) or NONE,
                dim_M_levels=" ".join(dims) or NONE,
                kernel_vs_dim=" ".join(f"{k}/{d}" for k, d in zip(kernels, dims)) if len(kernels) == len(dims) and dims
                else NONE,
                h_levels=_text(r.h_levels), beta_levels=_text(r.beta_levels), slope=_float(r.slope),
                slope_lo=_float(r.slope_lo), slope_hi=_float(r.slope_hi), fix=_fix(pred, verdict, norm),
                claim=verdicts.get(f"producer-{code}-{space}", NONE) if pred else NONE,
                predicted_in=predicted_in.get((code, space), NONE) if pred else NONE,
                evidence=_text(r.evidence if ok else r.status),
                stabilisation=_text(r.stabilisation) if ok and "stabilisation" in group else NONE)


def _not_run(code: str, spec: dict, cfg: dict, row, verdicts: dict, predicted_in: dict) -> list:
    """The rows of a code not installed: each configured space and offset, NOT RUN, with the install command."""
    preds = spec.get("predictions") or {}
    norms = cfg.get("norms") or [NONE]
    norm = next((n for n in NORM_ORDER if n in norms), norms[0])
    out = []
    for space in spec.get("spaces") or [NONE]:
        pred = preds.get(space)
        for offset in spec.get("offsets", cfg.get("offsets", [0])):
            out.append(dict(code=code, version=NONE, space=space, offset=int(offset), matching=matching(offset),
                            norm=norm, status="not installed", verdict=NOT_RUN, predicted=_predicted(pred, norm),
                            other_norms=NONE, kernel_levels=NONE, dim_M_levels=NONE, kernel_vs_dim=NONE,
                            h_levels=NONE, beta_levels=NONE, slope=np.nan, slope_lo=np.nan, slope_hi=np.nan,
                            fix=_fix(pred, NOT_RUN, norm), claim=verdicts.get(f"producer-{code}-{space}", NONE) if pred
                            else NONE, predicted_in=predicted_in.get((code, space), NONE) if pred else NONE,
                            evidence=f"not installed: run `{row.install}`", stabilisation=NONE))
    return out


def _predicted(pred, norm: str) -> str:
    return (pred or {}).get("verdicts", {}).get(norm, NONE)


def _fix(pred, verdict: str, norm: str) -> str:
    """The prediction's ``fix``; where none is given, :data:`NOT_GIVEN` for a space found (or, not
    run, predicted) UNSTABLE in the row's ``norm``, else :data:`NONE` (nothing to fix)."""
    if pred and pred.get("fix"):
        return " ".join(str(pred["fix"]).split())
    unstable = verdict == "UNSTABLE" or (verdict == NOT_RUN and _predicted(pred, norm) == "UNSTABLE")
    return NOT_GIVEN if unstable else NONE


def _split(cell) -> list:
    return [] if _text(cell) == NONE else _text(cell).split()


def _text(cell) -> str:
    """A cell as one line of text; :data:`NONE` for an empty one (NaN as read by pandas). A number
    (a one-level series, a version pandas read as a float) is its text."""
    if cell is None or (isinstance(cell, float) and math.isnan(cell)):
        return NONE
    text = " ".join(str(cell).split())
    return text or NONE


def _float(value) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


# ---------------------------------------------------------------- when each prediction was written

def prediction_commits(codes: dict, root: Path = Path("."), path: str = CONFIG) -> dict:
    """(code, space) → ``"<commit> <date>"``: the oldest commit of ``path``'s history (in ``root``'s
    git repository) whose config holds the prediction's verdicts and kernel as ``codes`` has them now;
    :data:`UNCOMMITTED` where none does (written, or changed, and not committed); :data:`NONE` for
    every prediction where there is no history to read (no git, no repository: an installed wheel,
    a tarball). The ``why`` and ``fix`` text may change afterwards; a changed verdict or kernel is a
    new prediction, dated by its own commit. A shallow clone dates by the oldest commit it has."""
    wanted = {(code, space): _prediction_key(pred) for code, spec in codes.items()
              for space, pred in (spec.get("predictions") or {}).items()}
    log = _git(root, "log", "--format=%h %cs", "--", path)
    if not log or not wanted:
        return {key: NONE for key in wanted}
    found = {}
    for line in log.splitlines():  # newest first: the last match is the oldest
        commit, date = line.split()[:2]
        held = _committed_predictions(_git(root, "show", f"{commit}:{path}") or "")
        for key, value in wanted.items():
            if held.get(key) == value:
                found[key] = f"{commit} {date}"
    return {key: found.get(key, UNCOMMITTED) for key in wanted}


def _prediction_key(pred: dict) -> tuple:
    """What a prediction asserts: its verdict per norm and its kernel (not its words)."""
    return tuple(sorted((pred.get("verdicts") or {}).items())), pred.get("kernel")


def _committed_predictions(text: str) -> dict:
    """(code, space) → :func:`_prediction_key` of one committed config's ``producers`` section
    (parsed alone: the rest of the file is not read); {} where it has none or does not parse."""
    import yaml

    match = re.search(r"^producers:[^\n]*\n(?:(?:[ \t#][^\n]*)?\n)*", text, flags=re.M)
    if not match:
        return {}
    try:
        section = (yaml.load(match.group(0), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader)) or {})["producers"]
        codes = section["codes"]
        return {(code, space): _prediction_key(pred) for code, spec in codes.items()
                for space, pred in ((spec or {}).get("predictions") or {}).items() if isinstance(pred, dict)}
    except (yaml.YAMLError, KeyError, TypeError, AttributeError):
        return {}


def _git(root: Path, *args) -> str | None:
    """``git -C root args``'s stdout, or None where git or the repository is missing or it fails."""
    env = dict(os.environ, GIT_TERMINAL_PROMPT="0", GIT_OPTIONAL_LOCKS="0")
    try:
        done = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True, timeout=60,
                              stdin=subprocess.DEVNULL, env=env)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return done.stdout if done.returncode == 0 else None
