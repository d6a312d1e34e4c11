"""The numerical kernel of the β_h eigenproblem (4.5) from the spectrum's gap.

A fixed relative threshold (eigenvalues below 1e-8 λ_max) calls the bottom of a spectrum
that decays smoothly a "kernel" of 2–5. Here a kernel is reported only where the bottom
of the spectrum has a clear gap above the round-off level of the computation
(:data:`KERNEL_CRITERION`), and it is compared with the structural count of the paper's
dimension arguments (Remarks 5.2 and 5.4: dim M_h − dim W_h). Pure numpy: the command
line states the rule without importing NGSolve.
"""
from __future__ import annotations

import numpy as np

GAP_DECADES = 3
"""A kernel needs the first eigenvalue above it at least 10**GAP_DECADES times the round-off level."""
KERNEL_CRITERION = (
    "kernel by the spectrum's gap: with the round-off level eta = n*eps*lambda_max of the dense "
    "eigen-solver (n = dim M, eps = machine epsilon), a kernel of dimension d is reported iff the "
    "d smallest eigenvalues beta^2 are <= eta and the next one is >= 1e3*eta (a gap of at least "
    "three decades clear of round-off); otherwise no kernel (d = 0), and a smoothly decaying "
    "bottom shows as a small beta_h and its slope over the meshes")
"""The rule of :func:`kernel_from_gap`, as stated in ``infsup-contact beta --help`` and the README."""


def kernel_from_gap(ev: np.ndarray, gap_decades: float = GAP_DECADES) -> tuple[int, float]:
    """Kernel dimension of an ascending spectrum by its gap, and the gap (see KERNEL_CRITERION).

    η = n ε λ_max bounds the absolute error of the eigenvalues from a backward-stable dense
    solver (n the dimension, ε the machine epsilon). The d eigenvalues <= η are
    indistinguishable from 0; they form a kernel only if the next eigenvalue stands at least
    10**gap_decades above η. A spectrum that decays smoothly into round-off (e.g. geometric,
    1, 1e-2, 1e-4, …) has no such gap and reports no kernel.

    Returns
    -------
    (int, float)
        d and λ_{d+1}/η (λ_1/η when d = 0; inf when every eigenvalue is at round-off level).
    """
    ev = np.asarray(ev, float)
    eta = len(ev) * np.finfo(float).eps * max(ev[-1], 0.0)
    d = int(np.sum(ev <= eta))
    if d == len(ev):  # S = 0: everything is kernel
        return d, np.inf
    gap = float(ev[d] / eta) if eta > 0 else np.inf
    if d > 0 and gap < 10.0 ** gap_decades:
        return 0, float(ev[0] / eta) if ev[0] > 0 else 0.0
    return d, gap


def kernel_check(numerical: int, structural: int) -> str:
    """Compare the numerical kernel with the structural count max(dim M − dim(W1 + W2), 0).

    The count is a lower bound on the kernel of Bᵀ (μ ⊥ W1 + W2), exact for the paper's
    matching-mesh cases (R5.2: 2, R5.4: 1). ``agree``; ``below_structural`` (fewer zero
    modes than must exist: the gap criterion missed a kernel); ``above_structural`` (zero
    modes the count does not predict).
    """
    if numerical == structural:
        return "agree"
    return "below_structural" if numerical < structural else "above_structural"
