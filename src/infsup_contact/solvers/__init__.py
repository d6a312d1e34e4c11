"""Solvers on the Γ-reduced problem: β_h and the bottom of its spectrum, the contact problem (4.1).

``infsup`` (β_h of (4.5), kernel dimensions), ``pdas`` (the primal–dual active set on
g = g0 + K λ), ``kkt`` (the same on the full sparse KKT system: the check route), ``contact``
(a scene solved on a mesh pair, u_h recovered), ``reduced_qp`` (the same from an assembled QP).
Imports ``models``, ``discretization`` and ``errors`` only.
"""
