"""The table of Γ shapes, beside the space registry: what a request's Γ can be.

Each row (:class:`GammaShape`) is a shape's name, the factory of its
:class:`~infsup_contact.discretization.gamma.interface.Interface`, its parameters with their checks
(the users' messages: same keys, same allowed values) and its couplings, each paired with the
function that ties the two sides' traces (None: the traces as built). The table pairs a shape with
its projection, so no shape's module imports its projection's (whose class is its subclass).

:func:`gamma_of` resolves a Γ from its name and parameters, building no mesh: the request resolves
its Γ once, at the edge, and carries it (:class:`~infsup_contact.solvers.request.BetaRequest`).
A new shape is its ``Interface`` module, one row of :data:`GAMMA_SHAPES` (:func:`add_shape`) and
the model builder that meshes it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from ...errors import InputError
from ..face.shapes import cylinder as cylinder_module
from ..face.shapes.cylinder_projection import project_pair as project_cylinder
from ..face.shapes.serendipity import SERENDIPITY
from ..face.shapes.square import SQUARE, SQUARE_TRIG, Square
from ..face.shapes.triangulated_square import TRIANGULATED
from ..segment import arc as arc_module
from ..segment.interface import SEGMENT
from ..segment.projection import project_pair as project_arc


@dataclass(frozen=True)
class GammaShape:
    """One row of the Γ table.

    Attributes
    ----------
    name : str
        The shape's name (``segment``, ``arc``, ``square``, ...).
    build : callable
        ``build(**params) -> Interface``: the shape with its parameters, checked before.
    params : tuple of str
        The names of its parameters (``radius``, ``coupling``; a face's ``cell``).
    check : callable or None
        ``check(**params)``: :class:`~infsup_contact.errors.InputError` naming the offending key
        and its allowed values; None: no parameter to check.
    couplings : dict
        Coupling name → ``pairing(gamma, sides) -> sides`` (None: the sides' traces as built).
    """

    name: str
    build: Callable
    params: tuple = ()
    check: Callable | None = None
    couplings: dict = field(default_factory=lambda: {"exact": None})

    def __call__(self, **params):
        """The checked :class:`Interface` of these parameters."""
        if self.check is not None:
            self.check(**params)
        return self.build(**params)


def _arc(radius, coupling=None):
    coupling = coupling or "exact"
    return arc_module.Arc(radius=float(radius), coupling=coupling, pairing=GAMMA_SHAPES["arc"].couplings[coupling])


def _check_arc(radius=None, coupling=None):
    arc_module.check_arc_options("arc", radius, coupling)


def _cylinder(radius, coupling=None, face: Square = SQUARE):
    coupling = cylinder_module.DEFAULT_COUPLING if coupling is None else coupling
    return cylinder_module.Cylinder(face.boundary, face.z, face.cell, face.width, float(radius), coupling,
                                    pairing=GAMMA_SHAPES["cylinder"].couplings[coupling])


def _check_cylinder(radius=None, coupling=None, face: Square = SQUARE):
    """The cylinder's options; projection is on tensor-product surfaces only: refused on
    tetrahedra, whose triangles' master images are curved in the slave's parameters."""
    cylinder_module.check_cylinder_options("cylinder", radius, coupling)
    if coupling == "projection" and face.cell != "quad":
        raise InputError("coupling", "exact on tetrahedra (projection: element hex)", got=coupling)


GAMMA_SHAPES = {row.name: row for row in (
    GammaShape("segment", lambda: SEGMENT),
    GammaShape("arc", _arc, ("radius", "coupling"), _check_arc, {"exact": None, "projection": project_arc}),
    GammaShape("square", lambda cell="quad": SQUARE if cell == "quad" else SQUARE_TRIG, ("cell",)),
    GammaShape("triangulated", lambda: TRIANGULATED),
    GammaShape("serendipity", lambda: SERENDIPITY),
    GammaShape("cylinder", _cylinder, ("radius", "coupling", "face"), _check_cylinder,
               {"exact": None, "projection": project_cylinder}),
)}
"""Every Γ shape by name (module docstring)."""


def add_shape(row: GammaShape) -> GammaShape:
    """Register a new Γ shape (a row of :data:`GAMMA_SHAPES`); its name must be new."""
    if row.name in GAMMA_SHAPES:
        raise ValueError(f"a Γ shape named {row.name!r} is registered already")
    GAMMA_SHAPES[row.name] = row
    return row


def gamma_of(name: str, **params):
    """The checked Γ named ``name`` with its parameters (:data:`GAMMA_SHAPES`); no mesh is built."""
    if name not in GAMMA_SHAPES:
        raise InputError("gamma", ", ".join(GAMMA_SHAPES), got=name)
    return GAMMA_SHAPES[name](**params)


def curved_of(flat, gammas: tuple, gamma=None, radius=None, coupling=None, face=None):
    """The Γ of a model's curving options (``--gamma``, ``--radius``, ``--coupling``) on its flat
    Γ ``flat``: ``gammas`` = (flat name, curved name), e.g. (``segment``, ``arc``); the options
    checked with the curved shape's messages (a radius or coupling without the curved name is
    refused naming its key); the flat Γ when the curved one is not asked for."""
    flat_name, curved = gammas
    row = GAMMA_SHAPES[curved]
    check = arc_module.check_arc_options if curved == "arc" else cylinder_module.check_cylinder_options
    check(gamma, radius, coupling)
    if gamma != curved:
        return flat
    params = dict(radius=radius, coupling=coupling, **({} if face is None else {"face": face}))
    return row(**params)


def arc_of(gamma=None, radius=None, coupling=None):
    """The 2D membranes' curving options: None for the paper's segment (no option given, or
    ``segment``), else the checked arc (:func:`curved_of`)."""
    return curved_of(None, ("segment", "arc"), gamma, radius, coupling)


def cylinder_of(face: Square, gamma=None, radius=None, coupling=None):
    """The 3D membranes' curving options on a body whose flat face is ``face``: None for the flat
    face (no option given, or ``square``), else the checked cylinder of its cells."""
    return curved_of(None, ("square", "cylinder"), gamma, radius, coupling, face=face)
