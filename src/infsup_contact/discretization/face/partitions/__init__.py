"""Partitions of the face Γ = (0, 1)²: tensor grids, general triangulations, and exact quadrature on their triangles."""
