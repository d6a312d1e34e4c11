"""The paper's Γ = (0, 1) × {1} (Bathe & Brezzi 2001, Sections 3–5), readable alone: the membrane
meshes of Fig. 4 (``meshes``), the spaces (5.3)/(5.5) and their dual basis (``multipliers``,
``dual``), the norms L²(Γ) and H^{1/2}_00(Γ)' (``norms``, ``logkernel``) and its
:class:`~.interface.Segment`."""
