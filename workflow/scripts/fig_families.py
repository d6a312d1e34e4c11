"""Figure 4: mesh families and the choice of the multiplier mesh G_h.

Top: a structured, a perturbed and an unstructured matching pair and a perturbed
non-matching pair (drawn from ``infsup_contact.discretization.segment.meshes.mesh_pair``: mesh geometry only,
cheap). Below: β_h (H norm) of a stable case (T3) against h for each family (columns)
and k (rows): matching pairs N×N, and the non-matching pairs of the most frequent ratio
N1:N2 (3:2 in the configs) with each multiplier mesh omega2 / omega1 / union of the β
table. Where the union partition makes the stable T3 space fail, β_h falls towards 0.
"""
import sys

if "snakemake" in globals():  # run by Snakemake: threads and log before numpy loads
    sys.path.insert(0, "workflow/scripts")
    from _glue import limit_threads, log_to, read_table
    from infsup_contact.study.beta.selection import primary_rows

    limit_threads(snakemake.threads)  # noqa: F821
    log_to(snakemake.log[0])  # noqa: F821

from fractions import Fraction  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from infsup_contact.discretization.spaces.registry import REFERENCE_SPACE  # noqa: E402
from infsup_contact.report.style import (h_ticks, CASE_COLORS, LABELS, NEUTRAL, case_style, mesh_size,  # noqa: E402
                                     save_figure, style)

FAMILY_ORDER = ("structured", "perturbed", "unstructured")
#: multiplier mesh → (line style, marker fill, legend text)
GH_STYLE = {
    "omega2": ("-", "full", r"$G_h$ = trace of $\Omega_2$ (paper)"),
    "omega1": ("-.", "none", r"$G_h$ = trace of $\Omega_1$"),
    "union": (":", "none", r"$G_h$ = union of both traces"),
}
#: mesh panels: (title, family, N1, N2)
MESH_PANELS = (("structured", "structured", 8, 8), ("perturbed", "perturbed", 8, 8),
               ("unstructured", "unstructured", 8, 8), ("perturbed, non-matching", "perturbed", 12, 8))


def mesh_arrays(family: str, n1: int, n2: int, **kwargs):
    """[(points, triangles) of Ω1, (points, triangles) of Ω2] of a library mesh pair."""
    import ngsolve

    from infsup_contact.discretization.segment.meshes import mesh_pair

    out = []
    for mesh in mesh_pair(family, n1, n2, **kwargs):
        pts = np.array([v.point for v in mesh.vertices])
        tris = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ngsolve.VOL)])
        out.append((pts, tris))
    return out


def default_meshes(seed: int = 0, alpha: float = 0.2, panels=MESH_PANELS):
    """The mesh panels of the figure: [(title, N1, N2, mesh_arrays), ...]."""
    out = []
    for title, family, n1, n2 in panels:
        kw = {"seed": seed, "alpha": alpha} if family == "perturbed" else {}
        out.append((title, n1, n2, mesh_arrays(family, n1, n2, **kw)))
    return out


def _edges(tris):
    e = np.sort(np.vstack([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0)


def draw_mesh_pair(ax, pair, title, n1, n2):
    """Both meshes in one axes, Γ bold with its trace nodes from each side."""
    shades = ("#f2f2f2", "#ffffff")
    for (pts, tris), shade in zip(pair, shades):
        ax.tripcolor(pts[:, 0], pts[:, 1], tris, np.zeros(len(tris)), cmap=plt.matplotlib.colors.ListedColormap([shade]),
                     shading="flat", edgecolors="none")
        seg = pts[_edges(tris)]
        ax.add_collection(LineCollection(seg, colors=NEUTRAL, linewidths=0.35))
    ax.plot([0, 1], [1, 1], color="k", lw=1.8, solid_capstyle="butt", zorder=3)
    for (pts, _), dy, mk in zip(pair, (-0.035, 0.035), ("^", "v")):
        on = np.abs(pts[:, 1] - 1.0) < 1e-12
        ax.plot(pts[on, 0], np.full(on.sum(), 1.0 + dy), linestyle="none", marker=mk, markersize=2.2,
                color="k", zorder=4)
    ax.set_aspect("equal")
    ax.set_xlim(-0.02, 1.02)
    ax.set_ylim(-0.02, 2.02)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.grid(False)
    for s in ax.spines.values():
        s.set_visible(False)
    ax.set_title(f"{title}\n$N_1={n1}$, $N_2={n2}$", fontsize=8.5)
    ax.text(0.5, 0.5, r"$\Omega_1$", ha="center", va="center", fontsize=8,
            bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.8))
    ax.text(0.5, 1.5, r"$\Omega_2$", ha="center", va="center", fontsize=8,
            bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.8))


def select_family_beta(beta: pd.DataFrame, case: str = REFERENCE_SPACE, ks=(1, 2)) -> pd.DataFrame:
    """β_h rows of the lower panels: ``case``, H norm, first (c1, c2), k in ``ks``."""
    sel = beta[(beta.case == case) & (beta.norm == "H") & beta.k.isin(ks)]
    if sel.empty:
        raise ValueError(f"beta table has no rows for case {case}, norm H, k in {list(ks)}")
    c1, c2 = sel.iloc[0][["c1", "c2"]]
    sel = sel[(sel.c1 == c1) & (sel.c2 == c2)]
    return sel.assign(h=mesh_size(sel), ratio=[Fraction(int(a), int(b)) for a, b in zip(sel.N1, sel.N2)])


def main_ratio(sel: pd.DataFrame):
    """The non-matching ratio N1/N2 with the most mesh pairs (None without non-matching rows)."""
    nm = sel[sel.N1 != sel.N2]
    if nm.empty:
        return None
    counts = nm.groupby("ratio").N2.nunique()
    return counts.sort_values(ascending=False, kind="stable").index[0]


def plot_families(beta: pd.DataFrame, meshes, pdf, png, case: str = REFERENCE_SPACE) -> None:
    """Mesh panels (top) and β_h per family / multiplier mesh (bottom); save PDF+PNG."""
    sel = select_family_beta(beta, case)
    ks = sorted(sel.k.unique())
    fams = [f for f in FAMILY_ORDER if f in set(sel.family)] + sorted(set(sel.family) - set(FAMILY_ORDER))
    ratio = main_ratio(sel)
    with style():
        fig = plt.figure(figsize=(9.6, 3.5 + 2.4 * len(ks)), layout="constrained")
        top, bottom = fig.subfigures(2, 1, height_ratios=[3.5, 2.4 * len(ks)], hspace=0.02)
        for ax, (title, n1, n2, pair) in zip(top.subplots(1, len(meshes)), meshes):
            draw_mesh_pair(ax, pair, title, n1, n2)
        top.supxlabel(r"$\Gamma$ bold;  $\blacktriangle$ trace nodes of the $\Omega_1$ mesh,  "
                      r"$\blacktriangledown$ trace nodes of the $\Omega_2$ mesh", fontsize=8)
        axes = bottom.subplots(len(ks), len(fams), squeeze=False, sharex=True, sharey=True)
        ylo = max(sel.beta[sel.beta > 0].min() if (sel.beta > 0).any() else 1e-6, 1e-8) / 4
        for i, k in enumerate(ks):
            for j, fam in enumerate(fams):
                ax = axes[i, j]
                d = sel[(sel.k == k) & (sel.family == fam)]
                m = d[(d.N1 == d.N2) & (d.multiplier_mesh == d.multiplier_mesh.iloc[0])].sort_values("h")
                ax.plot(m.h, m.beta, **case_style(case, color="#9ecae1", markeredgecolor="#9ecae1", lw=3.0,
                                                  marker=None, zorder=1))
                if ratio is not None:
                    nm = d[d.ratio == ratio]
                    for mm in GH_STYLE:
                        g = nm[nm.multiplier_mesh == mm].sort_values("h")
                        if g.empty:
                            continue
                        ls, fill, _ = GH_STYLE[mm]
                        y = g.beta.clip(lower=ylo)
                        ax.plot(g.h, y, **case_style(case, linestyle=ls, fillstyle=fill, markersize=4.5, zorder=3))
                        if mm == "union" and g.beta.min() < 1e-2:
                            jmin = g.beta.values.argmin()
                            ax.annotate(r"union $G_h$: $\beta_h \to 0$", xy=(g.h.values[jmin], y.values[jmin]),
                                        xytext=(0.04, 0.2), textcoords="axes fraction", ha="left", va="center",
                                        fontsize=7.5, color=CASE_COLORS[case],
                                        arrowprops=dict(arrowstyle="->", color=CASE_COLORS[case], lw=0.7,
                                                        shrinkA=2, shrinkB=4))
                ax.set_xscale("log")
                ax.set_yscale("log")
                ax.set_ylim(bottom=ylo)
                if i == 0:
                    ax.set_title(fam)
                if j == 0:
                    ax.set_ylabel(rf"{case}, k = {k}:  $\beta_h$ (H)")
                if i == len(ks) - 1:
                    ax.set_xlabel(LABELS["h"])
        h_ticks(axes, sel.h)
        proxies = [Line2D([], [], **case_style(case, color="#9ecae1", lw=3.0, marker=None))]
        labels = ["matching $N_1=N_2$ (all $G_h$ coincide)"]
        if ratio is not None:
            for mm in GH_STYLE:
                if mm in set(sel.multiplier_mesh):
                    ls, fill, text = GH_STYLE[mm]
                    proxies.append(Line2D([], [], **case_style(case, linestyle=ls, fillstyle=fill)))
                    labels.append(f"$N_1:N_2$ = {ratio.numerator}:{ratio.denominator}, {text}")
        bottom.legend(proxies, labels, loc="outside lower center", ncol=2, handlelength=3.0, fontsize=7.5)
        save_figure(fig, pdf, png)


assert CASE_COLORS  # the shared map (used through case_style)

if "snakemake" in globals():
    p = snakemake.params  # noqa: F821
    plot_families(primary_rows(read_table(snakemake.input.beta, "beta")), default_meshes(p.seed, p.alpha),  # noqa: F821
                  snakemake.output.pdf, snakemake.output.png)  # noqa: F821
