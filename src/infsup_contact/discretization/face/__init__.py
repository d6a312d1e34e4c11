"""The 3D contact face Γ = (0, 1)² × {1}: its ``Interface`` implementations
(tensor grids, ``square``; general triangulations, ``triangulated_square`` over ``triangulation``),
exact quadrature on its partitions, the multiplier spaces on it (``spaces``), their Gram matrices
(``norms``), kernel lower bounds and symmetries, and the unstructured 3D meshes (``meshes``)."""
