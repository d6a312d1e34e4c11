"""Models: each physical model brings its interface operator and nothing else.

``contract`` states what a model gives the engine (one factorized side per mesh, Γ last);
``schur`` is the shared Γ Schur complement / Steklov inverse machinery, ``ordering`` its
Γ-last nested dissection; ``membranes`` is the paper's model, ``elastic`` plane-strain elasticity (its Section 2). Imports ``discretization``
and ``errors`` only.
"""
from .contract import Model
from .membranes import MEMBRANES
from .elastic import ELASTIC, elastic_model

MODELS = {m.name: m for m in (MEMBRANES, ELASTIC)}
"""Every model by name (``elastic``: ν = 0.3; other ν through :func:`elastic_model`)."""
