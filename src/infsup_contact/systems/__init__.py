"""Foreign saddle-point systems: matrices exported by another code, a verdict out.

``manifest`` reads the YAML list of mesh levels, ``readers`` the matrix files
(MatrixMarket, scipy ``.npz``/``.npy``, Harwell-Boeing, PETSc binary), ``checks`` finds what
real exports look like (Dirichlet penalties, identity rows, asymmetry, NaN, …) and says so in
one line, ``engine`` computes β_h² = min eig(B A⁻¹ Bᵀ, G) per level, ``levels`` turns a manifest
into rows and a verdict, ``export`` writes this suite's own systems in the same layout;
``multiplier_basis`` / ``multiplier_gram`` turn a ``norm: H`` manifest's description of the
multipliers on Γ into their exact H^{-1/2}_00 Gram, ``mortar_distance`` measures B against the
exact coupling of described traces. Imports ``errors``, ``io``, ``models`` and ``solvers``.
"""
from .readers import SystemFileError

__all__ = ["SystemFileError"]
