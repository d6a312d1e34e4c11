"""The contact face's figures, drawn from the face study's tables only (nothing recomputed).

:func:`plot_face_beta`
    β_h in the H^{-1/2}_00(Γ) norm against h = 1/N on matching meshes, one panel per element
    (hexahedra, tetrahedra, and HEX20 where the table has its rows), one line per (space, k)
    without a kernel: a stable space stays level, an unstable one falls.
:func:`plot_face_studies`
    (a) β_h against the covered fraction θ of edge dropping, (b) the condition number of the
    interface operator S against θ, plain and κ-scaled basis, (c) β_h against α of the
    transformed duals (QUAD8, QUAD9), (d) a worst mode μ_h on Γ (``beta --worst-mode``).
"""
from __future__ import annotations

import numpy as np

ELEMENT_TITLES = {"hex": "hexahedra (Q$_k$, rectangles)", "tet": "tetrahedra (P$_k$, Kuhn triangles)",
                  "hex20": "HEX20 (serendipity, QUAD8 faces)"}
"""Panel titles of :func:`plot_face_beta`, in panel order."""
POPP_ALPHA = 0.2
"""α = 1/5 of Popp et al. (4C's transformed duals), marked in panel (c)."""


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def matching_series(beta, norm: str = "H"):
    """The rows of ``beta`` (a face_beta table) on matching meshes in ``norm`` whose space has no
    kernel there (β_h > 0 is what a log axis can show; a kernel is β_h = 0), with h = 1/N2."""
    rows = beta[(beta.N1 == beta.N2) & (beta.norm == norm) & (beta.kernel_dim == 0)]
    return rows.assign(h=1.0 / rows.N2)


def hex20_rows(hex20):
    """HEX20 rows as face_beta rows: a model-table β table (``model_beta``, a beta study with element
    ``hex20``) as it is, its HEX20 rows; a ``face_hex20`` table (``python -m infsup_contact.study.face.hex20``)
    with element ``hex20``, k = 2, matching meshes N1 = N2 = N."""
    if "N1" in hex20.columns:
        return hex20[hex20.element == "hex20"]
    return hex20.assign(element="hex20", k=2, N1=hex20.N, N2=hex20.N)


def plot_face_beta(beta, pdf, png, norm: str = "H", hex20=None) -> None:
    """β_h against h per (space, k), one panel per element of ``beta`` and of the HEX20 table
    ``hex20`` where given (module docstring)."""
    import pandas as pd

    from ..style import case_style, h_ticks, ordered_cases, save_figure, style

    plt = _plt()
    if hex20 is not None:
        beta = pd.concat([beta, hex20_rows(hex20)], ignore_index=True)
    series = matching_series(beta, norm)
    elements = [e for e in ELEMENT_TITLES if e in set(series.element)]
    if not elements:
        raise ValueError(f"no matching-mesh {norm} rows without a kernel to draw")
    with style():
        fig, axes = plt.subplots(1, len(elements), figsize=(7.2, 4.2), sharey=True,
                                 layout="constrained", squeeze=False)
        for ax, element in zip(axes[0], elements):
            s = series[series.element == element]
            for case in ordered_cases(s.case.unique()):
                for k, g in s[s.case == case].groupby("k"):
                    g = g.sort_values("h")
                    ax.loglog(g.h, g.beta, label=f"{case}, k={k}", **case_style(case, k, markersize=4))
            h_ticks(ax, s.h, powers_of_two=False)
            ax.set_xlabel("$h = 1/N$")
            ax.set_title(ELEMENT_TITLES[element], fontsize=8)
        handles = {}  # one legend for the panels: a (space, k) drawn alike in each
        for ax in axes[0]:
            handles.update(zip(*reversed(ax.get_legend_handles_labels())))
        fig.legend(handles.values(), handles.keys(), fontsize=6, ncol=5, loc="outside lower center", frameon=False)
        axes[0][0].set_ylabel(r"$\beta_h$ ($H^{-1/2}_{00}(\Gamma)$)" if norm == "H" else r"$\beta_h$ ($L^2(\Gamma)$)")
        save_figure(fig, pdf, png)


def plot_face_studies(edge, alpha, modes, pdf, png) -> None:
    """Edge dropping, the α sweep and a worst mode in four panels (module docstring)."""
    from ..style import save_figure, style

    plt = _plt()
    with style():
        fig, axes = plt.subplots(2, 2, figsize=(7.2, 6.4), layout="constrained")
        (a, b), (c, d) = axes
        _edge_panels(a, b, edge)
        _alpha_panel(c, alpha)
        _mode_panel(fig, d, modes)
        save_figure(fig, pdf, png)


def _edge_panels(ax_beta, ax_cond, edge) -> None:
    """(a) β_H against θ; (b) cond₂(S) against θ, the plain basis solid, the κ-scaled dotted."""
    from ..style import case_style, ordered_cases

    for case in ordered_cases(edge.case.unique()):
        for k, g in edge[edge.case == case].groupby("k"):
            g = g.sort_values("theta")
            kw = case_style(case, k, markersize=3.5)
            ok = g[g.beta_H_resolved.astype(bool)]
            ax_beta.loglog(ok.theta, ok.beta_H, label=f"{case}, k={k}", **kw)
            if "cond_S" in g:
                ax_cond.loglog(g.theta, g.cond_S, label=f"{case}, k={k}", **kw)
            if "cond_S_kappa" in g:
                ax_cond.loglog(g.theta, g.cond_S_kappa, **dict(kw, linestyle=":", marker=None))
    ax_beta.set_xlabel(r"covered fraction $\theta$")
    ax_beta.set_ylabel(r"$\beta_h$ ($H^{-1/2}_{00}(\Gamma)$)")
    ax_beta.set_title(f"(a) edge dropping, N = {int(edge.N.max())}", fontsize=9)
    ax_cond.set_xlabel(r"covered fraction $\theta$")
    ax_cond.set_ylabel(r"cond$_2(S)$ (dotted: $\kappa$-scaled)")
    ax_cond.set_title("(b) conditioning of the multiplier block", fontsize=9)
    ax_cond.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)  # (a) and (b)


def _alpha_panel(ax, alpha) -> None:
    """(c) β_h against α, QUAD8 and QUAD9, H solid and L² dashed; α the element refuses
    (a corner weight ∫ N_k <= 0) drawn as crosses on the axis."""
    from ..style import NEUTRAL, OKABE_ITO

    colours = dict(zip(("QUAD8", "QUAD9"), (OKABE_ITO["vermillion"], OKABE_ITO["blue"])))
    for (element, norm), g in alpha.groupby(["element", "norm"]):
        g = g.sort_values("alpha")
        ok = g[g.accepted.astype(bool) & np.isfinite(g.beta)]
        colour = colours.get(element, NEUTRAL)
        ax.semilogy(ok.alpha, ok.beta, color=colour, marker="o", markersize=3.5,
                    linestyle="-" if norm == "H" else "--", label=f"TDUAL-Q{element[-1]}, {norm}")
        refused = g[~g.accepted.astype(bool)]
        if len(refused) and norm == "H":  # on the bottom of the axes: no β_h there
            ax.plot(refused.alpha, np.full(len(refused), 0.03), "x", color=colour, markersize=5,
                    transform=ax.get_xaxis_transform(), clip_on=False, label=f"{element}: refused")
    ax.axvline(POPP_ALPHA, color=NEUTRAL, lw=0.7, linestyle=":")
    ax.set_xlabel(r"$\alpha$ of the transformed dual basis")
    ax.set_ylabel(r"$\beta_h$")
    ax.set_title(f"(c) transformed duals, N = {int(alpha.N.max())}", fontsize=9)
    ax.legend(fontsize=6, loc="center right", bbox_to_anchor=(1.0, 0.57), frameon=False)


def _mode_panel(fig, ax, modes) -> None:
    """(d) the first worst mode of ``modes`` (a ``beta --worst-mode`` table) on Γ: on a face the
    sample values, interpolated linearly on their Delaunay triangles (a jump of a discontinuous
    mode shows as a narrow band between its two values); on a segment a curve."""
    first = modes.iloc[0]
    keys = [c for c in ("case", "multiplier_mesh", "c1", "c2", "norm") if c in modes]
    m = modes[(modes[keys] == first[keys]).all(axis=1)]
    title = f"(d) worst mode of {first['case']}" + (r", $\beta_h = 0$" if first["beta"] == 0 else
                                                    f", $\\beta_h$ = {first['beta']:.3g}")
    if "y" in m:
        points = ax.tripcolor(m.x.to_numpy(), m.y.to_numpy(), m.mu.to_numpy(), shading="gouraud", cmap="RdBu_r",
                              vmin=-1, vmax=1)
        ax.set_aspect("equal")
        ax.set_xlabel("$x$ on $\\Gamma$")
        ax.set_ylabel("$y$ on $\\Gamma$")
        fig.colorbar(points, ax=ax, shrink=0.8, label=r"$\mu_h$ (max $|\mu_h| = 1$)")
    else:
        ax.plot(m.x, m.mu, color="black", lw=1.0)
        ax.set_xlabel("$x$ on $\\Gamma$")
        ax.set_ylabel(r"$\mu_h$")
    ax.set_title(title, fontsize=9)
