"""Figure 1: the model problem of the paper's Fig. 4, redrawn (no table input).

(a) Plan view: two pretensioned membranes Ω1 = (0,1)×(0,1) and Ω2 = (0,1)×(1,2), fixed
on three edges each (u_i = 0 on ∂Ω_i∖Γ, hatched), in unilateral contact on
Γ = (0,1)×{1} (u2 ≥ u1). (b) A section x1 = const through both membranes, the transverse
displacement x3 up: the loads of the membranes scene, f = +f0 on Ω1 (up) and f = −f0 on
Ω2 (down), f0 = 4(1 − 2x1) > 0 for x1 < 1/2, press the free edges together on Γ.
"""
import sys

if "snakemake" in globals():  # run by Snakemake: threads and log before numpy loads
    sys.path.insert(0, "workflow/scripts")
    from _glue import limit_threads, log_to

    limit_threads(snakemake.threads)  # noqa: F821
    log_to(snakemake.log[0])  # noqa: F821

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import FancyArrowPatch, Rectangle  # noqa: E402

from infsup_contact.report.style import CASE_COLORS, NEUTRAL, save_figure, style  # noqa: E402

OMEGA_FILL = ("#dedede", "#f2f2f2")  # Ω1, Ω2
LOAD = NEUTRAL


def _arrow(ax, a, b, color="k", lw=1.0, ms=8):
    ax.add_patch(FancyArrowPatch(tuple(a), tuple(b), arrowstyle="-|>", mutation_scale=ms, color=color, lw=lw,
                                 shrinkA=0, shrinkB=0, zorder=5))


def hatched_edge(ax, p, q, outward, n=12, length=0.07):
    """A clamped edge p→q: bold line plus slanted hatch ticks on the ``outward`` side."""
    p, q, outward = (np.asarray(v, dtype=float) for v in (p, q, outward))
    ax.plot(*np.array([p, q]).T, color="k", lw=1.8, solid_capstyle="projecting", zorder=3)
    t = (q - p) / np.linalg.norm(q - p)
    for s in np.linspace(0.03, 0.97, n):
        a = p + s * (q - p)
        ax.plot(*np.array([a, a + length * (outward + 0.6 * t)]).T, color="k", lw=0.6, zorder=3)


def _plan_view(ax):
    for y0, fill in zip((0.0, 1.0), OMEGA_FILL):
        ax.add_patch(Rectangle((0, y0), 1, 1, fc=fill, ec="none", zorder=1))
    hatched_edge(ax, (0, 0), (1, 0), (0, -1))
    hatched_edge(ax, (0, 2), (1, 2), (0, 1))
    hatched_edge(ax, (0, 0), (0, 2), (-1, 0), n=24)
    hatched_edge(ax, (1, 0), (1, 2), (1, 0), n=24)
    ax.plot([0, 1], [1, 1], color="k", lw=3.4, solid_capstyle="butt", zorder=4)
    ax.plot([0, 1], [1, 1], color="white", lw=1.0, linestyle=(0, (3, 2)), zorder=4)
    ax.text(1.13, 1.0, r"$\Gamma$" "\n" "(contact)", ha="left", va="center", fontsize=9)
    for y, i, sign in ((0.5, 1, "+"), (1.5, 2, "-")):
        ax.text(0.5, y + 0.12, rf"$\Omega_{i}$", ha="center", va="center", fontsize=12)
        ax.text(0.5, y - 0.12, rf"$c_{i}$,  $f = {sign}f_0$", ha="center", va="center", fontsize=9)
    ax.text(0.62, -0.2, r"$u_1 = 0$", ha="center", va="top", fontsize=9)
    ax.text(0.62, 2.2, r"$u_2 = 0$", ha="center", va="bottom", fontsize=9)
    _arrow(ax, (-0.42, -0.32), (-0.12, -0.32), ms=6, lw=0.8)
    _arrow(ax, (-0.42, -0.32), (-0.42, -0.02), ms=6, lw=0.8)
    ax.text(-0.08, -0.32, r"$x_1$", ha="left", va="center", fontsize=9)
    ax.text(-0.42, 0.02, r"$x_2$", ha="center", va="bottom", fontsize=9)
    ax.plot([0.25, 0.25], [-0.02, 2.02], color=LOAD, lw=0.9, linestyle="--", zorder=2)
    ax.text(0.25, 2.2, "(b)", ha="center", va="bottom", fontsize=7.5, color=LOAD)
    ax.set_title("(a) plan view", fontsize=9.5)
    ax.set_aspect("equal")
    ax.set_xlim(-0.5, 1.55)
    ax.set_ylim(-0.45, 2.5)
    ax.axis("off")


def _section(ax):
    """Schematic displaced section x1 = 1/4: u1 pushed up, u2 down, equal on Γ (contact)."""
    w = 0.06  # common value on Γ
    s1 = np.linspace(0, 1, 101)
    u1 = s1 * (0.9 - (0.9 - w) * s1)  # u1(0) = 0, u1(1) = w
    t = np.linspace(0, 1, 101)
    u2 = w * (1 - t) - 0.9 * t * (1 - t)  # u2(Γ) = w, u2(2) = 0
    ax.axhline(0, color=NEUTRAL, lw=0.6, linestyle=":", zorder=1)
    ax.plot(s1, u1, color="k", lw=2.0, zorder=3)
    ax.plot(1 + t, u2, color="k", lw=2.0, zorder=3)
    ax.fill_between(s1, 0, u1, color=OMEGA_FILL[0], zorder=0)
    ax.fill_between(1 + t, 0, u2, color=OMEGA_FILL[1], zorder=0)
    for x in (0.0, 2.0):  # clamped ends
        ax.add_patch(Rectangle((x - 0.05 if x == 0 else x, -0.12), 0.05, 0.24, fc="none", ec="k", hatch="////",
                               lw=0.6, zorder=2))
    for x in np.linspace(0.15, 0.85, 5):  # +f0 on Ω1: up
        y = x * (0.9 - (0.9 - w) * x)
        _arrow(ax, (x, y - 0.2), (x, y - 0.015), color=LOAD)
    for x in np.linspace(1.15, 1.85, 5):  # −f0 on Ω2: down
        tt = x - 1
        y = w * (1 - tt) - 0.9 * tt * (1 - tt)
        _arrow(ax, (x, y + 0.2), (x, y + 0.015), color=LOAD)
    ax.plot([1, 1], [-0.3, 0.32], color="k", lw=0.7, linestyle="--", zorder=2)
    ax.plot([1], [w], marker="o", color="k", markersize=5, zorder=6)
    ax.text(1.03, 0.33, r"$\Gamma$:  $u_2 \geq u_1$" "\n" r"here $u_2 = u_1$, $\lambda > 0$", ha="left", va="bottom",
            fontsize=8.5)
    ax.text(0.5, 0.27, r"$u_1$ on $\Omega_1$", ha="center", va="bottom", fontsize=9)
    ax.text(1.5, -0.33, r"$u_2$ on $\Omega_2$", ha="center", va="top", fontsize=9)
    ax.text(0.32, -0.02, r"$+f_0$", ha="center", va="top", fontsize=8.5, color=LOAD)
    ax.text(1.68, 0.08, r"$-f_0$", ha="center", va="bottom", fontsize=8.5, color=LOAD)
    _arrow(ax, (-0.25, -0.45), (0.1, -0.45), ms=6, lw=0.8)
    _arrow(ax, (-0.25, -0.45), (-0.25, -0.2), ms=6, lw=0.8)
    ax.text(0.13, -0.45, r"$x_2$", ha="left", va="center", fontsize=9)
    ax.text(-0.25, -0.17, r"$x_3$ (displacement)", ha="left", va="bottom", fontsize=8)
    ax.text(1.0, -0.62, r"$f_0(x_1) = 4(1-2x_1)$: pressed together for $x_1 < 1/2$, apart for $x_1 > 1/2$",
            ha="center", va="top", fontsize=8, color=LOAD)
    ax.set_title(r"(b) section $x_1 = 1/4$ (schematic)", fontsize=9.5)
    ax.set_xlim(-0.35, 2.25)
    ax.set_ylim(-0.75, 0.55)
    ax.axis("off")


def plot_model_problem(pdf, png) -> None:
    """Plan view (a) and displaced section (b) of the model problem; save PDF+PNG."""
    with style():
        fig, (a, b) = plt.subplots(1, 2, figsize=(8.4, 3.9), width_ratios=[1.0, 1.75], layout="constrained")
        _plan_view(a)
        _section(b)
        save_figure(fig, pdf, png)


assert CASE_COLORS  # the shared style module (no case is drawn in this figure)

if "snakemake" in globals():
    plot_model_problem(snakemake.output.pdf, snakemake.output.png)  # noqa: F821
