"""The census' mode plots: the worst mode of each UNSTABLE producer space on Γ (from tables only).

:func:`plot_census_modes` draws one panel per (code, space) whose census row is UNSTABLE in the
norm ``H`` and whose export left a mode (``results/tables/producers_modes.csv``: the finest
level's worst mode, a kernel vector of Bᵀ where β_h = 0, sampled on Γ and normalised to
max |μ_h| = 1; :mod:`infsup_contact.study.producers`): matching meshes solid, non-matching dashed.
A STABLE or not-run space has no panel. Nothing is recomputed.
"""
from __future__ import annotations

import math

from .face import _plt

NCOLS = 3


def unstable_panels(census, modes) -> list:
    """(code, space) of each panel, in the census' order: UNSTABLE in ``H`` with a mode of Γ (a
    segment's: the face's modes are not drawn here)."""
    bad = census[(census.verdict == "UNSTABLE") & (census.norm == "H")]
    drawn = set() if modes.empty else {(r.producer, r.space) for r in modes.itertuples()
                                       if "y" not in modes.columns or not _finite(r.y)}
    return [key for key in dict.fromkeys(zip(bad.code, bad.space)) if key in drawn]


def _finite(value) -> bool:
    try:
        return math.isfinite(float(value))
    except (TypeError, ValueError):
        return False


def plot_census_modes(census, modes, pdf, png) -> list:
    """The figure (PDF and PNG, atomically) and its panels' (code, space). With no panel the
    figure says so in one line (the workflow's output exists either way; the paper leaves it out)."""
    from ..style import save_figure, style

    plt = _plt()
    panels = unstable_panels(census, modes)
    ncols = min(NCOLS, max(1, len(panels)))
    nrows = max(1, math.ceil(len(panels) / ncols))
    with style():
        fig, axes = plt.subplots(nrows, ncols, figsize=(2.4 * ncols, 2.2 * nrows), layout="constrained",
                                 squeeze=False)
        for ax in axes.flat[len(panels):]:
            ax.set_axis_off()
        if not panels:
            axes.flat[0].text(0.5, 0.5, "no UNSTABLE producer space with a mode on Γ", ha="center", va="center",
                              fontsize=8)
        for ax, (code, space) in zip(axes.flat, panels):
            _panel(ax, code, space, census, modes)
        save_figure(fig, pdf, png)
    return panels


def _panel(ax, code: str, space: str, census, modes) -> None:
    """One (code, space): the finest level's mode per offset, the kernel against dim M_h in the legend."""
    rows = census[(census.code == code) & (census.space == space)]
    for r in rows.itertuples():
        m = modes[(modes.producer == code) & (modes.space == space) & (modes.offset == r.offset)].sort_values("x")
        if m.empty:
            continue
        kernel = r.kernel_vs_dim.split()[-1] if r.kernel_vs_dim != "-" else "-"
        beta = float(m.beta.iloc[0])
        what = f"kernel {kernel}" if bool(m.in_kernel.iloc[0]) else rf"$\beta_h$ = {beta:.1e}"
        ax.plot(m.x, m.mu, lw=0.9, linestyle="-" if r.offset == 0 else "--",
                label=f"K={r.offset}, 1/h={1 / float(m.h.iloc[0]):g}: {what}")
    ax.axhline(0.0, color="0.6", lw=0.5)
    ax.set_title(f"{code} {space}", fontsize=7)
    ax.set_xlabel(r"position on $\Gamma$", fontsize=6)
    ax.set_ylabel(r"$\mu_h$ ($\max|\mu_h|=1$)", fontsize=6)
    ax.tick_params(labelsize=5)
    ax.legend(fontsize=4.5, frameon=False, loc="upper center", bbox_to_anchor=(0.5, -0.3))  # below: off the mode
