"""Figure 5: contact solutions of a stable and an unstable pair on the same mesh.

Left: u_{1,h} and u_{2,h} (contours; Ω1 below Ω2 in one axes) of the stable case. Right:
along Γ, the gap u_{2,h} − u_{1,h} and the multiplier λ_h of both cases. Data:
results/tables/field_values.csv and results/tables/gamma_profiles.csv (rule
gamma_profiles); nothing is recomputed here.
"""
import sys

if "snakemake" in globals():  # run by Snakemake: threads and log before numpy loads
    sys.path.insert(0, "workflow/scripts")
    from _glue import limit_threads, log_to, read_table, register_user_spaces

    limit_threads(snakemake.threads)  # noqa: F821
    log_to(snakemake.log[0])  # noqa: F821
    register_user_spaces(snakemake.config)  # noqa: F821

import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from infsup_contact.report.style import (CASE_COLORS, LABELS, NEUTRAL, case_label, case_style,  # noqa: E402
                                     is_stable, ordered_cases, save_figure, style)

FIELD_CMAP = "PuOr_r"  # diverging, colour-vision-deficiency safe; u1 < 0 < u2 mostly


def _markevery(n: int, count: int = 16):
    return max(n // count, 1)


def plot_contact_solutions(gamma: pd.DataFrame, field: pd.DataFrame, pdf, png) -> None:
    """Draw the figure from the two tables (one k, one N; two or more cases)."""
    cases = ordered_cases(gamma.case.unique())
    stable = [c for c in cases if is_stable(c)]
    shown = stable[0] if stable else cases[0]  # the field panel shows a stable solution
    k, n = int(gamma.k.iloc[0]), int(gamma.N.iloc[0])
    with style():
        fig = plt.figure(figsize=(9.6, 4.5), layout="constrained")
        sub = fig.subfigures(1, 2, width_ratios=[1.0, 2.15], wspace=0.02)
        ax_u = sub[0].subplots()
        ax_g, ax_l = sub[1].subplots(2, 1, sharex=True)
        _fields(ax_u, sub[0], field[field.case == shown], shown, k, n)
        for case in cases:
            g = gamma[gamma.case == case]
            for ax, q in ((ax_g, "gap"), (ax_l, "lambda")):
                d = g[g.quantity == q].sort_values("x", kind="stable")
                ax.plot(d.x, d.value, label=case_label(case, k) + (" — stable" if is_stable(case) else " — unstable"),
                        **case_style(case, markevery=_markevery(len(d)), markersize=4, linewidth=1.3,
                                     zorder=3 if is_stable(case) else 2))
        for ax in (ax_g, ax_l):
            ax.axhline(0.0, color=NEUTRAL, lw=0.6, zorder=1)
            ax.set_xlim(0, 1)
        ax_g.set_ylabel(r"gap $u_{2,h}-u_{1,h}$ on $\Gamma$")
        ax_l.set_ylabel(r"multiplier $\lambda_h$")
        ax_l.set_xlabel(LABELS["x"])
        ax_g.set_title(rf"along $\Gamma$: structured mesh $N_1=N_2={n}$, $k={k}$")
        ax_g.legend(loc="upper left")
        save_figure(fig, pdf, png)


def _fields(ax, subfig, field, case, k, n):
    """Filled contours of u_1 on Ω1 and u_2 on Ω2, common levels, Γ highlighted."""
    umax = float(np.abs(field.u).max()) or 1.0
    levels = MaxNLocator(16, symmetric=True).tick_values(-umax, umax)
    cs = None
    for side in (1, 2):
        f = field[field.side == side]
        tri = mtri.Triangulation(f.x.values, f.y.values)  # convex square: Delaunay is fine
        cs = ax.tricontourf(tri, f.u.values, levels=levels, cmap=FIELD_CMAP)
        ax.tricontour(tri, f.u.values, levels=levels, colors="k", linewidths=0.3, alpha=0.55)
    ax.plot([0, 1], [1, 1], color="k", lw=2.2, solid_capstyle="butt")
    ax.text(0.5, 1.02, r"$\Gamma$", ha="center", va="bottom", fontsize=10,
            bbox=dict(boxstyle="round,pad=0.12", fc="white", ec="none", alpha=0.85))
    for y, name in ((0.08, r"$\Omega_1$: $u_{1,h}$"), (1.92, r"$\Omega_2$: $u_{2,h}$")):
        ax.text(0.5, y, name, ha="center", va="center", fontsize=9,
                bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85))
    ax.set_aspect("equal")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 2)
    ax.set_xticks([0, 0.5, 1])
    ax.set_yticks([0, 1, 2])
    ax.set_xlabel(r"$x_1$")
    ax.set_ylabel(r"$x_2$")
    ax.grid(False)
    ax.set_title(f"{case_label(case, k)}, N = {n}")
    cb = subfig.colorbar(cs, ax=ax, shrink=0.8, pad=0.03, aspect=30, ticks=levels[::2])
    cb.set_label(r"displacement $u_h$")
    cb.ax.tick_params(labelsize=7)


assert CASE_COLORS  # the shared map (used through case_style)

if "snakemake" in globals():
    inp = snakemake.input  # noqa: F821
    plot_contact_solutions(read_table(inp.gamma, "gamma_profiles"), read_table(inp.field, "field_values"), snakemake.output.pdf,  # noqa: F821
                           snakemake.output.png)  # noqa: F821
