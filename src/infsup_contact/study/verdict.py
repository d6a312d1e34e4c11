"""Is a multiplier space stable? One verdict from β_h over a series of mesh pairs, N1 = N2 + offset.

β_h is the discrete inf-sup constant of eq. (4.5), computed by
:func:`infsup_contact.solvers.infsup.beta_rows`. The verdict uses the claims ledger's own
criterion (:mod:`infsup_contact.criteria.claims`), so ``infsup-contact verdict`` and
``results/claims.csv`` cannot disagree about the same series:

* a kernel decision closer than the stated margin to its error level on any mesh
  (``kernel_decision == "close"``, :data:`infsup_contact.solvers.kernel.KERNEL_CRITERION`)
  is INCONCLUSIVE: the verdict must not depend on one BLAS kernel's rounding;
* a kernel on any mesh (``kernel_dim > 0``: β_h = 0, as for Rem 5.2 and Rem 5.4; proven by
  the dimension count or decided from Bᵀ) is UNSTABLE;
* otherwise :func:`~infsup_contact.criteria.claims.bounded_claim` ("β_h bounded away from
  zero": min β_h above a floor and the confidence interval of the slope of log β_h vs log h
  inside [−τ, τ]) decides: PASS → STABLE, FAIL → UNSTABLE, INCONCLUSIVE → INCONCLUSIVE.

Pure functions apart from :func:`verdict_rows`, which computes the β_h rows; no file I/O.
"""
from __future__ import annotations

import math

import time

import numpy as np
import pandas as pd

from ..discretization.face.shapes.square import CELL_BODIES
from ..discretization.spaces import registry
from ..discretization.spaces.spec import SpaceSpec
from ..errors import InputError
from .. import progress
from ..models import DEFAULT_MODEL
from ..solvers.infsup import beta_rows
from ..solvers.request import NO_OPTIONS, MeshOptions, check_norm
from ..criteria import claims as criteria
from ..criteria.stability import MIN_MESHES, stability_verdict


def verdict_rows(case_or_spec, k: int, family: str, ns, norm: str, *, tol: float, floor: float,
                 confidence: float, multiplier_mesh: str = "omega2", model=None, n1_offset: int = 0,
                 mesh: MeshOptions = NO_OPTIONS, gamma=None) -> dict:
    """β_h on the mesh pairs N1 = N + ``n1_offset``, N2 = N for each N in ``ns`` (matching
    meshes by default), and its stability verdict.

    Parameters
    ----------
    case_or_spec : str or SpaceSpec
        A registry id (``T3``) or a registered :class:`~infsup_contact.discretization.spaces.spec.SpaceSpec`.
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
    n1_offset : int
        N1 − N2 of every pair (non-matching meshes; :func:`check_n1_offset`); h = 1/N2.
    mesh : MeshOptions
        The mesh parameters (``seed``, ``alpha`` of the perturbed family; the 3D model's
        ``element``); default: the builder's.
    gamma : Interface or None
        The request's Γ (``--gamma``: the arc, the cylinder; resolved by
        :func:`~infsup_contact.solvers.request.resolve_gamma`); None: the model's flat Γ.

    Returns
    -------
    dict
        ``space``, ``k``, ``model``, ``element`` (the 3D models' mesh element, else None),
        ``gamma``, ``radius``, ``coupling`` (a curved Γ's, where set), ``family``, ``norm``, ``multiplier_mesh``, ``N1_offset``, the fields of
        :func:`stability_verdict`, ``N_list`` (the sorted N2) and ``seconds`` (wall time of
        the whole call).

    Raises
    ------
    InputError
        Naming ``N``, ``norm``, ``k``, ``family``, ``multiplier_mesh`` or a criterion key.
    """
    t0 = time.perf_counter()
    case = _case_id(case_or_spec)
    ns = check_mesh_sizes(ns)
    check_n1_offset(ns, n1_offset)
    check_criterion(tol, floor, confidence)
    check_norm(norm)
    model = DEFAULT_MODEL if model is None else model
    level = (lambda n: f"N1={n + n1_offset} N2={n}") if n1_offset else (lambda n: f"N={n}")
    rows = [r for n in progress.steps(ns, "level", level) for r in beta_rows(family, k, n + n1_offset, n, [case], multiplier_mesh,
                                             norms=(norm,), model=model, mesh=mesh, gamma=gamma)]
    curved = model.gamma_columns(gamma)
    out = dict(space=case, k=k, model=model.name, element=mesh.element, **curved, family=family, norm=norm,
               multiplier_mesh=multiplier_mesh, N1_offset=n1_offset,
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


def check_n1_offset(ns, offset) -> int:
    """N1 = N + ``offset`` >= 1 for every N of ``ns``; :class:`InputError` (key ``N1_offset``)
    otherwise."""
    if isinstance(offset, bool) or not isinstance(offset, (int, np.integer)) or min(ns) + offset < 1:
        raise InputError("N1_offset", f"an integer with N + offset >= 1 for every --N (smallest N: {min(ns)})",
                         got=offset)
    return int(offset)


def model_case_ids(model, k: int, family: str = "structured", mesh: MeshOptions = NO_OPTIONS, gamma=None) -> list:
    """The registered ids ``model`` builds for degree k: on a 2D model the segment's spaces
    defined for k; on a 3D model also the face-only ones its element's face cells carry
    (QUAD8/QUAD9 spaces on hexahedra, TRI6 spaces on tetrahedra), those refused by
    construction (DUAL-Q8, DUAL-T6) left out. Found as ``beta --case all`` finds them, on the
    model's coarsest mesh (one cell per direction; a 2D model: no mesh, the segment builds
    every space of its dimension)."""
    if model.dim == 2:
        return registry.ids_valid_for(k, registry.space_ids(model.dim - 1))
    return registry.ids_built_on(k, *_coarsest_multiplier_mesh(model, k, family, mesh, gamma))


def _coarsest_multiplier_mesh(model, k, family, mesh: MeshOptions, gamma=None):
    """(Γ, G_h) of ``model`` on its coarsest matching mesh pair (one cell per direction), without a
    mesh: the request's Γ ``gamma``, else the model's flat one (``Model.gamma``), and its uniform partition."""
    gamma = model.gamma(family, **mesh.kwargs()) if gamma is None else gamma
    partition = gamma.uniform_partition(1)
    return gamma, gamma.multiplier_partition(partition, partition)


def check_model_case(case: str, k: int, model, family: str = "structured", mesh: MeshOptions = NO_OPTIONS,
                     gamma=None) -> None:
    """:class:`InputError` unless ``model`` (with its mesh options, e.g. ``element``) builds the
    registered space ``case`` for degree k (:func:`model_case_ids`): one line naming the key
    (``case`` or ``k``) and the values allowed for this model, element and k. The id and k are
    checked before any mesh is built (a 2D model builds none)."""
    spec = registry.space_spec(case)  # an unknown id: every registered id listed
    if not spec.valid_for(k):
        ks = [j for j in range(registry.K_RANGE[0], registry.K_RANGE[1] + 1) if spec.valid_for(j)]
        raise InputError("k", f"k in {ks[0]}..{ks[-1]} for case {case} ({spec.paper_ref})", got=k)
    where = " ".join([f"--model {model.name}", *(f"--{key} {value}" for key, value in mesh.columns(model, gamma).items()),
                      *([f"--family {family}"] if family != "structured" else [])])
    if not spec.defined_on(model.dim - 1):
        why = (f"defined on the face of a 3D model only: --model {', '.join(_models(3))}" if model.dim == 2
               else "defined on the segment Γ of the 2D models only")
        allowed = model_case_ids(model, k, family, mesh, gamma)
        raise InputError("case", f"a space of {where} with k = {k}: {', '.join(allowed)} ({case} is {why})", got=case)
    if model.dim == 2:
        return
    gamma, g_h = _coarsest_multiplier_mesh(model, k, family, mesh, gamma)
    allowed = registry.ids_built_on(k, gamma, g_h)
    if case in allowed:
        return
    if not gamma.builds(spec):
        bodies = " and ".join(CELL_BODIES.get(c, c) for c in spec.face_cells)
        why = (f"built on the faces of {bodies} only" if gamma.cell is not None
               else "not built on a general triangulation of Γ: only Lagrange cases and their duals are")
    else:
        try:
            gamma.space(spec, k, g_h)
            why = "not built here"
        except InputError as err:  # refused by construction: the construction's reason and remedy
            why = f"refused: {err.allowed}"
    raise InputError("case", f"a space of {where} with k = {k}: {', '.join(allowed)} ({case} is {why})", got=case)


def _models(dim: int) -> list:
    from ..models import MODELS

    return [name for name, m in MODELS.items() if m.dim == dim]


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
    if isinstance(case_or_spec, SpaceSpec):
        if registry.SPACES.get(case_or_spec.id) is not case_or_spec:
            raise ValueError(f"space {case_or_spec.id!r} is not registered (registry.register it first)")
        return case_or_spec.id
    return registry.space_spec(case_or_spec).id
