"""The contact problem (4.1) on Γ, solved with the Lagrange multipliers whose β_h ``solvers`` measures.

``pdas`` (the primal–dual active set on g = g0 + K λ), ``lcp`` (the linear complementarity
problem's checks and minimum-norm representatives), ``kkt`` (the same on the full sparse KKT
system: the check route), ``contact`` (a scene solved on a mesh pair, u_h recovered),
``reduced_qp`` (the same from an assembled QP).
Imports ``solvers`` (the interface operator, the mesh options), ``models``, ``discretization``,
``la`` and ``errors`` only.
"""
