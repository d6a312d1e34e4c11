"""infsup-contact: inf-sup stability of Lagrange-multiplier contact discretizations.

Reproduces and extends K.J. Bathe & F. Brezzi, *Stability of finite element mixed
interpolations for contact problems*, Rend. Lincei Mat. Appl. 12 (2001) 167–183.
"""
__version__ = "0.1.0"

from .api import beta, certify, verdict  # noqa: E402  (the notebook API: docs/api.md)
from .errors import InputError  # noqa: E402  (what a bad keyword raises: `except ic.InputError`)

__all__ = ["beta", "verdict", "certify", "InputError", "__version__"]
