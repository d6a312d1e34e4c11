"""Gram matrices of the face's spaces for L²(Γ) and H^{1/2}_00(Γ)': tensor spaces (``tensor``),
cellwise spaces (``cellwise``), Kuhn-triangle spaces (``triangles``), general triangulations
(``unstructured``)."""
