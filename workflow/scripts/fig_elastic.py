"""Figure 9: the elastic scene. (a) β_h of the ν → 1/2 sweep against 1 − 2ν (finest mesh,
k = 1 and 2, every stable space) with a slope-1/2 triangle; (b) the Hertz scene's contact
pressure λ_h(x) for stable and unstable multipliers on one mesh, with plane-strain Hertz for
the measured resultant."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import limit_threads, log_to, read_table, register_user_spaces  # noqa: E402

limit_threads(1)
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821

import matplotlib.pyplot as plt  # noqa: E402

from infsup_contact.report.style import NEUTRAL, case_label, case_style, ordered_cases, save_figure, slope_triangle, style  # noqa: E402,E501
from infsup_contact.study.contact.registry import HERTZ  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821
sweep = read_table(inp.sweep, "elastic_beta")
prof = read_table(inp.profiles, "gamma_profiles")

with style():
    # legends below the panels: inside, they covered the curves of both
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(7.2, 4.0), layout="constrained")
    s = sweep[(sweep.N2 == sweep.N2.max()) & (sweep.kernel_dim == 0)]
    for case in ordered_cases(s.case.unique()):
        for k, g in s[s.case == case].groupby("k"):
            g = g.sort_values("nu")
            ax1.loglog(1 - 2 * g.nu, g.beta, label=case_label(case, k), **case_style(case, k, markersize=4))
    slope_triangle(ax1, 3e-4, 0.02, 0.5, decades=1.0, label="1/2")
    ax1.set_xlabel(r"$1 - 2\nu$")
    ax1.set_ylabel(r"$\beta_h$ (H norm)")
    ax1.set_title(f"(a) $\\nu \\to 1/2$, N = {int(s.N2.max())}", fontsize=9)
    ax1.legend(fontsize=6, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)
    lam = prof[prof.quantity == "lambda_h"]
    for (case, k), g in lam.groupby(["case", "k"], sort=False):
        kw = case_style(case, k)
        ax2.plot(g.x, g.value, color=kw["color"], linestyle=kw["linestyle"], lw=1.1, label=case_label(case, k))
    h = prof[prof.quantity == HERTZ.id]  # the Hertz pressure for the measured P (study/contact/hertz.py)
    ax2.plot(h.x, h.value, color=NEUTRAL, lw=0.8, linestyle=":", label="Hertz (measured P)")
    support = h[h.value > 0].x
    pad = 0.6 * (support.max() - support.min())
    ax2.set_xlim(support.min() - pad, support.max() + pad)
    ax2.set_xlabel(r"$x$ on $\Gamma$")
    ax2.set_ylabel(r"$\lambda_h$")
    ax2.set_title(f"(b) Hertz scene, N = {int(lam.N.iloc[0])}", fontsize=9)
    ax2.legend(fontsize=6, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)
    save_figure(fig, out.pdf, out.png)
