"""The generated subsection of a model of the model table (:mod:`infsup_contact.plans.beta`).

One page per model: what was run, how many of its claims came out as predicted, and its β_h on
matching meshes in both norms (rows: norm, element, k, case; columns: N). A pure function of the
model's β table and claims; ``paper/paper.tex`` reads ``model_sections.tex``, which
:func:`sections_index_tex` writes as one ``\\input`` per such model.
"""
from __future__ import annotations

import pandas as pd

from .blocks import n_as_predicted, predicted
from .templates import beta_by_mesh_table
from ..texformat import PaperTexError, case_order, fmt_sci, latex_escape, latex_id

def matching_beta_table(beta: pd.DataFrame) -> str:
    """Tabular of β_h on matching meshes: rows (norm, element, k, case), columns N
    (:func:`~.templates.beta_by_mesh_table`)."""
    b = beta[beta.N1 == beta.N2]
    if b.empty:
        raise PaperTexError("the model's β table has no matching rows")
    return beta_by_mesh_table(b, sorted({int(n) for n in b.N2}), ("element", "k"), ("element", "$k$", "case"),
                              lambda key: [latex_escape(key[0]), str(key[1]), latex_id(key[2])])


def model_section_tex(name: str, entry: dict, beta: pd.DataFrame, claims: pd.DataFrame) -> str:
    """The subsection of the model-table entry ``name`` (module docstring)."""
    checked, agree = predicted(claims), n_as_predicted(claims)
    model = latex_id(str(beta.model.iloc[0]))
    return "\n".join([
        rf"\subsection{{The model \texttt{{{latex_id(name)}}}}}\label{{sec:model-{name}}}",
        rf"Model \texttt{{{model}}} of the model table (\texttt{{config: models.{latex_id(name)}}}): $\beta_h$ "
        rf"of {len(set(beta.case))} multiplier spaces, $k \in \{{{', '.join(map(str, sorted(set(beta.k))))}\}}$, "
        rf"{len(beta)} rows. Of its {len(claims)} ledger claims, {len(checked)} carry a prediction and "
        rf"{agree} came out as predicted.{_pair_note(beta)}",
        r"\begin{center}", r"\small", matching_beta_table(beta), r"\end{center}", ""])


def _pair_note(beta: pd.DataFrame) -> str:
    """What the entry of a Petrov–Galerkin pair is (:mod:`infsup_contact.solvers.petrov_galerkin`), where the
    table has one; empty otherwise."""
    from ...discretization.spaces.registry import SPACES

    pairs = [SPACES[c] for c in dict.fromkeys(beta.case) if c in SPACES and SPACES[c].petrov_galerkin]
    if not pairs:
        return ""
    named = ", ".join(rf"\texttt{{{latex_id(p.id)}}} (trial \texttt{{{latex_id(p.trial_space)}}}, test "
                      rf"\texttt{{{latex_id(p.test_space)}}})" for p in pairs)
    return (rf" For the Petrov--Galerkin pairs {named} the entry is $\sqrt{{\gamma_h}}$, "
            r"$\gamma_h = \sigma_{\min}(L_N^{-1} B_N A^{-1} B_M^T L_M^{-T})$ with $G = L L^T$ the Gram matrices "
            r"of trial space $M$ and test space $N$: $\beta_h$ itself when $N = M$.")


def sections_index_tex(names) -> str:
    """``model_sections.tex``: one ``\\input`` per generated model subsection (empty without any)."""
    return "".join(rf"\input{{{name}}}" + "\n" for name in names)


VERDICT_MARK = {"STABLE": "", "UNSTABLE": r"$^{u}$", "INCONCLUSIVE": r"$^{?}$"}
"""How a cell of the arc's table marks its series' verdict (stable: no mark)."""


def arc_beta_table(beta: pd.DataFrame, verdicts: pd.DataFrame, coupling: str, series: str) -> str:
    """Tabular of β_h (H norm) on the finest pair of ``series``: rows case, columns R, each cell
    marked with the series' verdict at that radius (u unstable, ? undecided)."""
    b = beta[(beta.coupling == coupling) & (beta.series == series) & (beta.norm == "H")]
    b = b[b.N2 == b.N2.max()]
    v = verdicts[(verdicts.coupling == coupling) & (verdicts.series == series) & (verdicts.norm == "H")]
    kappas = sorted(set(b.curvature), reverse=True)  # R ascending, ∞ last
    head = " & ".join(["case"] + [r"$R=\infty$" if c == 0 else f"$R={1 / c:g}$" for c in kappas])
    lines = [r"\begin{tabular}{l" + "r" * len(kappas) + "}", r"\hline", head + r" \\", r"\hline"]
    for case in case_order(set(b.case)):
        cells = []
        for c in kappas:
            cell = b[(b.case == case) & (b.curvature == c)]
            mark = v[(v.case == case) & (v.curvature == c)].verdict
            cells.append(fmt_sci(float(cell.beta.iloc[0]), 3) + (VERDICT_MARK[mark.iloc[0]] if len(mark) else ""))
        lines.append(" & ".join([latex_id(case)] + cells) + r" \\")
    return "\n".join(lines + [r"\hline", r"\end{tabular}"])


def arc_patch_table(patch: pd.DataFrame) -> str:
    """Tabular of the patch test's max |λ_h − λ|/λ on the finest pair: rows (case, k), columns
    (R, coupling), R = ∞ with the exact coupling first."""
    p = patch[patch.N2 == patch.N2.max()]
    runs = [(0.0, "exact")] + [(c, cp) for c in sorted(set(p.curvature[p.curvature > 0])) for cp in ("exact", "projection")
                               if ((p.curvature == c) & (p.coupling == cp)).any()]
    head = " & ".join(["case", "$k$"] + [(r"$R=\infty$" if c == 0 else f"$R={1 / c:g}$") + (", proj." if cp == "projection"
                                                                                          else "") for c, cp in runs])
    lines = [r"\begin{tabular}{lr" + "r" * len(runs) + "}", r"\hline", head + r" \\", r"\hline"]
    for case in case_order(set(p.case)):
        for k in sorted(set(p.k[p.case == case])):
            cells = [p[(p.case == case) & (p.k == k) & (p.curvature == c) & (p.coupling == cp)].lambda_max_rel_error
                     for c, cp in runs]
            lines.append(" & ".join([latex_id(case), str(k)] + [fmt_sci(float(v.iloc[0]), 2) if len(v) else "--"
                                                                 for v in cells]) + r" \\")
    return "\n".join(lines + [r"\hline", r"\end{tabular}"])


GEOMETRY_TEX = {
    None: (r"The curved segment",
           r"$\Gamma$ is the arc of radius $R$ and length 1 between $\Omega_1=\{R-1<r<R\}$ and "
           r"$\Omega_2=\{R<r<R+1\}$, $0<\theta<1/R$: each body is the paper's mesh of its square mapped by polar "
           r"coordinates and curved isoparametrically at its own degree, so that $R=\infty$ is the paper's "
           r"segment. Everything on $\Gamma$ is parametrized by arc length; the $H^{-1/2}_{00}$ norm is the "
           r"segment's in that parameter, an equivalent norm of the arc's, exact as $R\to\infty$."),
    "hex": (r"The curved face",
            r"$\Gamma$ is the part $r=R$, $0<\theta<1/R$, $0<y<1$ of a cylinder between the 3D membranes "
            r"$\Omega_1=\{R-1<r<R\}$ and $\Omega_2=\{R<r<R+1\}$ on hexahedra: each body is the face study's box "
            r"mapped by cylindrical coordinates and curved isoparametrically at its own degree, so that $R=\infty$ "
            r"is the flat face. $\Gamma$ is parametrized by (arc length, $y$); the $H^{-1/2}_{00}$ norm is the "
            r"unit square's in those parameters, an equivalent norm, exact as $R\to\infty$."),
}
"""Title and geometry paragraph of a curved Γ's subsection, by the bodies' element (None: the 2D membranes)."""


def arc_section_tex(name: str, beta: pd.DataFrame, verdicts: pd.DataFrame, claims: pd.DataFrame,
                    patch: pd.DataFrame | None = None, element: str | None = None, figure: str | None = None) -> str:
    """The subsection of the arc study ``name`` (:mod:`infsup_contact.plans.arc`): what was run, the
    claims, and β_h of the finest non-matching pair per coupling and radius."""
    checked, agree = predicted(claims), n_as_predicted(claims)
    series = [s for s in dict.fromkeys(beta.series) if (beta[beta.series == s].N1 != beta[beta.series == s].N2).any()]
    shown = series[0] if series else beta.series.iloc[0]
    pair = beta[beta.series == shown].sort_values("N2").iloc[-1]
    couplings = [c for c in ("exact", "projection") if (beta.coupling == c).any()]
    radii = sorted({1 / c for c in beta.curvature if c > 0})
    title, geometry = GEOMETRY_TEX[element]
    text = [rf"\subsection{{{title} \texttt{{{latex_id(name)}}}}}\label{{sec:model-{name}}}",
            geometry + r" The "
            r"\emph{exact} coupling maps both traces to $\Gamma$ by arc length; the \emph{projection} integrates "
            r"on the discretized side that carries $G_h$ and evaluates the other side along its averaged "
            r"nodal normal, as mortar codes do. "
            rf"Radii $R\in\{{{', '.join(f'{r:g}' for r in radii)}, \infty\}}$, $k\in\{{{', '.join(map(str, sorted(set(beta.k))))}\}}$, "
            rf"{len(set(beta.case))} spaces, {len(beta)} rows. Of the study's {len(claims)} ledger claims, "
            rf"{len(checked)} carry a prediction and {agree} came out as predicted.", ""]
    for coupling in couplings:
        text += [r"\begin{center}", r"\small",
                 rf"$\beta_h$ ($H^{{-1/2}}_{{00}}$ norm), {coupling} coupling, $N_1{{:}}N_2 = "
                 rf"{int(pair.N1)}{{:}}{int(pair.N2)}$ (series \texttt{{{latex_id(shown)}}}; "
                 r"$^{u}$ unstable, $^{?}$ undecided over the series)\\[2pt]",
                 arc_beta_table(beta, verdicts, coupling, shown), r"\end{center}", ""]
    if patch is not None and len(patch):
        last = patch.sort_values("N2").iloc[-1]
        text += [r"The patch test on the arc (uniform normal pressure $\lambda=-c_1\partial_r u_1$; $u_1=0$ on $r=R-1$, "
                 r"$u_2=-\delta$ on $r=R+1$, the radial sides natural): the solution $a+b\ln r$ is not in $V_h$, so no "
                 r"space reproduces $\lambda$ at finite $R$; the spaces holding the constants converge and those "
                 r"without keep an $O(1)$ error at $\Gamma$'s ends. Max $|\lambda_h-\lambda|/\lambda$ on "
                 rf"$N_1{{:}}N_2 = {int(last.N1)}{{:}}{int(last.N2)}$:",
                 r"\begin{center}", r"\small", arc_patch_table(patch), r"\end{center}", ""]
    if figure:
        text += [r"\begin{figure}[htbp]", r"\centering",
                 rf"\includegraphics[width=\linewidth,keepaspectratio]{{{figure}.pdf}}",
                 r"\caption{The curved segment. (a) $\beta_h$ ($H^{-1/2}_{00}$) against $h$ on the pairs $N{:}N+1$, "
                 r"the flat segment dashed, the most curved arc solid: curvature moves the stable spaces a little "
                 r"and leaves the unstable ones falling. (b) The patch test on that arc: the spaces holding the "
                 r"constants converge like $h^2$. (c) The projection's worst mode of a space with end modes on the "
                 r"flat segment (config figures.arc\_mode), lifted to $\beta_h>0$.}"
                 rf"\label{{fig:{figure}}}", r"\end{figure}", ""]
    return "\n".join(text)
