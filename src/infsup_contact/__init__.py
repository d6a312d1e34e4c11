"""infsup-contact: inf-sup stability of Lagrange-multiplier contact discretizations.

Reproduces and extends K.J. Bathe & F. Brezzi, *Stability of finite element mixed
interpolations for contact problems*, Rend. Lincei Mat. Appl. 12 (2001) 167–183.
"""
__version__ = "0.1.0"
