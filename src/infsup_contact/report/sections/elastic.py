"""The elastic section's generated files (paper/elastic.tex): macros and three tables, each
declared through the section templates (:mod:`.templates`, :mod:`.sections`).

Pure functions from the elastic tables (results/tables/elastic_*.csv, the elastic claims and
results/benchmarks/elastic_beta.csv) to LaTeX text; ``workflow/scripts/model_paper.py``
reads and writes (plans/elastic.py). Macro names start with ``elastic`` (letters only, :func:`macro_name`), so
they stay apart from the main paper's generated namespace.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
import pandas as pd

from .blocks import check_section_tex, claim_count_macros, section_macros_tex
from .templates import (Group, at, beta_cell, blank, body_lines, case_keys, case_table, error_cells,
                        head_lines, multicolumn, tabular)
from ..texformat import case_order, fmt_fixed, fmt_int, fmt_sci, latex_id
from ..texnames import Macro, _k, macro_name

FAMILIES = ("structured", "perturbed", "unstructured")
"""The mesh families of the β_h table, in its row order."""
PATCH_ERRORS = ("lambda_max_rel_error", "lambda_end_rel_error", "lambda_middle_rel_error", "u_max_rel_error")
"""The patch table's error columns (elastic_patch.csv)."""


def _name(*labels) -> str:
    return macro_name("elastic", *labels)


def _slope(x, y) -> float:
    return float(np.polyfit(np.log(np.asarray(x, float)), np.log(np.asarray(y, float)), 1)[0])


def elastic_macros(beta, sweep, patch, hertz, claims, speed, nu_slope_cases=None) -> list[Macro]:
    """Every number of paper/elastic.tex. ``nu_slope_cases``: the spaces whose slope of log β_h
    against log(1 − 2ν) gets a macro (config key figures.nu_slope_cases; None: every case of
    the sweep without a kernel). The patch errors are those of the spaces whose M_h contains the
    constants (``SpaceSpec.contains_constants``, registry): the others fail by design."""
    from ...discretization.spaces.registry import SPACES

    out = claim_count_macros(claims, _name, "elastic_claims.csv")
    h = beta[(beta.norm == "H")]
    m = h[h.N1 == h.N2]
    out += [Macro(_name("Nu"), f"{beta.nu.iloc[0]:g}", "elastic_beta.csv: nu"),
            Macro(_name("FinestN"), fmt_int(m.N2.max()), "elastic_beta.csv: max matching N2"),
            Macro(_name("CoarsestN"), fmt_int(m.N2.min()), "elastic_beta.csv: min matching N2"),
            Macro(_name("NRows"), fmt_int(len(beta) + len(sweep)), "elastic_beta.csv + elastic_nu_sweep.csv: rows")]
    nok = beta[beta.kernel_dim_membranes == 0]
    ratio = nok.beta / nok.beta_membranes
    out += [Macro(_name("RatioMin"), fmt_fixed(ratio.min(), 2), "elastic_beta.csv: min beta/beta_membranes"),
            Macro(_name("RatioMax"), fmt_fixed(ratio.max(), 2), "elastic_beta.csv: max beta/beta_membranes")]
    fin = sweep[sweep.N2 == sweep.N2.max()]
    for (case, k), g in fin[fin.kernel_dim == 0].groupby(["case", "k"]):
        g = g[g.nu >= 0.49].sort_values("nu")
        if len(g) >= 2 and (nu_slope_cases is None or case in nu_slope_cases):
            out.append(Macro(_name("NuSlope", case, _k(k)), fmt_fixed(_slope(1 - 2 * g.nu, g.beta), 3),
                             f"elastic_nu_sweep.csv: polyfit slope of log beta vs log(1-2nu), {case}, k={k}"))
    top = fin[(fin.nu == fin.nu.max()) & (fin.kernel_dim == 0)]
    out += [Macro(_name("NuMax"), f"{fin.nu.max():g}", "elastic_nu_sweep.csv: max nu"),
            Macro(_name("BetaAtNuMaxMin"), fmt_fixed(top.beta.min(), 4), "elastic_nu_sweep.csv: min beta at max nu"),
            Macro(_name("BetaAtNuMaxMax"), fmt_fixed(top.beta.max(), 4), "elastic_nu_sweep.csv: max beta at max nu")]
    constants = np.array([SPACES[c].contains_constants(int(k)) for c, k in zip(patch.case, patch.k)], dtype=bool)
    good = patch[constants]
    but = "cases but " + ", ".join(dict.fromkeys(patch.case[~constants])) if (~constants).any() else "every case"
    out += [Macro(_name("PatchLambdaErr"), fmt_sci(good.lambda_max_rel_error.max(), 2),
                  f"elastic_patch.csv: max lambda error, {but}"),
            Macro(_name("PatchUErr"), fmt_sci(good.u_max_rel_error.max(), 2), f"elastic_patch.csv: max u error, {but}"),
            Macro(_name("PatchNPass"), fmt_int(int(patch.groupby(["case", "k"]).passes.all().sum())),
                  "elastic_patch.csv: (case, k) passing on every pair"),
            Macro(_name("PatchNSeries"), fmt_int(patch.groupby(["case", "k"]).ngroups), "elastic_patch.csv: (case, k)")]
    mod = hertz[hertz.study == "modeling"].sort_values("d")
    if len(mod):
        out += [Macro(_name("HertzErrSmall"), fmt_fixed(100 * mod.p_max_rel_error.iloc[0], 1),
                      "elastic_hertz.csv: modeling p_max error (%), smallest d"),
                Macro(_name("HertzErrLarge"), fmt_fixed(100 * mod.p_max_rel_error.iloc[-1], 1),
                      "elastic_hertz.csv: modeling p_max error (%), largest d"),
                Macro(_name("HertzAWSmall"), fmt_fixed(mod.hertz_a.iloc[0], 3), "elastic_hertz.csv: a/W, smallest d"),
                Macro(_name("HertzAWLarge"), fmt_fixed(mod.hertz_a.iloc[-1], 3), "elastic_hertz.csv: a/W, largest d"),
                Macro(_name("HertzModelN"), fmt_int(mod.N.iloc[0]), "elastic_hertz.csv: modeling N")]
    disc = hertz[hertz.study == "discretization"]
    if len(disc):
        out += [Macro(_name("HertzNRef"), fmt_int(disc.N_ref.iloc[0]), "elastic_hertz.csv: N_ref"),
                Macro(_name("HertzD"), f"{disc.d.iloc[0]:g}", "elastic_hertz.csv: d"),
                Macro(_name("HertzR"), f"{disc.R.iloc[0]:g}", "elastic_hertz.csv: R")]
    for k, g in speed[speed.route.isin(["ours", "ours_core"])].groupby("k"):
        for route, r in g.groupby("route"):
            out.append(Macro(_name("Speed", route.replace("_", " "), _k(k)), fmt_fixed(r.ratio_to_limit.max(), 1),
                             f"elastic_beta.csv (benchmarks): {route}/limit, k={k}"))
    out.append(Macro(_name("SpeedN"), fmt_int(speed.N.max()), "elastic_beta.csv (benchmarks): N"))
    return out


def elastic_macros_tex(macros: list[Macro]) -> str:
    """The section's macro file (:func:`~.sections.section_macros_tex`)."""
    return section_macros_tex(macros, "elastic", "infsup_contact.report.sections.elastic (rule elastic_paper)")


def elastic_beta_table(beta: pd.DataFrame, sweep: pd.DataFrame) -> str:
    """Rows (family, case), columns k: β_h on the finest matching mesh and on the finest
    non-matching pair ("0 [d]": a d-dimensional kernel); then β_h of the ν sweep on the finest
    structured mesh, rows (k, case), columns ν."""
    h = beta[beta.norm == "H"]
    m, nm = h[h.N1 == h.N2], h[h.N1 != h.N2]
    ks = sorted(int(k) for k in set(h.k))
    meshes = [(m[m.N2 == m.N2.max()], rf"$N_1=N_2={int(m.N2.max())}$")]
    if len(nm):
        pair = nm.sort_values("N2").iloc[-1]
        meshes.append((nm[(nm.N1 == pair.N1) & (nm.N2 == pair.N2)],
                       rf"$N_1{{:}}N_2={int(pair.N1)}{{:}}{int(pair.N2)}$"))
    fin = sweep[sweep.N2 == sweep.N2.max()]
    nus = sorted(set(fin.nu))
    width = max(len(ks) * len(meshes), len(nus))  # the value columns both parts share
    groups = [Group(tuple(rf"$k={k}$" for k in ks), _mesh_cells(rows, ks), title) for rows, title in meshes]
    groups.append(blank(width - len(ks) * len(meshes)))
    sweep_groups = [Group((), lambda key: [beta_cell(at(fin[(fin.k == key[0]) & (fin.case == key[1])], "nu", v), True)
                                           for v in nus]), blank(width - len(nus))]
    note = rf"$\nu \to 1/2$, structured, $N={int(fin.N2.max())}$; columns: " + ", ".join(rf"$\nu={v:g}$" for v in nus)
    families = [f for f in FAMILIES if f in set(m.family)]
    return tabular("ll" + "r" * width, head_lines(("family", "case"), groups),
                   [body_lines(case_keys(m, "family", order=families),
                               lambda key: [f"{key[0][:6]}.", latex_id(key[1])], groups),
                    [multicolumn(2 + width, note, "l") + r" \\"],
                    body_lines(case_keys(fin, "k"), lambda key: [rf"$k={key[0]}$", latex_id(key[1])], sweep_groups)])


def _mesh_cells(rows: pd.DataFrame, ks) -> Callable:
    """key (family, case) → β_h per k on one mesh (:func:`~.templates.beta_cell`, with its kernel)."""
    return lambda key: [beta_cell(rows[(rows.family == key[0]) & (rows.case == key[1]) & (rows.k == k)], True)
                        for k in ks]


def elastic_patch_table(patch: pd.DataFrame) -> str:
    """Rows (case, k): passes on every pair, max relative errors of λ_h (all, end intervals,
    middle half) and of u_h, kernel dimension."""
    pairs = ", ".join(f"{a}:{b}" for a, b in patch[["N1", "N2"]].drop_duplicates().itertuples(index=False))
    keys = [(case, k) for case in case_order(patch.case.unique()) for k in sorted(set(patch[patch.case == case].k))]
    rows = lambda key: patch[(patch.case == key[0]) & (patch.k == key[1])]  # noqa: E731
    groups = [Group(("pass",), lambda key: ["yes" if rows(key).passes.astype(bool).all() else "no"]),
              Group((r"$\max|\lambda_h-p|/p$", "end int.", "middle", r"$\max|u_h-u|/\delta$"),
                    lambda key: error_cells(rows(key), PATCH_ERRORS))]
    return case_table("llcrrrr", ("case", "$k$"), lambda key: [latex_id(key[0]), str(key[1])], groups, [keys],
                      head_after=[multicolumn(7, f"pairs $N_1{{:}}N_2$ = {pairs}", "l") + r" \\"])


def elastic_hertz_table(hertz: pd.DataFrame) -> str:
    """Discretization study: per (k, case) the fitted energy-error slope and, per mesh, the
    energy error, p_max error and oscillation; modeling study: a/W and the errors vs Hertz."""
    d = hertz[hertz.study == "discretization"]
    ns = sorted(int(n) for n in set(d.N))
    def rows(key):
        return d[(d.k == key[0]) & (d.case == key[1])].set_index("N").sort_index()

    def per_mesh(head, column, fmt):
        return Group(tuple(f"{head} {n}" for n in ns), lambda key: [fmt(rows(key)[column][n], 2) for n in ns])

    groups = [Group(("slope",), lambda key: [fmt_fixed(-_slope(rows(key).index.to_numpy(float),
                                                                rows(key).energy_error), 2)]),
              per_mesh("$e_a$", "energy_error", fmt_sci), per_mesh("$e_p$", "p_max_rel_error", fmt_sci),
              per_mesh("osc", "oscillation", fmt_fixed)]
    blocks = [body_lines(case_keys(d, "k"), lambda key: [str(key[0]), latex_id(key[1])], groups)]
    mod = hertz[hertz.study == "modeling"].sort_values("d")
    if len(mod):
        blocks += [[multicolumn(2 + 1 + 3 * len(ns), rf"modeling error vs plane-strain Hertz "
                                rf"({latex_id(mod.case.iloc[0])}, $k={int(mod.k.iloc[0])}$, $N={int(mod.N.iloc[0])}$): "
                                r"$a/W$, $e_p$, half-width error", "l") + r" \\"],
                   [rf"\multicolumn{{2}}{{l}}{{$d={r.d:g}$}} & {fmt_fixed(r.hertz_a, 3)} & "
                    f"{fmt_sci(r.p_max_rel_error, 2)} & {fmt_sci(r.half_width_rel_error, 2)}"
                    + " &" * (3 * len(ns) - 2) + r" \\" for _, r in mod.iterrows()]]
    return tabular("ll" + "r" * (1 + 3 * len(ns)), head_lines(("$k$", "case"), groups), blocks)


def elastic_paper_files(beta, sweep, patch, hertz, claims, speed, nu_slope_cases=None) -> dict[str, str]:
    """Every generated file of the elastic section (name → text); ``nu_slope_cases``: see
    :func:`elastic_macros`."""
    return {"elastic_macros.tex": elastic_macros_tex(elastic_macros(beta, sweep, patch, hertz, claims, speed,
                                                                    nu_slope_cases)),
            "elastic_beta_table.tex": elastic_beta_table(beta, sweep),
            "elastic_patch_table.tex": elastic_patch_table(patch),
            "elastic_hertz_table.tex": elastic_hertz_table(hertz)}


def check_elastic_tex(tex: str, files: dict[str, str]) -> None:
    """PaperTexError unless every \\elastic… macro and \\input of ``tex`` is generated."""
    check_section_tex(tex, files, "elastic")
