"""The section "Certifying production codes", generated from the producers table.

Per producer: its own paragraph (``examples/producers/<code>/paper.tex``: what the code's
multiplier space is, what it does at Γ's ends, the fix a user can apply; written with the
exporter, no numbers in it), then the table of its certificates (verdict, kernel dimension
and β_h per level in each norm, matching and non-matching) and its claims' verdicts. A
producer not installed where the paper was built is one sentence with its install command
(its claims are NOT RUN); a sentence up front names the codes that ran and those that did not.
Last, the census (:func:`census_tex`, from ``results/tables/census.csv``): one line per code, space
and offset, the verdict against the prediction, the fix, and the worst modes of the UNSTABLE spaces
(``results/figures/census_modes.pdf``).
"""
from __future__ import annotations

import pandas as pd

from ..texformat import PaperTexError, fmt_fixed, latex_id

NEEDED = ("producer", "version", "space", "offset", "norm", "status", "verdict", "beta_levels", "kernel_levels",
          "h_levels", "install")


def _levels(row) -> str:
    """β_h per level (4 decimals; 0 on a level with a kernel)."""
    betas = str(row.beta_levels).split()
    kernels = str(row.kernel_levels).split()
    return ", ".join("0" if k != "0" else fmt_fixed(b, 4) for b, k in zip(betas, kernels))


def producer_table(rows: pd.DataFrame) -> str:
    """One producer's certificates: space, offset K, norm, verdict, kernel and β_h per level."""
    ok = rows[rows.status == "ok"]
    hs = str(ok.h_levels.iloc[0] if len(ok) else "").split()
    lines = [r"\begin{tabular}{lrllll}", r"\toprule",
             r"space & $K$ & norm & verdict & kernel & $\beta_h$, $1/h = "
             + ", ".join(f"{1 / float(h):g}" for h in hs) + r"$ \\", r"\midrule"]
    for r in rows.itertuples():
        if r.status != "ok":
            reason = str(r.status).removeprefix("refused: ").split(": ", 1)[-1]  # without the file name
            cells = [latex_id(r.space), str(r.offset), latex_id(r.norm), r"\multicolumn{3}{l}{refused: "
                     + latex_id(reason[:48]) + "}"]
        else:
            cells = [latex_id(r.space), str(r.offset), latex_id(r.norm), latex_id(r.verdict),
                     latex_id(" ".join(str(r.kernel_levels).split())), _levels(r)]
        lines.append(" & ".join(cells) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}"]
    return "\n".join(lines) + "\n"


def which_ran(table: pd.DataFrame) -> str:
    """One sentence: the codes that ran (with their versions) and those not installed."""
    names = list(dict.fromkeys(table.producer))
    missing = [n for n in names if (table[table.producer == n].status == "not installed").all()]
    ran = [rf"{latex_id(n)} {latex_id(table[table.producer == n].version.iloc[0])}" for n in names if n not in missing]
    if not ran:
        return ("None of the producers was installed where this paper was built, so none was run: "
                + ", ".join(latex_id(n) for n in missing) + ".")
    return ("Ran where this paper was built: " + ", ".join(ran)
            + ("; not installed, so not run: " + ", ".join(latex_id(n) for n in missing) if missing else "") + ".")


def _betas(cell: str) -> str:
    """β_h per level, two significant digits (a kernel's 0 printed 0)."""
    if cell == "-":
        return "-"
    return " ".join("0" if float(b) == 0 else f"{float(b):.2g}" for b in str(cell).split())


def _slope(r) -> str:
    if not pd.notna(r.slope):
        return "-"
    ci = f" [{fmt_fixed(r.slope_lo, 2)}, {fmt_fixed(r.slope_hi, 2)}]" if pd.notna(r.slope_lo) and pd.notna(r.slope_hi) else ""
    return fmt_fixed(r.slope, 2) + ci


def _verdict(r) -> str:
    """The verdict, a stabilised system's class (a C block: ``stabilisation``), and the prediction
    where it differs (or where there is none)."""
    stab = str(getattr(r, "stabilisation", "-"))
    out = latex_id(r.verdict) + ("" if stab in ("-", "none", "nan", "") else f"; {latex_id(stab)}")
    if r.predicted == "-":
        return out + " (no prediction)"
    return out + ("" if r.verdict == r.predicted else rf" (predicted {latex_id(r.predicted)})")


CENSUS_NEEDED = ("code", "version", "space", "offset", "norm", "verdict", "predicted", "kernel_vs_dim", "beta_levels",
                 "slope", "slope_lo", "slope_hi", "fix", "claim", "predicted_in")


CENSUS_WIDTHS = (("l", None), ("", 1.4), ("r", None), ("", 2.3), ("", 1.3), ("", 1.3), ("", 1.2), ("", 2.3),
                 ("l", None), ("l", None))
"""The census table's columns: (alignment, width in cm of a ragged paragraph column or None)."""


def _versions(census: pd.DataFrame) -> str:
    """Each code and the version it ran as, or that it did not run."""
    first = census.drop_duplicates("code")
    return ", ".join(f"{latex_id(r.code)} " + ("not installed" if r.status == "not installed" else latex_id(r.version))
                     for r in first.itertuples())


def census_tex(census: pd.DataFrame, panels) -> str:
    """The census subsection: its longtable and, where ``panels`` (the (code, space) the figure
    draws, :func:`~infsup_contact.report.figures.census.unstable_panels`) is not empty, the mode figure."""
    for col in CENSUS_NEEDED:
        if col not in census.columns:
            raise PaperTexError(f"census.csv lacks column {col!r}")
    out = [r"\subsection{The census}\label{sec:census}", "",
           r"""One line per code, example space and offset $K$ ($K=0$: matching meshes): the verdict in the
norm of its first column (the prediction beside it where they differ), the kernel of $B^T$ against
$\dim M_h$ (the multipliers certified, constrained rows removed) and $\beta_h$ per level, coarse to
fine, the slope of $\log\beta_h$ against $\log h$ (above a kernel: of the first non-zero
eigenvalue's root) with its confidence interval, what makes the space
stable (the prediction's \texttt{fix}), the claim's verdict, and the commit since which
\texttt{config/config.yaml} holds the prediction: predictions are committed before their first run,
and a verdict changed afterwards is dated by its own commit. Generated: \texttt{results/tables/census.csv}.""",
           "", r"{\scriptsize\setlength{\tabcolsep}{1.5pt}",
           # ragged columns of fixed widths: the table fits the text width (a4, 2.5 cm margins)
           r"\begin{longtable}{" + "".join(rf">{{\raggedright\arraybackslash}}p{{{w}cm}}" if w else c
                                          for c, w in CENSUS_WIDTHS) + "}",
           r"\caption{The census of the producers' examples (\texttt{results/tables/census.csv}); versions: "
           + _versions(census) + r".}\label{tab:census}\\",
           r"\toprule",
           r"code & space & $K$ & verdict & kernel / $\dim M_h$ & $\beta_h$ & slope [CI] & fix & claim & predicted in \\",
           r"\midrule", r"\endhead", r"\bottomrule", r"\endfoot"]
    for r in census.itertuples():
        cells = [latex_id(r.code), latex_id(r.space), str(r.offset), _verdict(r) + ("" if r.norm == "H" else f" ({latex_id(r.norm)})"),
                 latex_id(r.kernel_vs_dim), latex_id(_betas(r.beta_levels)), _slope(r), latex_id(r.fix),
                 latex_id(r.claim), latex_id(str(r.predicted_in).split()[0])]
        out.append(" & ".join(cells) + r" \\")
    out += [r"\end{longtable}}", ""]
    if len(panels):
        out += [r"\begin{figure}[ht]\centering",
                r"\includegraphics[width=\linewidth,height=0.45\textheight,keepaspectratio]{census_modes.pdf}",
                r"\caption{The worst mode $\mu_h$ on $\Gamma$ of each UNSTABLE space of the census (norm $H$), on its "
                r"finest level: a kernel vector of $B^T$ where the kernel is not empty, else the eigenvector of "
                r"$\beta_h^2$; normalised to $\max|\mu_h| = 1$; matching meshes solid, non-matching dashed. "
                + "Panels: " + ", ".join(f"{latex_id(c)} {latex_id(s)}" for c, s in panels) + ".}",
                r"\label{fig:census-modes}", r"\end{figure}", ""]
    return "\n".join(out) + "\n"


def producers_tex(table: pd.DataFrame, claims: pd.DataFrame, paragraphs: dict, census: pd.DataFrame | None = None,
                  panels=()) -> str:
    """The whole section; ``paragraphs``: producer name → its LaTeX paragraph (or absent);
    ``census`` and ``panels``: :func:`census_tex`'s, last (none without a census)."""
    for col in NEEDED:
        if col not in table.columns:
            raise PaperTexError(f"producers.csv lacks column {col!r}")
    out = [r"% Generated by infsup_contact.report.sections.producers (rule producers_paper): do not edit.",
           r"\section{Certifying production codes}\label{sec:producers}", "",
           r"""\texttt{infsup-contact verdict --system} certifies the saddle-point systems another code
assembles. Each producer below is an exporter run by that code's own interpreter: it assembles
the two membranes of Section~\ref{sec:model} with the code's own elements and interface
coupling on $N$ segments of $\Omega_2$ and $N+K$ of $\Omega_1$ along $\Gamma$ ($K=0$:
matching), and writes $A$, $B$ and the $L^2$ mass of its multipliers exactly as the code
assembles them (its quadrature, its Dirichlet rows, its scale factors), with a description of
the multiplier basis on $\Gamma$ from which the certifier assembles the
$H^{-1/2}_{00}(\Gamma)$ Gram itself (norm $H$). The $L^2$ and $h$-weighted $L^2$ rows certify
copies with the norm changed; by Remark~3.1 a stable space is UNSTABLE in $L^2$.""", "", which_ran(table), ""]
    for name, rows in table.groupby("producer", sort=False):
        if (rows.status == "not installed").all():
            n = int(claims.claim_id.str.startswith(f"producer-{name}-").sum())
            out += [rf"\paragraph{{{latex_id(name)}}} not installed where this paper was built "
                    rf"(install: \texttt{{{latex_id(rows.install.iloc[0])}}}): nothing of it was run"
                    + (rf", and its {n} predicted claims are \verdictfmt{{NOT RUN}} in the ledger." if n else "."),
                    ""]
            continue
        out += [rf"\paragraph{{{latex_id(name)} {latex_id(rows.version.iloc[0])}}}", paragraphs.get(name, ""), "",
                r"\begin{table}[ht]\centering\small", producer_table(rows),
                rf"\caption{{{latex_id(name)} {latex_id(rows.version.iloc[0])}: the certificates of its exports. "
                r"Kernel: the dimension of the kernel of $B^T$ the certifier decided per level.}",
                rf"\label{{tab:producer-{latex_id(name)}}}", r"\end{table}", ""]
        mine = claims[claims.claim_id.str.startswith(f"producer-{name}-")]
        if len(mine):
            out += ["Its claims (predicted from the theorems and remarks of Sections 4--5 and the code's documented space, config/config.yaml): "
                    + "; ".join(rf"\texttt{{{latex_id(c.space_id)}}} {latex_id(c.verdict)}"
                                for c in mine.assign(space_id=mine.claim_id.str[len(f"producer-{name}-"):]).itertuples())
                    + ".", ""]
    if census is not None:
        out.append(census_tex(census, panels))
    return "\n".join(out) + "\n"
