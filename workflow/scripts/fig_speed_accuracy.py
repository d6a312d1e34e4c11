"""Figure 7: error against wall time per method, Pareto front marked (speed_accuracy.csv).

One row of panels per scene (and mesh family, if the table has several), one column per
error measure (energy, λ in H^{-1/2}). A
method is a (case, k) pair — or the ``method`` column when the table has one — and its
points (one per N) are joined in order of N. The Pareto front of a panel (no other point
is both faster and more accurate) is the grey staircase, its points ringed; it is taken
from the table's ``pareto_energy`` / ``pareto_lambda`` flags when present.
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

from infsup_contact.bench import pareto_front  # noqa: E402
from infsup_contact.report.style import (CASE_COLORS, K_FILL, LABELS, MEASURES, NEUTRAL, case_label, case_style,  # noqa: E402
                                     ordered_cases, save_figure, style)

REQUIRED = ("scene", "case", "k", "N", "seconds")
MEASURE_ORDER = ("energy_error", "lambda_hm12_error")
#: Pareto flags the benchmarks stage may already have computed (per scene and family)
PARETO_COLUMNS = {"energy_error": "pareto_energy", "lambda_hm12_error": "pareto_lambda"}


def front_mask(panel: pd.DataFrame, measure: str) -> np.ndarray:
    """The table's Pareto flag for ``measure`` if it has one, else :func:`pareto_front`."""
    col = PARETO_COLUMNS.get(measure)
    if col in panel.columns:
        return panel[col].astype(str).str.lower().isin(["true", "1"]).to_numpy()
    return pareto_front(panel.seconds.to_numpy(), panel[measure].to_numpy())


def _fill_note(ks) -> str:
    """'marker fill: k = 1 open, k = 2 filled' for the degrees present."""
    names = {"none": "open", "full": "filled", "left": "left half", "top": "top half"}
    return "marker fill: " + ", ".join(f"k = {k} {names[K_FILL.get(int(k), 'full')]}" for k in sorted(set(ks)))


def _method_columns(frame):
    return ["method"] if "method" in frame.columns else ["case", "k"]


def plot_speed_accuracy(table: pd.DataFrame, pdf, png) -> None:
    """Error against wall time, per scene × measure; methods coloured by case."""
    missing = [c for c in REQUIRED if c not in table.columns]
    if missing:
        raise ValueError(f"speed_accuracy table lacks columns {missing}")
    measures = [m for m in MEASURE_ORDER if m in table.columns]
    panel_keys = ["scene", "family"] if "family" in table.columns else ["scene"]
    panels = list(dict.fromkeys(table[panel_keys].itertuples(index=False, name=None)))
    mcols = _method_columns(table)
    with style():
        fig, axes = plt.subplots(len(panels), len(measures), figsize=(3.7 * len(measures) + 0.4, 3.2 * len(panels) + 0.7),
                                 squeeze=False, layout="constrained")
        seen = {}
        for i, key in enumerate(panels):
            sc = table[(table[panel_keys] == pd.Series(key, index=panel_keys)).all(axis=1)]
            name = ", ".join(str(v) for v in key)
            for j, m in enumerate(measures):
                ax = axes[i, j]
                for _, g in sc.groupby(mcols, sort=False):
                    g = g.sort_values("N")
                    case, k = g.case.iloc[0], int(g.k.iloc[0])
                    kw = case_style(case, k) if case in CASE_COLORS else dict(color=NEUTRAL, marker="x")
                    label = (g.method.iloc[0] if "method" in g.columns else case_label(case, k))
                    (line,) = ax.plot(g.seconds, g[m], label=label, zorder=3, **kw)
                    seen.setdefault(label, (case, k, line))
                front = front_mask(sc, m)
                f = sc[front].sort_values("seconds")
                if len(f):
                    ax.step(f.seconds, f[m], where="post", color=NEUTRAL, lw=1.0, alpha=0.7, zorder=2)
                    ax.plot(f.seconds, f[m], linestyle="none", marker="o", markersize=11, fillstyle="none",
                            markeredgecolor=NEUTRAL, markeredgewidth=1.0, zorder=4)
                ax.set_xscale("log")
                ax.set_yscale("log")
                ax.set_title(f"{name}: {MEASURES[m][0]}")
                ax.set_ylabel(MEASURES[m][1])
                ax.set_xlabel(LABELS["seconds"])
        order = sorted(seen, key=lambda lab: (ordered_cases(CASE_COLORS).index(seen[lab][0])
                                              if seen[lab][0] in CASE_COLORS else 99, seen[lab][1], lab))
        handles = [seen[lab][2] for lab in order]
        front_proxy = Line2D([], [], color=NEUTRAL, alpha=0.7, marker="o", markersize=9, fillstyle="none",
                             markeredgecolor=NEUTRAL)
        fig.legend(handles + [front_proxy], order + ["Pareto front"], loc="outside lower center",
                   ncol=min(len(order) + 1, 4), handlelength=2.6,
                   title="one point per mesh N; " + _fill_note(table.k), title_fontsize=7.5)
        save_figure(fig, pdf, png)


if "snakemake" in globals():
    plot_speed_accuracy(read_table(snakemake.input.table, "speed_accuracy"), snakemake.output.pdf,  # noqa: F821
                        snakemake.output.png)  # noqa: F821
