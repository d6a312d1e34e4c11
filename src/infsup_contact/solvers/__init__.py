"""Solvers on the Γ-reduced problem: β_h and the bottom of its spectrum, the contact problem (4.1).

``request`` (a β_h request, validated once), ``infsup`` (β_h of (4.5) for a request),
``routes`` (how one space's pencil is solved: dense, bottom, split; the kernel of Bᵀ),
``spectra`` (the pencils on each route), ``symmetry`` (Γ's reflections for the engine),
``kernel`` (the kernel decisions), ``interface_operator`` (Σ_i B_i X_i B_iᵀ / c_i),
``side_cache`` (side operators shared by a sweep), ``pdas`` (the primal–dual active set on
g = g0 + K λ), ``kkt`` (the same on the full sparse KKT system: the check route), ``contact``
(a scene solved on a mesh pair, u_h recovered), ``reduced_qp`` (the same from an assembled QP).
Imports ``models``, ``discretization``, ``la`` and ``errors`` only.
"""
