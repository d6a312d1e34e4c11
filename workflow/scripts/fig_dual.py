"""Figure 8: dual mortar multipliers against the paper's T3 (from results/tables only).

(a) β_h against h, H^{-1/2}_00 norm, structured matching meshes, G_h = trace of Ω2, every k of
the table; (b) λ_h along Γ for the scene figures.dual.scene (the Γ profiles of the
``dual_profiles`` job); (c) the energy error of the primary scene (contact.primary_scene) against h. Marker fill = k as in every
figure; colour and marker = the space (the registry's).
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
import pandas as pd  # noqa: E402

from infsup_contact.report.style import (LABELS, MEASURES, case_label, case_style, h_ticks,  # noqa: E402
                                         mesh_size, save_figure, style)


def select(beta, contact, gamma, cases, scene):
    """The rows of the three panels; a missing case or table part raises ValueError."""
    b = beta[(beta.family == "structured") & (beta.multiplier_mesh == "omega2") & (beta.N1 == beta.N2)
             & (beta.norm == "H") & beta.case.isin(cases)]
    if b.empty:
        raise ValueError(f"beta table has no structured/omega2/matching H rows for {cases}")
    c1, c2 = b.iloc[0][["c1", "c2"]]
    b = b[(b.c1 == c1) & (b.c2 == c2)]
    c = contact[(contact.scene == scene) & (contact.family == "structured") & contact.case.isin(cases)]
    lam = gamma[(gamma.quantity == "lambda") & gamma.case.isin(cases)]
    for name, frame in ((f"contact ({scene}, structured)", c), ("Γ profiles (lambda)", lam)):
        if frame.empty:
            raise ValueError(f"{name}: no rows for {cases}")
    return b.assign(h=mesh_size(b)), c.assign(h=mesh_size(c)), lam


def plot_dual(beta, contact, gamma, cases, pdf, png, scene, profile_scene) -> None:
    """``scene``: the contact scene of panel (c) (config contact.primary_scene); ``profile_scene``:
    the scene of the Γ profiles in (b) (figures.dual.scene)."""
    b, c, lam = select(beta, contact, gamma, cases, scene)
    with style():
        fig, (ax_b, ax_l, ax_e) = plt.subplots(1, 3, figsize=(11.0, 3.6), layout="constrained")
        for case in cases:
            for k, g in b[b.case == case].groupby("k"):
                g = g.sort_values("h")
                ax_b.plot(g.h, g.beta, label=case_label(case, k), **case_style(case, k))
            for k, g in c[c.case == case].groupby("k"):
                g = g.sort_values("h")
                ax_e.plot(g.h, g.energy_error, label=case_label(case, k), **case_style(case, k))
            g = lam[lam.case == case].sort_values("x")
            ax_l.plot(g.x, g.value, label=case_label(case, int(g.k.iloc[0])),
                      **case_style(case, int(g.k.iloc[0]), markevery=max(1, len(g) // 24)))
        for ax in (ax_b, ax_e):
            ax.set_xscale("log")
            ax.set_xlabel(LABELS["h"])
        h_ticks(ax_b, b.h)
        h_ticks(ax_e, c.h)
        ax_e.set_yscale("log")
        ax_b.set_ylabel(LABELS["beta_H"])
        ax_b.set_title("(a) inf-sup constant")
        ax_l.axhline(0.0, color="0.5", lw=0.6)
        ax_l.set_xlabel(LABELS["x"])
        ax_l.set_ylabel(r"$\lambda_h$")
        n = int(lam.N.iloc[0])
        ax_l.set_title(f"(b) $\\lambda_h$, {profile_scene} scene, $N={n}$")
        ax_e.set_ylabel(MEASURES["energy_error"][1])
        ax_e.set_title(f"(c) energy error, {scene} scene")
        ax_b.legend(fontsize=6.5, ncol=2)
        ax_l.legend(fontsize=6.5)
        save_figure(fig, pdf, png)


if "snakemake" in globals():
    inp = snakemake.input  # noqa: F821
    plot_dual(primary_rows(read_table(inp.beta, "beta")), read_table(inp.contact, "contact"), read_table(inp.gamma, "gamma_profiles"),
              snakemake.params.cases, snakemake.output.pdf, snakemake.output.png,  # noqa: F821
              snakemake.params.scene, snakemake.params.profile_scene)  # noqa: F821
