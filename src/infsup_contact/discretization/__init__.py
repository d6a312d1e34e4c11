"""Discretization: meshes of Ω1, Ω2, multiplier spaces on G_h, the coupling b(v, μ), the norms of μ.

Everything the paper's Sections 4–5 define before any solve: Γ, the interface object every consumer
asks for partitions, trace dofs, quadrature, Gram matrices and spaces (``interface``), mesh pairs (``meshes``), the
spaces M_h and their registry (``multipliers``), B_i (``coupling``), the Gram matrices of
L²(Γ) and H^{-1/2}_00(Γ) (``norms``, ``logkernel``). Imports only ``errors`` and each other.
The 2D face: elements, (transformed) dual bases, grid spaces (``face_elements``, ``face_dual``, ``face_cells``).
"""
