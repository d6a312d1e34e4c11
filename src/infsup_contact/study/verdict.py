"""Is a multiplier space stable? One verdict from β_h over a sequence of matching meshes.

β_h is the discrete inf-sup constant of eq. (4.5), computed by
:func:`infsup_contact.solvers.infsup.beta_rows`. The verdict uses the claims ledger's own
criterion (:mod:`infsup_contact.study.claims`), so ``infsup-contact verdict`` and
``results/claims.csv`` cannot disagree about the same series:

* a kernel decision closer than the stated margin to its error level on any mesh
  (``kernel_decision == "close"``, :data:`infsup_contact.solvers.kernel.KERNEL_CRITERION`)
  is INCONCLUSIVE: the verdict must not depend on one BLAS kernel's rounding;
* a kernel on any mesh (``kernel_dim > 0``: β_h = 0, as for Rem 5.2 and Rem 5.4; proven by
  the dimension count or decided from Bᵀ) is UNSTABLE;
* otherwise :func:`~infsup_contact.study.claims.bounded_claim` ("β_h bounded away from
  zero": min β_h above a floor and the confidence interval of the slope of log β_h vs log h
  inside [−τ, τ]) decides: PASS → STABLE, FAIL → UNSTABLE, INCONCLUSIVE → INCONCLUSIVE.

Pure functions apart from :func:`verdict_rows`, which computes the β_h rows; no file I/O.
"""
from __future__ import annotations

import math

import time

import numpy as np
import pandas as pd

from ..discretization import registry
from ..discretization.norms import NORMS
from ..errors import InputError
from ..solvers.infsup import beta_rows
from . import claims

STABLE, UNSTABLE, INCONCLUSIVE = "STABLE", "UNSTABLE", "INCONCLUSIVE"
FROM_LEDGER = {claims.PASS: STABLE, claims.FAIL: UNSTABLE, claims.INCONCLUSIVE: INCONCLUSIVE}
"""The ledger's verdict on "β_h bounded away from 0" as a stability verdict."""
MIN_MESHES = 3
"""Fewest meshes of a series: a slope's confidence interval needs n − 2 >= 1 dof."""
_ONE_VALUE = ("case", "k", "family", "norm", "multiplier_mesh", "c1", "c2")


def stability_verdict(rows, tol: float, floor: float, confidence: float) -> dict:
    """STABLE, UNSTABLE or INCONCLUSIVE for one space and one norm over a mesh sequence.

    Parameters
    ----------
    rows : list of dict or pandas.DataFrame
        Rows of :func:`~infsup_contact.solvers.infsup.beta_rows` (columns ``N2``, ``beta``,
        ``kernel_dim``, ``smallest_nonzero``), one per mesh, all of one case, degree, family,
        norm and multiplier mesh; h = 1/N2.
    tol : float
        Slope tolerance τ (config ``claims.slope_tolerance``).
    floor : float
        β floor (config ``claims.beta_floor``): min β_h <= floor is UNSTABLE.
    confidence : float
        Confidence level of the slope interval (config ``claims.confidence``).

    Returns
    -------
    dict
        ``verdict``; ``kernel_dim`` (the largest numerical kernel dimension over the meshes);
        ``beta_min``, ``beta_max`` (β_h of eq. (4.5) over the meshes); ``slope``,
        ``slope_lo``, ``slope_hi`` (least-squares slope and its interval,
        :func:`~infsup_contact.study.claims.slope_interval`) of log β_h vs log h, or, where
        there is a kernel, of log(smallest_nonzero) (β above the kernel) vs log h; NaN when
        fewer than two positive values; ``evidence`` (one line of text).

    Raises
    ------
    ValueError
        If the rows mix cases, degrees, families, norms or multiplier meshes, or repeat a mesh.
    """
    frame = _series(rows)
    h = 1.0 / frame.N2.to_numpy(float)
    beta = frame.beta.to_numpy(float)
    kernel_dim = int(frame.kernel_dim.max())
    close = claims.close_decisions(frame)
    if len(close):
        verdict, fitted = INCONCLUSIVE, frame.smallest_nonzero.to_numpy(float) if kernel_dim > 0 else beta
        evidence = claims.close_text(close)
    elif kernel_dim > 0:
        verdict, fitted = UNSTABLE, frame.smallest_nonzero.to_numpy(float)
        evidence = (f"β_h = 0: kernel dims {frame.kernel_dim.astype(int).tolist()} over N = "
                    f"{claims._ns(frame)}; fit of the eigenvalue above the kernel")
    else:
        ledger_verdict, evidence = claims.bounded_claim(frame, tol, floor, confidence)
        verdict, fitted = FROM_LEDGER[ledger_verdict], beta
    slope, lo, hi = _fit(h, fitted, confidence)
    return dict(verdict=verdict, kernel_dim=kernel_dim, beta_min=float(beta.min()),
                beta_max=float(beta.max()), slope=slope, slope_lo=lo, slope_hi=hi,
                evidence=evidence)


def verdict_rows(case_or_spec, k: int, family: str, ns, norm: str, *, tol: float, floor: float,
                 confidence: float, multiplier_mesh: str = "omega2", model=None, **mesh_kwargs) -> dict:
    """β_h on matching meshes N1 = N2 = N for each N in ``ns``, and its stability verdict.

    Parameters
    ----------
    case_or_spec : str or SpaceSpec
        A registry id (``T3``) or a registered :class:`~infsup_contact.discretization.registry.SpaceSpec`.
    k : int
        Displacement degree (1..4, at least the space's ``min_k``).
    family : str
        Mesh family (``structured``, ``perturbed``, ``unstructured``).
    ns : sequence of int
        Segments on Γ, at least :data:`MIN_MESHES` distinct values >= 1.
    norm : str
        Multiplier norm, ``H`` (H^{-1/2}_00(Γ), eq. (4.5)) or ``L2`` (Remark 3.1: there even
        the stable spaces decay like h^{1/2}, so they come out UNSTABLE).
    tol, floor, confidence : float
        The criterion of :func:`stability_verdict`.
    multiplier_mesh : str
        Partition G_h of the multipliers: ``omega2`` (the paper's), ``omega1``, ``union``.
    model : Model, optional
        The physical model (:mod:`infsup_contact.models`); default the paper's membranes.
    **mesh_kwargs
        Passed to the mesh generator (``seed``, ``alpha`` of the perturbed family; the 3D
        model's ``element``).

    Returns
    -------
    dict
        ``space``, ``k``, ``family``, ``norm``, ``multiplier_mesh``, the fields of
        :func:`stability_verdict`, ``N_list`` (the sorted N) and ``seconds`` (wall time of
        the whole call).

    Raises
    ------
    InputError
        Naming ``N``, ``norm``, ``k``, ``family``, ``multiplier_mesh`` or a criterion key.
    """
    t0 = time.perf_counter()
    case = _case_id(case_or_spec)
    ns = check_mesh_sizes(ns)
    check_criterion(tol, floor, confidence)
    if norm not in NORMS:
        raise InputError("norm", ", ".join(NORMS), got=norm)
    if model is not None:
        mesh_kwargs["model"] = model
    rows = [r for n in ns for r in beta_rows(family, k, n, n, [case], multiplier_mesh,
                                             norms=(norm,), **mesh_kwargs)]
    out = dict(space=case, k=k, family=family, norm=norm, multiplier_mesh=multiplier_mesh,
               **stability_verdict(rows, tol, floor, confidence), N_list=ns)
    out["seconds"] = time.perf_counter() - t0
    return out


def check_mesh_sizes(ns) -> list:
    """The sorted mesh sizes; :class:`InputError` (key ``N``) unless there are at least
    :data:`MIN_MESHES` distinct integers >= 1."""
    ns = list(ns)
    for n in ns:
        if not isinstance(n, (int, np.integer)) or n < 1:
            raise InputError("N", "integers >= 1", got=n)
    repeated = sorted({n for n in ns if ns.count(n) > 1})
    if repeated:
        raise InputError("N", "distinct mesh sizes (each N once)", got=" ".join(map(str, ns)))
    if len(set(ns)) < MIN_MESHES:
        raise InputError("N", f"at least {MIN_MESHES} distinct mesh sizes (a slope interval needs them)",
                         got=" ".join(map(str, ns)))
    return sorted(set(int(n) for n in ns))


MAX_SLOPE_TOLERANCE = 0.25
"""τ < 1/4 (config claims.slope_tolerance too): a slope band 0 ± τ must not reach 1/2 − τ."""


def check_criterion(tol: float, floor: float, confidence: float) -> None:
    """:class:`InputError` unless τ > 0, floor >= 0 and 0 < confidence < 1 (config keys)."""
    if not 0 < tol < MAX_SLOPE_TOLERANCE:  # NaN fails too
        raise InputError("slope_tolerance", f"a number in (0, {MAX_SLOPE_TOLERANCE}): the bands 0 ± τ (bounded) "
                         "and 1/2 ± τ (the L² decay of Remark 3.1) must not overlap", got=tol)
    if not 0 <= floor < math.inf:
        raise InputError("beta_floor", "a finite number >= 0 (inf would fail every series)", got=floor)
    if not 0 < confidence < 1:
        raise InputError("confidence", "a number in (0, 1)", got=confidence)


def _case_id(case_or_spec) -> str:
    if isinstance(case_or_spec, registry.SpaceSpec):
        if registry.SPACES.get(case_or_spec.id) is not case_or_spec:
            raise ValueError(f"space {case_or_spec.id!r} is not registered (registry.register it first)")
        return case_or_spec.id
    return registry.space_spec(case_or_spec).id


def _series(rows) -> pd.DataFrame:
    frame = pd.DataFrame(rows)
    missing = {"N2", "beta", "kernel_dim", "smallest_nonzero"} - set(frame.columns)
    if len(frame) == 0 or missing:
        raise ValueError(f"need beta_rows rows with columns N2, beta, kernel_dim, smallest_nonzero "
                         f"(missing {sorted(missing)}, {len(frame)} rows)")
    for col in _ONE_VALUE:
        if col in frame.columns and frame[col].nunique() > 1:
            raise ValueError(f"rows of one series expected; column {col!r} has {sorted(set(frame[col]))}")
    if frame.N2.duplicated().any():
        raise ValueError(f"one row per mesh expected; N2 = {frame.N2.tolist()}")
    return frame.sort_values("N2")


def _fit(h, y, confidence):
    ok = np.isfinite(y) & (y > 0)
    if ok.sum() < 2:
        return np.nan, np.nan, np.nan
    return tuple(float(v) for v in claims.slope_interval(h[ok], y[ok], confidence))
