"""The CI gate (``snakemake verify-claims``): the claims ledger is trusted only when it is
there, was built from the tables that are there now, and each of them reads under its schema;
then every claim the paper predicts (PASS or FAIL) must have that verdict.

What it refuses, each with one line (:class:`GateError` or :class:`~infsup_contact.io.TableError`):

* a ledger or one of its tables missing (a deleted file, a table a failed job removed);
* a damaged table or ledger (:func:`~infsup_contact.io.read_table`);
* a ledger older than one of its tables, or a table older than what it is made of (``stages``):
  the ledger was not rebuilt from the current tables (a refused or failed rerun, ``--touch``,
  ``--omit-from``: a stale ledger must not pass);
* a verdict or a prediction outside :data:`VERDICTS` / :data:`PREDICTIONS` (a ``"pass"`` or
  ``"PASS "`` would otherwise count as a finding, never checked), or a ledger without one
  predicted claim (nothing checked is not a pass);
* a predicted claim whose verdict differs: a FAIL where the paper predicts PASS, an
  INCONCLUSIVE anywhere a verdict is predicted. Findings (``predicted = finding``) are listed,
  not judged: the paper says nothing about them, and FAIL is one of their results.

A claim with the verdict NOT RUN (an optional producer not installed where the ledger was
built, its evidence naming the install command) is listed by id in the summary line, not
judged: nothing was computed for it. It does not count as checked, so a ledger of only NOT RUN
and findings is still refused.
"""
from __future__ import annotations

import os
from pathlib import Path

from ...criteria.claims import FAIL, FINDING, INCONCLUSIVE, NOT_RUN, PASS

VERDICTS = (PASS, FAIL, INCONCLUSIVE, NOT_RUN)
PREDICTIONS = (PASS, FAIL, FINDING)


class GateError(ValueError):
    """The gate refuses the ledger: the message is one line."""


def _mtime(path) -> int:
    return os.stat(path).st_mtime_ns


def check_stage(product, sources: dict) -> None:
    """``product`` (a file) is at least as new as each of ``sources`` (path → table kind of
    :data:`~infsup_contact.table_schemas.SCHEMAS`; ``kind?``: the table may have no rows, as the
    producers' claims of a config without predictions), and each source exists and reads under its schema."""
    from ...io import TableError, read_table

    for path, kind in sources.items():
        read_table(path, kind.rstrip("?"), allow_empty=kind.endswith("?"))  # missing or damaged: TableError
    if not Path(product).is_file():
        raise TableError(product, "no such file")
    for path in sources:
        if _mtime(path) > _mtime(product):
            raise GateError(f"{product} is older than {path}: it was not rebuilt from the current tables "
                            "(a refused or failed rerun?); rerun `snakemake verify-claims`")


def gate(ledger, stages) -> tuple:
    """Check the ledger (module docstring) and return ``(frame, summary line)``.

    Parameters
    ----------
    ledger : path
        results/claims.csv.
    stages : iterable of (product, {source: kind})
        The ledger and the tables it is made of, and any table with the tables it is made of
        (e.g. the rates table and the contact table): every source must read and be no newer
        than its product.

    Raises
    ------
    GateError, TableError
        One line: a missing, damaged or stale file, an unknown verdict, nothing predicted, or
        predicted claims with another verdict (named).
    """
    from ...io import read_table

    for product, sources in stages:
        check_stage(product, sources)
    frame = read_table(ledger, "claims")
    for col, allowed in (("verdict", VERDICTS), ("predicted", PREDICTIONS)):
        bad = frame[~frame[col].isin(allowed)]
        if len(bad):
            raise GateError(f"{ledger}: claim {bad.claim_id.iloc[0]} has {col} {bad[col].iloc[0]!r} "
                            f"(allowed: {', '.join(allowed)})")
    not_run = frame[frame.verdict == NOT_RUN]
    checked = frame[(frame.predicted != FINDING) & (frame.verdict != NOT_RUN)]
    if not len(checked):
        raise GateError(f"{ledger}: no claim with a predicted verdict that ran ({len(frame)} findings or "
                        f"{NOT_RUN}): nothing to verify")
    wrong = checked[checked.verdict != checked.predicted]
    if len(wrong):
        raise GateError(f"{len(wrong)} claim(s) differ from the paper's prediction: "
                        + ", ".join(f"{c} ({v}, predicted {p})" for c, v, p in
                                    zip(wrong.claim_id, wrong.verdict, wrong.predicted)))
    findings = int((frame.predicted == FINDING).sum()) - int((not_run.predicted == FINDING).sum())
    summary = f"verify-claims: {len(checked)} claims as predicted, {findings} findings listed"
    if len(not_run):
        summary += (f", {len(not_run)} {NOT_RUN} (a code not installed, its install command in the evidence): "
                    + ", ".join(not_run.claim_id))
    return frame, summary
