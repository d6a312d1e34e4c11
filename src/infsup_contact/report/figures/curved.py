"""The curved segment's figure, drawn from the arc study's tables only (nothing recomputed).

:func:`plot_curved`
    (a) β_h (H^{-1/2}_00 norm) against h on the non-matching series N:N+1 per space with the
    exact coupling, the flat segment dashed and the most curved arc solid: curvature moves the
    stable spaces by a little and leaves the unstable ones falling; (b) the patch test's
    max |λ_h − λ|/λ against h on the most curved arc, per space holding the constants, with the
    slope-2 triangle (T3, which does not hold them, stays at 1 and is off the axis); (c) the
    projection's worst mode of DUAL-ALL on a non-matching pair (``beta --worst-mode``): the
    flat segment's two end modes, lifted by the projection to β_h > 0.
"""
from __future__ import annotations

import numpy as np

from .face import _plt


def _radius_text(kappa: float) -> str:
    return r"$R=\infty$" if kappa == 0 else f"$R={1 / kappa:g}$"


def plot_curved(beta, patch, modes, pdf, png, series: str = "plus1") -> None:
    """The three panels of the module docstring from the ``arc_beta``, ``arc_patch`` and
    ``worst_mode`` tables."""
    from ..style import case_style, h_ticks, ordered_cases, save_figure, slope_triangle, style

    plt = _plt()
    b = beta[(beta.series == series) & (beta.norm == "H") & (beta.coupling == "exact") & (beta.kernel_dim == 0)]
    curved = float(b.curvature.max())
    with style():
        fig, axes = plt.subplots(1, 3, figsize=(7.2, 3.0), layout="constrained")
        ax = axes[0]
        for case in ordered_cases(b.case.unique()):
            for kappa, ls in ((0.0, "--"), (curved, "-")):
                g = b[(b.case == case) & (b.curvature == kappa)].sort_values("N2")
                if len(g):
                    ax.loglog(1.0 / g.N2, g.beta, label=case if kappa == curved else None,
                              **case_style(case, None, markersize=3, linestyle=ls))
        h_ticks(ax, 1.0 / b.N2, powers_of_two=False)
        ax.set_xlabel("$h = 1/N_2$")
        ax.set_ylabel(r"$\beta_h$ ($H^{-1/2}_{00}(\Gamma)$)")
        ax.set_title(f"(a) {series}: flat dashed, {_radius_text(curved)} solid", fontsize=7)
        ax.legend(fontsize=5, frameon=False)
        ax = axes[1]
        p = patch[(patch.curvature == patch.curvature.max()) & (patch.coupling == "exact")
                  & patch.holds_constants.astype(bool)]
        for (case, k), g in p.groupby(["case", "k"]):
            g = g.sort_values("N2")
            ax.loglog(1.0 / g.N2, g.lambda_max_rel_error, label=f"{case}, k={k}", **case_style(case, k, markersize=3))
        h = 1.0 / p.N2.to_numpy(float)
        slope_triangle(ax, float(np.median(h)), float(p.lambda_max_rel_error.min()) * 2.0, 2.0)
        h_ticks(ax, h, powers_of_two=False)
        ax.set_xlabel("$h = 1/N_2$")
        ax.set_ylabel(r"$\max|\lambda_h-\lambda|/\lambda$")
        ax.set_title(f"(b) patch test, {_radius_text(float(patch.curvature.max()))}", fontsize=7)
        ax.legend(fontsize=5, frameon=False, ncol=2)
        ax = axes[2]
        m = modes.sort_values("x")
        ax.plot(m.x, m.mu, color="0.2", lw=0.8)
        ax.axhline(0.0, color="0.6", lw=0.5)
        ax.set_xlim(0.0, 0.25)  # the mode lives at Γ's end s = 0 (zero beyond)
        ax.set_xlabel("arc length $s$ on $\\Gamma$ (near $s = 0$)")
        ax.set_ylabel(r"$\mu_h$ ($\max|\mu_h|=1$)")
        case = str(modes.case.iloc[0])
        ax.set_title(f"(c) {case}, projection: " + r"$\beta_h$" + f" = {float(modes.beta.iloc[0]):.1e}", fontsize=7)
        save_figure(fig, pdf, png)
