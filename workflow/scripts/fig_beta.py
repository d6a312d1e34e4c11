"""Figures 2 and 3: β_h against h, one panel per k, every case (from results/tables/beta.csv).

Structured family, multiplier mesh omega2 (the paper's G_h), matching meshes N1 = N2, the
first (c1, c2) pair of the table, one norm (H: figure 2, L2: figure 3). A case with a
kernel (kernel_dim > 0: R5.2, R5.4) has β_h = 0; it is drawn dashed with
``smallest_nonzero``, the first eigenvalue above the kernel, and annotated with the
number of zero modes. The L2 figure carries the slope-½ triangle of Remark 3.1.
"""
import sys

if "snakemake" in globals():  # run by Snakemake: threads and log before numpy loads
    sys.path.insert(0, "workflow/scripts")
    from _glue import limit_threads, log_to, read_table, register_user_spaces
    from infsup_contact.study.beta.selection import primary_rows

    limit_threads(snakemake.threads)  # noqa: F821
    log_to(snakemake.log[0])  # noqa: F821
    register_user_spaces(snakemake.config)  # noqa: F821

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from infsup_contact.report.style import (h_ticks, CASE_COLORS, LABELS, NEUTRAL, case_label, case_style,  # noqa: E402
                                     mesh_size, ordered_cases, save_figure, slope_triangle, style)


def select_beta(beta: pd.DataFrame, norm: str) -> pd.DataFrame:
    """Rows of the figure: structured, omega2, matching, ``norm``, first (c1, c2) pair."""
    sel = beta[(beta.family == "structured") & (beta.multiplier_mesh == "omega2")
               & (beta.N1 == beta.N2) & (beta.norm == norm)]
    if sel.empty:
        raise ValueError(f"beta table has no structured/omega2/matching rows with norm {norm}")
    c1, c2 = sel.iloc[0][["c1", "c2"]]
    sel = sel[(sel.c1 == c1) & (sel.c2 == c2)]
    return sel.assign(h=mesh_size(sel)).sort_values(["k", "case", "h"])


def zero_mode_text(kernel_dims) -> str:
    """'1 zero mode', '2 zero modes' or '2–3 zero modes' for the kernel dimensions seen."""
    lo, hi = int(min(kernel_dims)), int(max(kernel_dims))
    n = f"{lo}" if lo == hi else f"{lo}–{hi}"
    return f"{n} zero mode" + ("" if hi == 1 else "s")


def plot_beta(beta: pd.DataFrame, pdf, png, norm: str = "H") -> None:
    """Draw β_h (or the first nonzero eigenvalue above a kernel) against h; save PDF+PNG."""
    sel = select_beta(beta, norm)
    ks = sorted(sel.k.unique())
    handles = {}
    with style():
        fig, axes = plt.subplots(1, len(ks), figsize=(3.5 * len(ks) + 0.5, 3.6), squeeze=False,
                                 sharey=True, layout="constrained")
        axes = axes[0]
        for ax, k in zip(axes, ks):
            sub = sel[sel.k == k]
            notes = []
            for case in ordered_cases(sub.case.unique()):
                g = sub[sub.case == case].sort_values("h")
                kernel = g.kernel_dim.max() > 0
                y = g.smallest_nonzero if kernel else g.beta
                kw = case_style(case)
                if kernel:  # open, larger, dashed, on top: the stable curve under it stays visible
                    kw.update(linestyle="--", fillstyle="none", markersize=6.5, zorder=3)
                    notes.append((case, g.h.values, y.values, zero_mode_text(g.kernel_dim)))
                (line,) = ax.plot(g.h, y, label=case_label(case), **kw)
                handles.setdefault(case, line)
            ax.set_xscale("log")
            ax.set_yscale("log")
            h_ticks(ax, sub.h)
            ax.set_title(f"displacement degree k = {k}")
            ax.set_xlabel(LABELS["h"])
            if norm == "L2":
                _half_slope_triangle(ax, sub)
            _annotate_kernels(ax, notes)
        axes[0].set_ylabel(LABELS[f"beta_{norm}"])
        order = ordered_cases(handles)
        fig.legend([handles[c] for c in order], [case_label(c) for c in order], loc="outside lower center",
                   ncol=min(len(order), 5), handlelength=2.6, columnspacing=1.2,
                   title="solid, filled: $\\beta_h$;  dashed, open: $\\beta_h = 0$, first eigenvalue above the kernel shown",
                   title_fontsize=7.5)
        save_figure(fig, pdf, png)


def _annotate_kernels(ax, notes):
    """Name the kernel of each dashed curve below right of it (clear of a rising curve)."""
    for case, h, y, note in notes:
        lh = np.log(h)
        x = np.exp(lh.min() + 0.6 * (lh.max() - lh.min()))
        yx = np.exp(np.interp(np.log(x), lh, np.log(y)))
        ax.annotate(note, xy=(x, yx), xytext=(6, -6), textcoords="offset points", ha="left", va="top",
                    fontsize=7.5, color=CASE_COLORS[case])


def _half_slope_triangle(ax, sub):
    """Slope-½ reference (Remark 3.1: β_h ~ h^{1/2} in the L² norm), under the stable curves."""
    stable = sub[sub.kernel_dim == 0]
    if stable.empty:
        return
    lh = np.log10(sub.h)
    x0 = 10 ** (lh.min() + 0.08 * (lh.max() - lh.min()))
    y_at = [np.interp(np.log(x0), np.log(g.h), np.log(g.beta)) for _, g in stable.groupby("case")]
    y0 = np.exp(min(y_at)) * 0.4
    slope_triangle(ax, x0, y0, 0.5, decades=0.22 * (lh.max() - lh.min()), label="½")


if "snakemake" in globals():
    plot_beta(primary_rows(read_table(snakemake.input.beta, "beta")), snakemake.output.pdf, snakemake.output.png,  # noqa: F821
              norm=snakemake.params.norm)  # noqa: F821
