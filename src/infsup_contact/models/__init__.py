"""Models: each physical model brings its interface operator and nothing else.

``contract`` states what a model gives the engine (one factorized side per mesh, Γ last);
``schur`` is the shared Γ Schur complement / Steklov inverse machinery, ``ordering`` its
Γ-last nested dissection; ``membranes`` is the paper's model. Imports ``discretization``
and ``errors`` only.
"""
from .contract import Model
from .membranes import MEMBRANES

MODELS = {m.name: m for m in (MEMBRANES,)}
"""Every model by name; a new model (e.g. plane-strain elasticity) adds itself here."""
