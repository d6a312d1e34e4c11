"""Figure 6: contact errors against h with the fitted slopes (contact.csv, rates.csv).

The primary scene (config contact.primary_scene), structured meshes. Columns: the error measures (energy, L²(Ω),
λ in L²(Γ), λ in H^{-1/2}); rows: displacement degree k. Stable cases solid, unstable
dashed; the legend of each panel gives the slope fitted by the rates stage (rates.csv:
least squares over the finest meshes).
"""
import sys

if "snakemake" in globals():  # run by Snakemake: threads and log before numpy loads
    sys.path.insert(0, "workflow/scripts")
    from _glue import limit_threads, log_to, read_table, register_user_spaces

    limit_threads(snakemake.threads)  # noqa: F821
    log_to(snakemake.log[0])  # noqa: F821
    register_user_spaces(snakemake.config)  # noqa: F821

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from infsup_contact.report.style import (h_ticks, CASE_COLORS, LABELS, MEASURES, case_label, case_style,  # noqa: E402
                                     mesh_size, ordered_cases, save_figure, style)

MEASURE_ORDER = ("energy_error", "l2_error", "lambda_l2_error", "lambda_hm12_error")


def pick_scene(contact: pd.DataFrame, scene: str) -> str:
    """``scene`` (config contact.primary_scene), checked to be in the table."""
    if scene in set(contact.scene):
        return scene
    raise ValueError(f"contact table has no scene {scene!r} (contact.primary_scene)")


def plot_convergence(contact: pd.DataFrame, rates: pd.DataFrame, pdf, png, scene: str,
                     family: str = "structured") -> None:
    """Errors against h, one column per measure, one row per k; slopes from ``rates``."""
    scene = pick_scene(contact, scene)
    sel = contact[(contact.scene == scene) & (contact.family == family) & (contact.N1 == contact.N2)]
    sel = sel.assign(h=mesh_size(sel))
    rt = rates[(rates.scene == scene) & (rates.family == family)]
    measures = [m for m in MEASURE_ORDER if m in sel.columns]
    ks = sorted(sel.k.unique())
    with style():
        fig, axes = plt.subplots(len(ks), len(measures), figsize=(2.55 * len(measures) + 0.5, 2.55 * len(ks) + 0.6),
                                 squeeze=False, sharex=True, layout="constrained")
        for i, k in enumerate(ks):
            sub = sel[sel.k == k]
            cases = ordered_cases(sub.case.unique())
            for j, m in enumerate(measures):
                ax = axes[i, j]
                handles, labels = [], []
                for z, case in enumerate(cases):
                    g = sub[sub.case == case].sort_values("h")
                    # coinciding curves (energy, L²) stay visible: each later curve has smaller
                    # markers and is drawn on top of the earlier ones
                    # (white marker edges separate the nested markers)
                    size = 9.0 - 5.0 * z / max(len(cases) - 1, 1)
                    (line,) = ax.plot(g.h, g[m], **case_style(case, markersize=size, zorder=2 + z,
                                                               markeredgecolor="white", markeredgewidth=0.6))
                    r = rt[(rt.case == case) & (rt.k == k) & (rt.measure == m)]
                    slope = f"{r.slope.iloc[0]:.2f}" if len(r) and np.isfinite(r.slope.iloc[0]) else "n/a"
                    handles.append(line)
                    labels.append(f"{case}: {slope}")
                ax.set_xscale("log")
                ax.set_yscale("log")
                ax.legend(handles, labels, loc="lower right", title="fitted slope", title_fontsize=7,
                          fontsize=7, handlelength=2.2, borderpad=0.3, labelspacing=0.25)
                if i == 0:
                    ax.set_title(MEASURES[m][0])
                if j == 0:
                    ax.set_ylabel(f"k = {k}: error")
                ax.text(0.03, 0.97, MEASURES[m][1], transform=ax.transAxes, ha="left", va="top", fontsize=7.5,
                        bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8))
                if i == len(ks) - 1:
                    ax.set_xlabel(LABELS["h"])
        h_ticks(axes, sel.h, powers_of_two=False)
        allcases = ordered_cases(sel.case.unique())
        proxies = [Line2D([], [], **case_style(c)) for c in allcases]
        fig.legend(proxies, [case_label(c) for c in allcases], loc="outside lower center", ncol=len(allcases),
                   handlelength=2.6, title="stable cases solid, unstable dashed", title_fontsize=7.5)
        save_figure(fig, pdf, png)


assert CASE_COLORS  # the shared map (used through case_style)

if "snakemake" in globals():
    inp = snakemake.input  # noqa: F821
    plot_convergence(read_table(inp.contact, "contact"), read_table(inp.rates, "rates"), snakemake.output.pdf,  # noqa: F821
                     snakemake.output.png, scene=snakemake.params.scene)  # noqa: F821
