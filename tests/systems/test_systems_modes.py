"""The worst mode of a foreign system's level (``level_spectrum(..., vectors=True)``, the mode of
``beta --system --worst-mode``): on every route the eigenvector of β_h² (its Rayleigh quotient), the
same vector on all three, and a vector of the kernel of Bᵀ where the kernel is larger than declared."""
import numpy as np
import pytest
import scipy.sparse as sp

from infsup_contact.systems.engine import level_spectrum
from tests.systems.test_systems_deflation import synthetic_system

EPS = np.finfo(float).eps
ROUTES = ("gamma-dense", "solves-dense", "shift-invert")


def schur(A, B):
    return (B @ sp.linalg.splu(sp.csc_matrix(A)).solve(B.T.toarray())).astype(float)


def test_mode_is_the_eigenvector_of_beta_squared_on_every_route():
    A, B, G = synthetic_system(nx=8, m0=12, d=0)
    S, Gd = schur(A, B), G.toarray()
    modes = []
    for route in ROUTES:
        res = level_spectrum(A, B, G, route=route, vectors=True)
        m = res.mode
        assert res.kernel.dim == 0 and np.linalg.norm(m) == pytest.approx(1.0)
        rq = m @ S @ m / (m @ Gd @ m)
        # Lanczos to tol 1e-12 and the dense pencil: the Rayleigh quotient to 1e-10 relative
        assert abs(rq - res.beta ** 2) <= 1e-10 * res.beta ** 2, (route, rq, res.beta ** 2)
        modes.append(m * np.sign(m[np.argmax(np.abs(m))]))
    for m in modes[1:]:
        assert np.max(np.abs(m - modes[0])) < 1e-6  # a simple eigenvalue: one direction


@pytest.mark.parametrize("route", ROUTES)
def test_undeclared_kernel_mode_is_in_the_kernel_of_bt(route):
    A, B, G = synthetic_system(nx=8, m0=12, d=3)
    res = level_spectrum(A, B, G, route=route, vectors=True)
    assert res.beta == 0.0 and res.kernel.detected == 3
    residual = np.linalg.norm(B.T @ res.mode) / sp.linalg.norm(B)
    assert residual <= 100 * sum(B.shape) * EPS, residual


def test_no_vector_unless_asked():
    A, B, G = synthetic_system(nx=8, m0=12, d=0)
    assert level_spectrum(A, B, G).mode is None
