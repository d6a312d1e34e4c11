"""Discretization: Γ, the multiplier spaces M_h on G_h, the coupling b(v, μ), the norms of μ.

Everything the paper's Sections 4–5 define before any solve, Γ first:

``gamma``    what every Γ shares: the ``Interface``, the ``MultiplierSpace`` protocol, traces,
             coupling, quadrature, symmetries, "is 1 ∈ M_h?".
``segment``  the paper's segment Γ = (0, 1): meshes, spaces, norms.
``face``     the 3D contact face Γ = (0, 1)²: partitions, spaces, norms, its interfaces and meshes.
``spaces``   the registry of spaces (as data) and users' spaces.
"""
