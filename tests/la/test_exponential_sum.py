"""The exponential sum of 1/√x and the face Gram it makes separable (large route of face_norms)."""
import numpy as np
import pytest
import scipy.linalg as sla

from infsup_contact.discretization.face.norms import tensor as face_norms
from infsup_contact.discretization.spaces import registry
from infsup_contact.la import exponential_sum
from infsup_contact.la.exponential_sum import inverse_sqrt
from infsup_contact.discretization.face.shapes.square import SQUARE
from infsup_contact.discretization.face.partitions.tensor_grid import TensorPartition
from infsup_contact.errors import InputError


@pytest.mark.parametrize("x_max", [2.0, 1e4, 2 * 1536.0 ** 2, 2 * 6144.0 ** 2])
@pytest.mark.parametrize("rtol", [1e-13, 1e-10, 1e-6])
def test_relative_error_at_the_lattice_points(x_max, rtol):
    """At every x = m² + n² of the face series the sum is 1/√x to rtol (exact values, not the
    sample the module measures on), every weight and rate positive."""
    e = inverse_sqrt(2.0, x_max, rtol)
    m = np.arange(1, int(np.sqrt(x_max / 2)) + 1, max(1, int(np.sqrt(x_max / 2)) // 300))
    x = (m[:, None] ** 2 + m[None, :] ** 2).ravel().astype(float)
    assert np.max(np.abs(e(x) * np.sqrt(x) - 1.0)) <= rtol
    assert e.rel_error <= rtol
    assert np.all(e.weights > 0) and np.all(e.rates > 0)


def test_trapezoidal_rule_converges_like_exp_of_minus_pi_squared_over_h(monkeypatch):
    """Analytic in the strip |Im s| < π/2: error ~ e^{−π²/h} (log error linear in 1/h, slope −π²)."""
    steps, errs = [0.9, 0.75, 0.6, 0.5], []
    for h in steps:
        monkeypatch.setattr(exponential_sum, "STEP", h)
        errs.append(inverse_sqrt(2.0, 1e6, 1e-15).rel_error)
    slope = np.polyfit(1.0 / np.array(steps), np.log(errs), 1)[0]
    assert abs(slope + np.pi ** 2) < 0.1 * np.pi ** 2


@pytest.mark.parametrize("bad", [dict(x_min=0.0, x_max=1.0), dict(x_min=3.0, x_max=2.0),
                                 dict(x_min=1.0, x_max=np.inf), dict(x_min=1.0, x_max=2.0, rtol=0.0),
                                 dict(x_min=1.0, x_max=2.0, rtol=1.5)])
def test_bad_input_is_refused(bad):
    with pytest.raises(InputError):
        inverse_sqrt(**bad)


def _space(case, k, nx, ny):
    return registry.case_space(case, k, TensorPartition(np.linspace(0, 1, nx + 1), np.linspace(0, 1, ny + 1)),
                               SQUARE)


@pytest.mark.parametrize("case,k,nx,ny,aspect", [("R5.2", 2, 4, 5, 1.0), ("T3", 2, 6, 6, 1.0),
                                                ("R5.4", 1, 5, 6, 1.0), ("DUAL-ALL", 1, 7, 5, 1.7),
                                                ("T4", 2, 6, 7, 0.6)])
def test_separable_gram_equals_the_direct_sum_in_loewner_order(monkeypatch, case, k, nx, ny, aspect):
    """Both routes of partial_gram: G_sep − G is within ±EXP_SUM_RTOL (plus round-off) of G in the
    Loewner order, i.e. the generalized eigenvalues of (G_sep − G, G) are that small."""
    space = _space(case, k, nx, ny)
    n = 96
    direct = face_norms.partial_gram(space, n, aspect, direct=True)
    separable = face_norms.partial_gram(space, n, aspect)
    assert np.array_equal(separable, separable.T)
    ev = sla.eigh(separable - direct, direct, eigvals_only=True)
    assert np.max(np.abs(ev)) < 1e-12


def test_the_reference_route_is_the_direct_sum(monkeypatch):
    """``direct=True`` is another computation (the flag must reach the sum): the two differ in
    their last digits, and the default route is the exponential sum at every size."""
    space = _space("R5.2", 2, 4, 4)
    direct = face_norms.partial_gram(space, 64, direct=True)
    separable = face_norms.partial_gram(space, 64)
    assert not np.array_equal(separable, direct)
    monkeypatch.setattr(face_norms, "_separable_sum", lambda *a: (_ for _ in ()).throw(RuntimeError("taken")))
    with pytest.raises(RuntimeError, match="taken"):
        face_norms.partial_gram(space, 64)


@pytest.mark.parametrize("n,aspect", [(96, 1.0), (1536, 1.0), (1536, 0.45)])
def test_the_taylor_block_keeps_the_loewner_bound_at_large_n(monkeypatch, n, aspect):
    """The small rates taken as one Taylor block (TAYLOR_BELOW, TAYLOR_DEGREE): still within
    ±1e-12 of the direct sum in the Loewner order, at n_max where most terms are in the block."""
    space = _space("DUAL-ALL", 1, 5, 4)
    direct = face_norms.partial_gram(space, n, aspect, direct=True)
    separable = face_norms.partial_gram(space, n, aspect)
    ev = sla.eigh(separable - direct, direct, eigvals_only=True)
    assert np.max(np.abs(ev)) < 1e-12
    monkeypatch.setattr(face_norms, "TAYLOR_BELOW", 0.0)          # no block: the plain sum agrees too
    plain = face_norms.partial_gram(space, n, aspect)
    assert np.max(np.abs(sla.eigh(plain - direct, direct, eigvals_only=True))) < 1e-12
