"""A β_h request, validated once at the edge into a typed, frozen object the engine trusts.

The command line (:mod:`infsup_contact.cli.beta`) and the Python callers
(:func:`~.infsup.beta_rows`, :func:`~.infsup.beta_rows_all`) build a :class:`BetaRequest`;
building it checks every key (one :class:`~infsup_contact.errors.InputError` naming the first
offending one) and :func:`~.infsup.beta_table` runs it without checking again. The mesh
parameters travel as a :class:`MeshOptions`, not as keywords; Γ travels as the request's own
field (``gamma``, resolved once at the edge by :func:`resolve_gamma`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..discretization.segment import meshes

from ..discretization.spaces import registry
from ..discretization.gamma.interface import check_choice
from ..discretization.segment.norms import NORMS
from ..errors import InputError, check_prestress
from ..models import DEFAULT_MODEL
from ..models.contract import Model
from .petrov_galerkin import check_pair_size


@dataclass(frozen=True)
class MeshOptions:
    """The mesh parameters of a request beyond (family, N): the model's mesh builder's own.

    Γ is not one of them: a request carries its Γ itself (:attr:`BetaRequest.gamma`, resolved by
    :func:`resolve_gamma`) and the builder receives it as its own argument (``Model.subdomain_mesh``).

    Attributes
    ----------
    element : str or None
        The 3D models' cells (``hex`` or ``tet``; the model's ``mesh_options``); None: the builder's default.
    seed, alpha : int, float or None
        The perturbed family's seed and amplitude α / h; None: the builder's default.
    width : float or None
        A 3D body's extent in x (a narrower Ω2, :mod:`infsup_contact.study.face.edge_dropping`).
    """

    element: str | None = None
    seed: int | None = None
    alpha: float | None = None
    width: float | None = None

    def kwargs(self) -> dict:
        """The builder's keywords: the options that are set."""
        return {key: getattr(self, key) for key in self.__dataclass_fields__ if getattr(self, key) is not None}

    def columns(self, model, gamma=None) -> dict:
        """The table's columns of the options that are set (after ``family``): the builder's, then
        those of the request's Γ ``gamma`` (``Model.gamma_columns``: gamma, radius, coupling)."""
        return {**self.kwargs(), **model.gamma_columns(gamma)}


CURVING = ("gamma", "radius", "coupling")
"""The command line's Γ keys (``--gamma``, ``--radius``, ``--coupling``): the request's Γ, not mesh options."""


def resolve_gamma(model, family: str = "structured", **options):
    """The request's Γ named by ``options``' Γ keys (:data:`CURVING`), resolved and checked by
    ``Model.gamma`` (the Γ table's checks, no mesh) with the mesh options beside them (a 3D
    model's element chooses the face); None where no Γ key is set: the model's flat Γ."""
    if all(options.get(key) is None for key in CURVING):
        return None
    return model.gamma(family, **{key: value for key, value in options.items() if value is not None})


def options_of(model, family: str = "structured", **options) -> tuple:
    """(:class:`MeshOptions`, Γ) of ``model``'s options as the command line names them: the mesh
    builder's own, and the request's Γ (:func:`resolve_gamma`; None: the model's flat Γ)."""
    mesh = MeshOptions(**{key: value for key, value in options.items() if key not in CURVING})
    return mesh, resolve_gamma(model, family, **options)


NO_OPTIONS = MeshOptions()
"""No mesh option set: the builder's defaults."""


@dataclass(frozen=True)
class BetaRequest:
    """β_h of (4.5) for the cases × multiplier meshes × (c1, c2) × norms of one mesh pair.

    Building it validates it (:meth:`__post_init__`); ``cases`` None means every registered
    space defined for k. A case is a registry id, an unregistered
    :class:`~infsup_contact.discretization.spaces.registry.SpaceSpec` or a general triple
    ``(label, s, continuous, vanish)`` (those two are the caller's, not checked here). The
    registered ids are resolved once, here, to their entries checked on the request's Γ
    (:attr:`interface`, resolved without a mesh): the built request's ``cases`` hold those
    :class:`SpaceSpec` s (their ``id`` the rows' name), and the engine never looks an id up again.
    ``gamma`` is the request's Γ where it names one (``--gamma``: the arc, the cylinder; an
    Interface resolved once, at the edge, by :func:`resolve_gamma`), None for the model's flat Γ;
    ``mesh`` holds the mesh builder's own parameters only.
    """

    family: str
    k: int
    n1: int
    n2: int
    cases: tuple | None = None
    multiplier_meshes: tuple = ("omega2",)
    c_pairs: tuple = ((1.0, 1.0),)
    norms: tuple = NORMS
    h_route: str = "logkernel"
    model: Model = DEFAULT_MODEL
    mesh: MeshOptions = NO_OPTIONS
    gamma: object = None

    def __post_init__(self):
        check_k(self.k)
        cases = registry.common_ids(self.k) if self.cases is None else list(self.cases)
        if not isinstance(self.mesh, MeshOptions):  # a caller's slip, not input: say what it should be
            raise TypeError(f"BetaRequest.mesh must be a MeshOptions, not {type(self.mesh).__name__}")
        if isinstance(self.gamma, str):  # a caller's slip: Γ is resolved at the edge (resolve_gamma)
            raise TypeError("BetaRequest.gamma must be a resolved Interface (resolve_gamma) or None, not a str")
        declared = dict(getattr(self.model, "mesh_options", ()))
        for name, value in self.mesh.kwargs().items():
            if name in declared:  # the builder's options (seed, α: the family's)
                check_mesh_option(self.model, name, value)
        ids = {i: c for i, c in enumerate(cases) if isinstance(c, str)}
        gamma = self.interface if ids else None
        entries = {i: registry.check_on_gamma(c, self.k, gamma) for i, c in ids.items()}
        object.__setattr__(self, "cases", tuple(entries.get(i, c) for i, c in enumerate(cases)))  # resolved once
        entries = list(entries.values())  # the registered ones, checked here (the caller's own are not)
        meshes.check_mesh_args(self.family, self.n1, "N1")
        meshes.check_mesh_args(self.family, self.n2, "N2")
        for c1, c2 in self.c_pairs:
            for key, c in (("c1", c1), ("c2", c2)):
                check_prestress(key, c)
        for nm in self.norms:
            check_norm(nm)
        for mm in self.multiplier_meshes:
            check_choice(mm)
            registry.check_pair_spaces(entries, self.k, self.n1, self.n2, (mm,))  # dim M_h = 0: refused here
            check_pair_size(entries, self.k, self.n1, self.n2, mm)  # a Petrov–Galerkin pair is solved densely
        if self.family == "perturbed":  # the mesh builder trusts the request (SideCache.pair, checked)
            meshes.check_perturbation(self.mesh.alpha, self.mesh.seed)  # None: the builder's default

    @property
    def interface(self):
        """The request's Γ resolved: its own (:attr:`gamma`), else the model's flat one for its
        family and mesh options (``Model.gamma``: no mesh is built)."""
        return self.gamma if self.gamma is not None else self.model.gamma(self.family, **self.mesh.kwargs())


def check_mesh_option(model, name: str, value) -> None:
    """:class:`InputError` (key ``name``) unless ``value`` is one of ``model``'s values of its mesh
    option ``name`` (``Model.mesh_options``, e.g. ``element``: ``hex``, ``tet``)."""
    allowed = dict(model.mesh_options).get(name, ())
    if value not in allowed:
        raise InputError(name, allowed_text(allowed), got=value)


def allowed_text(allowed) -> str:
    """The allowed values of a mesh option in words: its choices, or a :class:`~infsup_contact.models.contract.Range`'s text."""
    return allowed if isinstance(allowed, str) else ", ".join(allowed) if isinstance(allowed, tuple) else str(allowed)


def check_norm(norm) -> None:
    """:class:`InputError` unless ``norm`` is a multiplier norm of :data:`NORMS` (H, L2)."""
    if norm not in NORMS:
        raise InputError("norm", ", ".join(NORMS), got=norm)


def check_k(k) -> None:
    """:class:`InputError` unless k is an integer in 1..4."""
    if not isinstance(k, (int, np.integer)) or not 1 <= k <= 4:
        raise InputError("k", "an integer in 1..4", got=k)
