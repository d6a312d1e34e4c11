"""Solvers on the Γ-reduced problem: β_h and the bottom of its spectrum (contact (4.1) is in ``contact``).

``request`` (a β_h request, validated once), ``infsup`` (β_h of (4.5) for a request),
``routes`` (how one space's pencil is solved: dense, bottom, split; the kernel of Bᵀ),
``spectra`` (the pencils on each route), ``symmetry`` (Γ's reflections for the engine),
``kernel`` (the kernel decisions), ``interface_operator`` (Σ_i B_i X_i B_iᵀ / c_i),
``side_cache`` (side operators shared by a sweep).
Imports ``models``, ``discretization``, ``la`` and ``errors`` only.
"""
