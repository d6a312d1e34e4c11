"""The paper's generated tables (LaTeX tabulars) and the row selections they share with the macros."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..study.beta.selection import primary_rows

from .sections.templates import beta_by_mesh_table
from .texformat import (LEDGER_VERDICTS, MEASURES, SPEED_COLUMNS, PaperTexError, _require, case_rank,
                        fmt_fixed, fmt_sci, latex_escape, latex_id)


def beta_default_rows(beta: pd.DataFrame) -> pd.DataFrame:
    """The paper's setting: G_h = trace of Ω2 (omega2), matching meshes, first (c1, c2) pair."""
    _require(beta, ["case", "k", "family", "N1", "N2", "multiplier_mesh", "c1", "c2", "norm", "beta",
                    "kernel_dim", "smallest_nonzero", "dim_M", "dim_W"], "beta.csv")
    beta = primary_rows(beta)
    b = beta[(beta.multiplier_mesh == "omega2") & (beta.N1 == beta.N2)]
    if b.empty:
        raise PaperTexError("beta.csv: no rows with multiplier_mesh=omega2 and N1 == N2")
    c1, c2 = b[["c1", "c2"]].iloc[0]
    return b[(b.c1 == c1) & (b.c2 == c2)]


def beta_table(beta: pd.DataFrame, ks=(1, 2, 3), even_only: bool = True) -> str:
    """Tabular of β_h (structured, omega2, matching, first c): rows (norm, k, case), columns N."""
    b = beta_default_rows(beta)
    b = b[(b.family == "structured") & b.k.isin(list(ks))]
    if b.empty:
        raise PaperTexError(f"beta.csv: no structured rows with k in {list(ks)}")
    ns = sorted({int(n) for n in b.N2 if (n % 2 == 0 or not even_only)})
    return beta_by_mesh_table(b, ns, ("k",), ("$k$", "case"), lambda key: [str(key[0]), latex_id(key[1])])


def rates_table(rates: pd.DataFrame, primary: str) -> str:
    """Tabular: slopes of the four error measures per (scene, case, k), structured family."""
    _require(rates, ["scene", "case", "k", "family", "measure", "slope", "stderr", "expected", "points"],
             "rates.csv")
    r = rates[rates.family == "structured"] if (rates.family == "structured").any() else rates
    slope = r.set_index(["scene", "case", "k", "measure"])
    cols = list(MEASURES)
    lines = [r"\begin{tabular}{llrrrrrr}", r"\toprule",
             r"scene & case & $k$ & expected & $\|u-u_h\|_a$ & $\|u-u_h\|_{L^2}$ & "
             r"$\|\lambda-\lambda_h\|_{L^2(\Gamma)}$ & $\|\lambda-\lambda_h\|_M$ \\", r"\midrule"]
    scenes = sorted(set(r.scene), key=lambda s: (s != primary, s))  # the primary scene first
    for i, scene in enumerate(scenes):
        if i:
            lines.append(r"\midrule")
        keys = r[r.scene == scene][["case", "k"]].drop_duplicates()
        keys = sorted(map(tuple, keys.values),
                      key=lambda ck: (int(ck[1]), case_rank(ck[0]), ck[0]))
        for case, k in keys:
            exp = slope.loc[(scene, case, k, "energy_error"), "expected"] \
                if (scene, case, k, "energy_error") in slope.index else np.nan
            cells = []
            for m in cols:
                if (scene, case, k, m) in slope.index:
                    cells.append(fmt_fixed(slope.loc[(scene, case, k, m), "slope"], 2))
                else:
                    cells.append("--")
            lines.append(f"{latex_id(scene, 'rates.csv scene')} & {latex_id(case)} & {int(k)} & "
                         f"{'--' if pd.isna(exp) else format(float(exp), 'g')} & " + " & ".join(cells) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}", ""]
    return "\n".join(lines)


def _claims_checked(claims: pd.DataFrame) -> pd.DataFrame:
    _require(claims, ["claim_id", "paper_ref", "statement", "evidence", "verdict", "predicted"], "claims.csv")
    bad = sorted(set(claims.verdict) - set(LEDGER_VERDICTS))
    if bad:
        raise PaperTexError(f"claims.csv: unknown verdict(s) {bad}")
    return claims


def _breakable_id(claim_id: str) -> str:
    return r"\texttt{" + latex_id(claim_id).replace("-", r"-\allowbreak{}") + "}"


SERIES_ORDER = ("ratio3-2", "plus1", "sqrt2")
MM_ORDER = ("omega2", "omega1", "union")
FAMILY_ORDER = ("structured", "perturbed", "unstructured")


def series_tex(series: str) -> str:
    """LaTeX label of a mesh series id: ``$N_1=N_2+1$``, ``$N_1{:}N_2=3{:}2$``."""
    if series == "plus1":
        return r"$N_1=N_2+1$"
    if series == "sqrt2":
        return r"$N_1=\mathrm{round}(\sqrt2\,N_2)$"
    if series.startswith("ratio"):
        p, q = series[len("ratio"):].split("-")
        return rf"$N_1{{:}}N_2={p}{{:}}{q}$"
    return latex_id(series)


def nonmatching_table(claims: pd.DataFrame) -> str:
    """Verdicts of "β_h bounded away from 0" on the non-matching series, one tabular: rows
    (case, k), columns series × multiplier mesh, each cell the verdicts on the structured,
    perturbed and unstructured meshes as three letters (P pass, F fail, I inconclusive,
    - no claim)."""
    from ..study.claims.membranes import nonmatching_claims

    nm = nonmatching_claims(_claims_checked(claims))
    series = [s for s in SERIES_ORDER if s in set(nm.series)] + sorted(set(nm.series) - set(SERIES_ORDER))
    mms = [m for m in MM_ORDER if m in set(nm.mm)]
    if nm.empty:
        return "% no non-matching claims in claims.csv\n"
    letter = {"PASS": "P", "FAIL": "F", "INCONCLUSIVE": "I"}
    v = nm.set_index(["series", "mm", "case", "k", "family"]).verdict
    lines = [r"\begin{tabular}{@{}ll" + "".join("|" + "c" * len(mms) for _ in series) + "@{}}", r"\toprule",
             " & & " + " & ".join(rf"\multicolumn{{{len(mms)}}}{{c}}{{{series_tex(s)}}}" for s in series)
             + r" \\",
             "case & $k$ & " + " & ".join(r"\texttt{" + m + "}" for _ in series for m in mms) + r" \\", r"\midrule"]
    keys = nm[["case", "k"]].drop_duplicates()
    keys = keys.assign(rank=[case_rank(c) for c in keys.case]).sort_values(["rank", "k"])
    for _, r in keys.iterrows():
        cells = []
        for s in series:
            for m in mms:
                cells.append(r"\texttt{" + "".join(letter.get(v.get((s, m, r.case, r.k, f)), "-")
                                                   for f in FAMILY_ORDER) + "}")
        lines.append(rf"\case{{{latex_id(r.case)}}} & {int(r.k)} & " + " & ".join(cells) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}", ""]
    return "\n".join(lines)


def claims_table(claims: pd.DataFrame) -> str:
    """The ledger as a longtable: id, paper reference, verdict, statement and evidence; the
    non-matching bounded claims are the grid of :func:`nonmatching_table` instead (hundreds
    of rows; each is in claims.csv)."""
    from ..study.claims.membranes import NONMATCHING_ID

    claims = _claims_checked(claims)
    claims = claims[~claims.claim_id.astype(str).str.match(NONMATCHING_ID)]
    head = (r"claim & paper & verdict & statement; evidence \\")
    lines = [r"\begin{footnotesize}",
             r"\setlength{\tabcolsep}{4pt}",
             r"\begin{longtable}{@{}>{\raggedright\arraybackslash}p{0.23\linewidth}"
             r">{\raggedright\arraybackslash}p{0.10\linewidth}l"
             r">{\raggedright\arraybackslash}p{0.44\linewidth}@{}}",
             r"\caption{The claims ledger \texttt{results/claims.csv}, one row per claim: verdict by the "
             r"criterion of Section~\ref{sec:criteria}; rows with paper reference ``beyond the paper'' are "
             r"findings (no prediction).}\label{tab:claims}\\",
             r"\toprule", head, r"\midrule", r"\endfirsthead",
             r"\toprule", head, r"\midrule", r"\endhead",
             r"\midrule", r"\multicolumn{4}{r}{\emph{continued on the next page}}\\", r"\endfoot",
             r"\bottomrule", r"\endlastfoot"]
    for _, r in claims.iterrows():
        where = f"claims.csv claim {r.claim_id}"
        lines.append(f"{_breakable_id(r.claim_id)} & {latex_escape(r.paper_ref, where)} & "
                     rf"\verdictfmt{{{r.verdict}}} & {latex_escape(r.statement, where)}; "
                     rf"\emph{{{latex_escape(r.evidence, where)}}} \\")
    lines += [r"\end{longtable}", r"\end{footnotesize}", ""]
    return "\n".join(lines)


def speed_selection(speed: pd.DataFrame) -> pd.DataFrame:
    """The speed–accuracy rows the paper reports: structured family when a family column is
    present (as for the rates)."""
    _require(speed, SPEED_COLUMNS, "speed_accuracy.csv")
    if "family" in speed.columns and (speed.family == "structured").any():
        speed = speed[speed.family == "structured"]
    return speed


def speed_rows(speed: pd.DataFrame) -> pd.DataFrame:
    """Rows of the speed–accuracy table at the finest N of each (scene, case, k)."""
    speed = speed_selection(speed)
    idx = speed.groupby(["scene", "case", "k"]).N.idxmax()
    rows = speed.loc[idx]
    order = rows.case.map(case_rank)
    return rows.assign(_order=order).sort_values(["scene", "k", "_order", "case"]).drop(columns="_order")


def front_winner(speed: pd.DataFrame, error: str) -> str:
    """The (case, k) that is fastest for the most accuracy targets (all scenes), as text;
    ties list every such pair."""
    front = fastest_for_targets(speed, error).dropna(subset=["seconds"])
    if front.empty:
        return "none"
    counts = front.groupby(["case", "k"]).size()
    best = counts[counts == counts.max()].index
    return " and ".join(f"{latex_id(case)} with $k={int(k)}$" for case, k in best) + \
        f" ({int(counts.max())} of {len(front)} targets)"


ERRORS = {"energy_error": r"$\|u-u_h\|_a$", "lambda_hm12_error": r"$\|\lambda-\lambda_h\|_M$"}


def fastest_for_targets(speed: pd.DataFrame, error: str) -> pd.DataFrame:
    """Per scene and accuracy target 10^-j (every decade the table's errors span): the fastest
    row whose ``error`` is at most the target — the discretization to pick for that accuracy.

    Returns columns scene, target, case, k, N, seconds, error (NaN row values where no row
    reaches the target).
    """
    out = []
    for scene, g in speed_selection(speed).groupby("scene", sort=True):
        err = g[error].to_numpy(dtype=float)
        err = err[np.isfinite(err) & (err > 0)]
        if not len(err):
            continue
        for j in range(int(np.ceil(-np.log10(err.max()))), int(np.floor(-np.log10(err.min()))) + 1):
            ok = g[g[error] <= 10.0 ** -j]
            best = ok.loc[ok.seconds.idxmin()] if len(ok) else None
            out.append(dict(scene=scene, target=10.0 ** -j, case=best.case if best is not None else None,
                            k=int(best.k) if best is not None else np.nan,
                            N=int(best.N) if best is not None else np.nan,
                            seconds=float(best.seconds) if best is not None else np.nan,
                            error=float(best[error]) if best is not None else np.nan))
    return pd.DataFrame(out, columns=["scene", "target", "case", "k", "N", "seconds", "error"])


def front_table(speed: pd.DataFrame) -> str:
    """Tabular: for each scene and accuracy target, the fastest discretization reaching it,
    once for the energy error and once for the multiplier error in the norm of M."""
    lines = [r"\begin{tabular}{llrlrrr}", r"\toprule",
             r"scene & error & target & fastest & $k$ & $N$ & seconds \\", r"\midrule"]
    first = True
    for error, label in ERRORS.items():
        front = fastest_for_targets(speed, error)
        for scene, g in front.groupby("scene", sort=False):
            if not first:
                lines.append(r"\midrule")
            first = False
            for _, r in g.iterrows():
                if r.case is None or pd.isna(r.seconds):
                    continue
                target = f"$10^{{{int(round(np.log10(r.target)))}}}$"
                lines.append(f"{latex_id(scene)} & {label} & {target} & {latex_id(r.case)} & "
                             f"{int(r.k)} & {int(r.N)} & {fmt_sci(r.seconds)} \\\\")
    lines += [r"\bottomrule", r"\end{tabular}", ""]
    return "\n".join(lines)


def speed_table(speed: pd.DataFrame) -> str:
    """Tabular: time and errors at the finest N of each (scene, case, k); rows on the energy
    Pareto front of their scene marked when the table has the flag."""
    s = speed_rows(speed)
    front = "pareto_energy" in s.columns
    lines = [r"\begin{tabular}{llrrrrr" + ("c" if front else "") + "}", r"\toprule",
             r"scene & case & $k$ & $N$ & seconds & $\|u-u_h\|_a$ & $\|\lambda-\lambda_h\|_M$"
             + (r" & front" if front else "") + r" \\", r"\midrule"]
    for i, (scene, g) in enumerate(s.groupby("scene", sort=False)):
        if i:
            lines.append(r"\midrule")
        for _, r in g.iterrows():
            mark = (" & " + (r"$\bullet$" if bool(r.pareto_energy) else "")) if front else ""
            lines.append(f"{latex_id(scene)} & {latex_id(r.case)} & {int(r.k)} & {int(r.N)} & {fmt_sci(r.seconds)} & "
                         f"{fmt_sci(r.energy_error)} & {fmt_sci(r.lambda_hm12_error)}{mark} \\\\")
    lines += [r"\bottomrule"]
    if front:
        lines.append(r"\multicolumn{8}{l}{\footnotesize $\bullet$: on the Pareto front (time, energy error) "
                     r"of its scene over all $N$} \\")
    lines += [r"\end{tabular}", ""]
    return "\n".join(lines)
