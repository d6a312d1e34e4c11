"""Models: each physical model brings its interface operator and its scenes' needs, nothing else.

``contract`` states what a model gives the engine (one factorized side per mesh, Γ last, its
:class:`~.contract.SideOperator` made by :mod:`infsup_contact.la.schur`; a 3D body's mesh with its
Γ, :class:`~.contract.Body`; the loads, lifts and u_h of a contact scene); ``membranes`` is the paper's
model, ``elastic`` plane-strain elasticity (its Section 2), ``membranes3d`` the membranes
in 3D with a 2D contact face, ``elastic3d`` the linear-elastic bodies on that
face, ``plane_strain`` the material law
the elastic scenes measure with. Imports ``discretization``, ``la`` and ``errors`` only.

This file is the registry of models: the engine (``solvers``, ``study``) asks it for a model by
name and never imports a concrete model.
"""
from .contract import Model
from .membranes import MEMBRANES
from .elastic import ELASTIC, elastic_model
from .membranes3d import MEMBRANES3D
from .elastic3d import ELASTIC3D, elastic3d_model

MODELS = {m.name: m for m in (MEMBRANES, ELASTIC, MEMBRANES3D, ELASTIC3D)}
"""Every model by name (``elastic``, ``elastic3d``: ν = 0.3; other ν through :func:`make_model`).
The order matters to :func:`model_taking` and :func:`model_of_dim` (the first match)."""
_BUILDERS = {MEMBRANES.name: lambda: MEMBRANES, ELASTIC.name: elastic_model, MEMBRANES3D.name: lambda: MEMBRANES3D,
             ELASTIC3D.name: elastic3d_model}
DEFAULT_MODEL = MEMBRANES
"""The paper's model: what β_h and contact use when no model is named."""


def make_model(name: str, **params) -> Model:
    """The model ``name`` with its parameters (``elastic``: ``nu``), from the registry."""
    return _BUILDERS[name](**params)


def model_taking(param: str) -> Model:
    """The first registered model whose stiffness K_i itself takes the parameter ``param``
    (``nu``: the plane-strain bodies), for a study of that parameter's effect."""
    for m in MODELS.values():
        if any(p.name == param and p.side is None for p in m.params):
            return m
    raise KeyError(f"no registered model takes the parameter {param!r}")


def model_of_dim(dim: int) -> Model:
    """The first registered model whose bodies have dimension ``dim`` (3: the membranes in 3D),
    for a study of a geometry the command line does not offer (:mod:`infsup_contact.study.face.edge_dropping`)."""
    for m in MODELS.values():
        if m.dim == dim:
            return m
    raise KeyError(f"no registered model of dimension {dim}")
