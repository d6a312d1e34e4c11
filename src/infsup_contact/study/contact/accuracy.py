"""Error measures of a contact solution against the exact (manufactured) solution or a
reference solution (membranes): energy, L²(Ω), λ in L²(Γ) and in the H^{-1/2}_00 dual
norm (eq. (3.9), by sine series), contact set, penetration.
"""
from __future__ import annotations

import ngsolve
import numpy as np
import scipy.fft

from ...contact.contact import ContactSolution, gamma_values, lambda_values
from ...discretization.segment.norms import sine_coefficients
from .profiles import gamma_sample_points

N_SAMPLE = 4001
"""Points on Γ for pointwise quantities (penetration, contact set)."""


def _gauss_on(gamma, partition, n: int = 12):
    """``n`` Gauss points per cell of ``partition``: Γ's quadrature of degree 2n − 1."""
    return gamma.quadrature(partition, 2 * n - 1)


def energy_and_l2_errors(sol: ContactSolution, exact) -> tuple[float, float]:
    """‖u − u_h‖_a = (Σ c_i ∫|∇(u_i − u_ih)|²)^{1/2} and ‖u − u_h‖_{L²(Ω)}."""
    e2 = l2 = 0.0
    for gf, side, u, gu, c in zip(sol.u, sol.sides, (exact.u1, exact.u2),
                                  (exact.grad_u1, exact.grad_u2), sol.c):
        mesh, order = side.trace.fes.mesh, 2 * side.trace.fes.globalorder + 6
        d = ngsolve.grad(gf) - gu
        e2 += c * ngsolve.Integrate(d * d, mesh, order=order)
        l2 += ngsolve.Integrate((gf - u) ** 2, mesh, order=order)
    return float(np.sqrt(max(e2, 0))), float(np.sqrt(max(l2, 0)))


def lambda_l2_error(sol: ContactSolution, lam_exact, kinks=()) -> float:
    """‖λ − λ_h‖_{L²(Γ)} by Gauss on the multiplier partition refined at ``kinks``."""
    breaks = np.unique(np.r_[np.linspace(0, 1, 4 * sol.space.n_intervals + 1), sol.space.breakpoints, kinks])
    x, w = _gauss_on(sol.gamma, breaks)
    return float(np.sqrt(w @ (lam_exact(x) - lambda_values(sol, x)) ** 2))


def exact_sine_coefficients(f, n_max: int) -> np.ndarray:
    """√2 ∫ f sin(nπx), n = 1..n_max, by the DST-I of f on a fine grid (trapezoid rule)."""
    m = 8 * n_max
    x = np.arange(1, m) / m
    return np.sqrt(2.0) * scipy.fft.dst(f(x), type=1)[:n_max] / (2 * m)


def lambda_hm12_error(sol: ContactSolution, lam_exact, n_max: int = 2**14) -> float:
    """‖λ − λ_h‖_M = (Σ e_n²/(nπ))^{1/2}, truncated at n_max and Richardson-extrapolated
    assuming an n^{-2} tail (λ_h may jump)."""
    n = np.arange(1, n_max + 1)
    e = exact_sine_coefficients(lam_exact, n_max) - sol.lam @ sine_coefficients(sol.space, n)
    partial = np.cumsum(e**2 / (n * np.pi))
    s_half, s_full = partial[n_max // 2 - 1], partial[-1]
    return float(np.sqrt(max(s_full + (s_full - s_half) / 3.0, 0.0)))


def contact_set(values: np.ndarray, x: np.ndarray, rtol: float = 1e-8) -> np.ndarray:
    """Mask of sample points where λ_h is positive (relative to its maximum)."""
    return values > rtol * max(np.abs(values).max(), 1e-300)


def contact_set_error(sol: ContactSolution, exact_set: tuple) -> float:
    """|A Δ A_h|: measure of the symmetric difference, by sampling Γ."""
    x = (np.arange(N_SAMPLE) + 0.5) / N_SAMPLE
    a, b = exact_set
    exact = (x > a) & (x < b)
    return float(np.mean(exact != contact_set(lambda_values(sol, x), x)))


def max_penetration(sol: ContactSolution, n: int = 801) -> float:
    """max(u_{1,h} − u_{2,h}, 0) sampled along Γ."""
    x = np.linspace(0, 1, n)[1:-1]
    u1, u2 = gamma_values(sol, x)
    return float(max(np.max(u1 - u2), 0.0))


def lambda_min_pointwise(sol: ContactSolution, per_interval: int = 41) -> float:
    """min_x λ_h(x) over ``per_interval`` samples per interval of G_h (one-sided at the
    breakpoints). The cone of (4.1) constrains coefficients; for a non-nodal basis (dual
    multipliers) or nodal ones of degree ≥ 2, λ_h may dip below 0 between the nodes."""
    return float(lambda_values(sol, gamma_sample_points(sol.space.breakpoints, per_interval)).min())


def lambda_total_variation(sol: ContactSolution) -> float:
    """Σ |Δλ_h| over the multiplier nodes in x order: grows when λ_h oscillates."""
    order = np.argsort(sol.space.nodes())
    return float(np.abs(np.diff(sol.lam[order])).sum())


# --- against a reference solution (membranes: no exact solution) -------------------------

def _element_quadrature(mesh, order: int):
    """Physical quadrature points and weights of all volume elements of ``mesh``."""
    pts = np.array([v.point for v in mesh.vertices])
    tris = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ngsolve.VOL)])
    ir = ngsolve.IntegrationRule(ngsolve.TRIG, order)
    ref = np.array([p[:2] for p in ir.points])
    w = np.array(ir.weights)
    p0, p1, p2 = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    # reference (ξ, η) ↦ p0·(1 − ξ − η) + p1 ξ + p2 η, NGSolve's TRIG has vertices (1,0),(0,1),(0,0)
    lam = np.column_stack([ref[:, 0], ref[:, 1], 1 - ref[:, 0] - ref[:, 1]])
    xy = np.einsum("qa,tad->tqd", lam, np.stack([p0, p1, p2], axis=1))
    e1, e2 = p1 - p0, p2 - p0
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    return xy.reshape(-1, 2), (2.0 * area[:, None] * w[None, :]).ravel()


def _values_at(gf, xy, mips=None):
    """u_h and ∇u_h at the points xy (``mips``: those points already located in its mesh)."""
    mips = gf.space.mesh(xy[:, 0], xy[:, 1]) if mips is None else mips
    return np.asarray(gf(mips)).reshape(len(xy)), np.asarray(ngsolve.grad(gf)(mips)).reshape(len(xy), 2)


def _located(samples: dict, side: int, mesh, xy):
    """The reference's quadrature points of ``side`` located in ``mesh`` (the search for the
    element of each point is nearly all the cost of evaluating u_h there). Kept for the most
    recent mesh of each side: the multiplier cases solved on one mesh pair share it."""
    last = samples.setdefault("located", {})
    if side not in last or last[side][0] is not mesh:
        last[side] = (mesh, mesh(xy[:, 0], xy[:, 1]))
    return last[side][1]


N_SINE = 2**14
"""Sine coefficients of λ in the M-norm error (Richardson-extrapolated beyond)."""


def _reference_samples(ref) -> dict:
    """What every error measure evaluates of the reference alone, computed on first use and
    kept on the reference object: a contact job measures a few dozen solutions against one
    reference, and evaluating the reference at its own quadrature points is half the cost.

    Keys: ``quadrature`` (per side: points, weights, values, gradients), ``lambda_sine``
    (its λ's first :data:`N_SINE` sine coefficients), ``lambda_samples`` (λ at the
    contact-set sample points).
    """
    cached = vars(ref).get("_error_samples")
    if cached is not None:
        return cached
    quadrature = []
    for gref in ref.u:
        xy, w = _element_quadrature(gref.space.mesh, 2 * gref.space.globalorder)
        vr, gr = _values_at(gref, xy)
        quadrature.append((xy, w, vr, gr))
    return vars(with_reference_quadrature(ref, quadrature))["_error_samples"]


def reference_quadrature(ref) -> list:
    """Per side (points, weights, values, gradients) of the reference at its own quadrature
    points: all the error measures need of its u (what a saved reference stores,
    :func:`~.contact_rows.save_reference`)."""
    return _reference_samples(ref)["quadrature"]


def with_reference_quadrature(ref, quadrature):
    """``ref`` (space and λ) with its u given by :func:`reference_quadrature`'s samples: the
    error measures evaluate it as the reference it was saved from."""
    vars(ref)["_error_samples"] = dict(
        quadrature=quadrature, lambda_sine=ref.lam @ sine_coefficients(ref.space, np.arange(1, N_SINE + 1)),
        lambda_samples=lambda_values(ref, _contact_set_points()))
    return ref


def _contact_set_points() -> np.ndarray:
    return (np.arange(N_SAMPLE) + 0.5) / N_SAMPLE


def energy_and_l2_vs_reference(sol: ContactSolution, ref: ContactSolution) -> tuple[float, float]:
    """‖u_ref − u_h‖_a and L²(Ω), by quadrature on the reference mesh (exact when nested)."""
    e2 = l2 = 0.0
    samples = _reference_samples(ref)
    for side, (gf, (xy, w, vr, gr), c) in enumerate(zip(sol.u, samples["quadrature"], sol.c)):
        v, g = _values_at(gf, xy, _located(samples, side, gf.space.mesh, xy))
        e2 += c * w @ np.sum((g - gr) ** 2, axis=1)
        l2 += w @ (v - vr) ** 2
    return float(np.sqrt(e2)), float(np.sqrt(l2))


def lambda_errors_vs_reference(sol: ContactSolution, ref: ContactSolution):
    """(‖λ_ref − λ_h‖_{L²(Γ)}, ‖λ_ref − λ_h‖_M), both exact up to the series tail."""
    gamma = sol.gamma  # tol=0: only equal breakpoints merge (as np.union1d)
    x, w = _gauss_on(gamma, gamma.common_refinement(sol.space.breakpoints, ref.space.breakpoints, tol=0.0))
    l2 = float(np.sqrt(w @ (lambda_values(ref, x) - lambda_values(sol, x)) ** 2))
    n = np.arange(1, N_SINE + 1)
    e = _reference_samples(ref)["lambda_sine"] - sol.lam @ sine_coefficients(sol.space, n)
    partial = np.cumsum(e**2 / (n * np.pi))
    s_half, s_full = partial[N_SINE // 2 - 1], partial[-1]
    return l2, float(np.sqrt(max(s_full + (s_full - s_half) / 3.0, 0.0)))


def contact_set_error_vs_reference(sol: ContactSolution, ref: ContactSolution) -> float:
    """|A_ref Δ A_h| by sampling Γ."""
    x = _contact_set_points()
    return float(np.mean(contact_set(_reference_samples(ref)["lambda_samples"], x)
                         != contact_set(lambda_values(sol, x), x)))
