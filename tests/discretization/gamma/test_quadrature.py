"""The shared Gauss–Legendre rules: exactness and protection of the cached arrays."""
import numpy as np
import pytest

from infsup_contact.discretization.gamma.quadrature import gauss_legendre, gauss_legendre_01


@pytest.mark.parametrize("n", [1, 2, 5, 9])
def test_exact_up_to_degree_2n_minus_1(n):
    t, w = gauss_legendre(n)
    u, lam = gauss_legendre_01(n)
    for p in range(2 * n):
        assert abs(w @ t**p - (1 + (-1) ** p) / (p + 1)) < 1e-14
        assert abs(lam @ u**p - 1 / (p + 1)) < 1e-14
    # and not beyond: the error for x^(2n) is (n!)^4 / ((2n + 1) ((2n)!)^2) > 0
    from math import factorial
    err = factorial(n) ** 4 / ((2 * n + 1) * factorial(2 * n) ** 2)
    assert abs((1 / (2 * n + 1) - lam @ u ** (2 * n)) - err) < 1e-12 + 1e-6 * err


def test_cached_rules_cannot_be_changed():
    t, w = gauss_legendre_01(4)
    with pytest.raises(ValueError):
        t[0] = 0.0
    assert gauss_legendre_01(4)[0] is t
