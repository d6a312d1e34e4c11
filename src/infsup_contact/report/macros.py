"""The paper's numbers as macros: one ``\\newcommand`` per value, each with its table source.

The naming scheme is :mod:`infsup_contact.report.texnames`'s; the selections of rows are the
tables' (:mod:`infsup_contact.report.tables`), so a macro and a table cell never disagree.
"""
from __future__ import annotations

import pandas as pd

from .tables import _claims_checked, beta_default_rows, front_winner, speed_rows, speed_selection
from .texformat import (MEASURES, NOT_RUN, VERDICTS, PaperTexError, _require, _src, fmt_fixed, fmt_int, fmt_sci,
                        latex_escape)
from .texnames import Macro, _family, _k, _n, _scene, is_generated_name, macro_name


# --------------------------------------------------------------------------- β_h


def beta_macros(beta: pd.DataFrame) -> list[Macro]:
    b = beta_default_rows(beta)
    c1, c2 = b.c1.iloc[0], b.c2.iloc[0]
    out = []
    for (fam, case, k, norm), g in b.groupby(["family", "case", "k", "norm"], sort=True):
        g = g.sort_values("N2")
        last = g.iloc[-1]
        sel = dict(family=fam, case=case, k=k, norm=norm, multiplier_mesh="omega2", c1=c1, c2=c2)
        fin = dict(sel, N1=last.N1, N2=last.N2)
        base = ("beta", norm, case, _k(k), _family(fam))
        out.append(Macro(macro_name(*base), fmt_fixed(last.beta, 4), _src("beta.csv", "beta", **fin)))
        for _, r in g.iterrows():
            out.append(Macro(macro_name(*base, _n(r.N2)), fmt_fixed(r.beta, 4),
                             _src("beta.csv", "beta", **sel, N1=r.N1, N2=r.N2)))
        for agg in ("min", "max"):
            out.append(Macro(macro_name(f"beta{agg.capitalize()}", norm, case, _k(k), _family(fam)),
                             fmt_fixed(g.beta.agg(agg), 4), _src("beta.csv", "beta", agg, **sel, matching=1)))
        out.append(Macro(macro_name("smallestNonzero", norm, case, _k(k), _family(fam)),
                         fmt_fixed(last.smallest_nonzero, 4), _src("beta.csv", "smallest_nonzero", **fin)))
        if fam == "structured" and norm == "H":
            out.append(Macro(macro_name("kernelDim", case, _k(k)), fmt_int(last.kernel_dim),
                             _src("beta.csv", "kernel_dim", **fin)))
            out.append(Macro(macro_name("dimM", case, _k(k)), fmt_int(last.dim_M), _src("beta.csv", "dim_M", **fin)))
    s = b[(b.family == "structured") & (b.norm == "H")] if (b.family == "structured").any() else b
    for k, g in s.groupby("k"):
        last = g.sort_values("N2").iloc[-1]
        out.append(Macro(macro_name("dimW", _k(k)), fmt_int(last.dim_W),
                         _src("beta.csv", "dim_W", family=last.family, case=last.case, k=k, norm=last.norm,
                              multiplier_mesh="omega2", c1=c1, c2=c2, N1=last.N1, N2=last.N2)))
    out += [Macro("betaCPair", rf"\ensuremath{{({c1:g}, {c2:g})}}", "beta.csv: first (c1, c2) pair"),
            Macro("finestN", fmt_int(b.N2.max()), _src("beta.csv", "N2", "max", multiplier_mesh="omega2", matching=1)),
            Macro("coarsestN", fmt_int(b.N2.min()), _src("beta.csv", "N2", "min", multiplier_mesh="omega2", matching=1)),
            Macro("nBetaRows", fmt_int(len(beta)), "beta.csv: number of rows"),
            Macro("nBetaFamilies", fmt_int(beta.family.nunique()), "beta.csv: number of mesh families"),
            Macro("nBetaMeshPairs", fmt_int(len(beta[["N1", "N2"]].drop_duplicates())),
                  "beta.csv: number of (N1, N2) pairs")]
    if "kernel_margin_decades" in beta.columns:  # the kernel decisions' distance from their error level
        from ..solvers.kernel import MARGIN_DECADES

        margin = beta.kernel_margin_decades.astype(float)
        out.append(Macro("kernelMarginDecades", fmt_int(MARGIN_DECADES) if float(MARGIN_DECADES).is_integer()
                         else f"{MARGIN_DECADES:g}", "solvers/kernel.py: MARGIN_DECADES"))
        out.append(Macro("kernelMarginMin", f"{margin.min():.2g}", "beta.csv: kernel_margin_decades min"))
        for d, word in ((1, "One"), (2, "Two"), (3, "Three")):
            out.append(Macro(f"nKernelWithin{word}", fmt_int((margin < d).sum()),
                             f"beta.csv: rows with kernel_margin_decades < {d}"))
        out.append(Macro("nKernelClose", fmt_int((beta.kernel_decision == "close").sum()),
                         "beta.csv: rows with kernel_decision == close"))
        out.append(Macro("nKernelDetected", fmt_int((beta.kernel_detected > 0).sum()),
                         "beta.csv: rows with kernel_detected > 0"))
    if "kernel_check" in beta.columns:  # numerical count vs the structural (proven) one
        for word in ("agree", "below_structural", "above_structural"):
            name = macro_name("nKernel", *word.split("_"))
            for label, rows in (("", beta), ("Matching", beta[beta.N1 == beta.N2])):
                out.append(Macro(name + label, fmt_int((rows.kernel_check == word).sum()),
                                 f"beta.csv: rows with kernel_check == {word}" + (", N1 == N2" if label else "")))
    return out


# --------------------------------------------------------------------------- rates and contact


def rates_macros(rates: pd.DataFrame, primary: str) -> list[Macro]:
    _require(rates, ["scene", "case", "k", "family", "measure", "slope", "stderr", "expected"], "rates.csv")
    out = []
    for _, r in rates.sort_values(["scene", "family", "case", "k", "measure"]).iterrows():
        if r.measure not in MEASURES:
            continue
        parts = (_scene(r.scene, primary), _family(r.family), MEASURES[r.measure], r.case, _k(r.k))
        sel = dict(scene=r.scene, family=r.family, case=r.case, k=r.k, measure=r.measure)
        out.append(Macro(macro_name("slope", *parts), fmt_fixed(r.slope, 2), _src("rates.csv", "slope", **sel)))
        out.append(Macro(macro_name("stderr", *parts), fmt_fixed(r.stderr, 3), _src("rates.csv", "stderr", **sel)))
        if pd.notna(r.expected):
            out.append(Macro(macro_name("expected", *parts), f"{float(r.expected):g}",
                             _src("rates.csv", "expected", **sel)))
    return out


def contact_macros(contact: pd.DataFrame, primary: str) -> list[Macro]:
    _require(contact, ["scene", "case", "k", "family", "N1", "N2", "iterations", "nonunique",
                       "max_penetration", *MEASURES], "contact.csv")
    c = contact[contact.N1 == contact.N2]
    nonunique = contact.nonunique.astype(str).str.lower().eq("true")
    out = [Macro("nContactSolves", fmt_int(len(contact)), "contact.csv: number of rows"),
           Macro("nNonunique", fmt_int(nonunique.sum()), "contact.csv: rows with nonunique = True"),
           Macro("maxIterations", fmt_int(contact.iterations.max()), _src("contact.csv", "iterations", "max")),
           Macro("nContactScenes", fmt_int(contact.scene.nunique()), "contact.csv: number of scenes")]
    for scene, gs in c.groupby("scene"):
        finest = int(gs.N2.max())
        label = scene  # the primary scene too: "maxIterationsManufactured"
        out += [Macro(macro_name("contactFinestN", _scene(scene, primary)), fmt_int(finest),
                      _src("contact.csv", "N2", "max", scene=scene, matching=1)),
                Macro(macro_name("maxIterations", label), fmt_int(gs.iterations.max()),
                      _src("contact.csv", "iterations", "max", scene=scene, matching=1)),
                Macro(macro_name("maxPenetration", label), fmt_sci(gs[gs.N2 == finest].max_penetration.max()),
                      _src("contact.csv", "max_penetration", "max", scene=scene, N1=finest, N2=finest))]
        for (fam, case, k), g in gs[gs.N2 == finest].groupby(["family", "case", "k"]):
            r = g.iloc[0]
            sel = dict(scene=scene, family=fam, case=case, k=k, N1=finest, N2=finest)
            for col, meas in MEASURES.items():
                out.append(Macro(macro_name("error", _scene(scene, primary), _family(fam), meas, case, _k(k)),
                                 fmt_sci(r[col]), _src("contact.csv", col, **sel)))
            out.append(Macro(macro_name("iterations", _scene(scene, primary), _family(fam), case, _k(k)),
                             fmt_int(r.iterations), _src("contact.csv", "iterations", **sel)))
            if "min_lambda_pointwise" in r:
                out.append(Macro(macro_name("lambdaMin", _scene(scene, primary), _family(fam), case, _k(k)),
                                 fmt_sci(r.min_lambda_pointwise), _src("contact.csv", "min_lambda_pointwise", **sel)))
    return out


# --------------------------------------------------------------------------- claims


def claims_macros(claims: pd.DataFrame) -> list[Macro]:
    claims = _claims_checked(claims)
    not_run = claims[claims.verdict == NOT_RUN]  # an optional code not installed: counted on their own
    ran = claims[claims.verdict != NOT_RUN]
    beyond = ran.paper_ref.astype(str).str.startswith("beyond the paper")
    paper = ran[(ran.predicted != "finding") & ~beyond]
    found = ran[ran.predicted == "finding"]
    ours = ran[(ran.predicted != "finding") & beyond]  # predicted by us, about other spaces
    checked = paper[paper.predicted.isin(["PASS", "FAIL"])]
    out = [Macro("nClaims", fmt_int(len(paper)), "claims.csv: rows with predicted != finding, paper_ref "
                 "not 'beyond the paper ...', verdict not NOT RUN"),
           Macro("nBeyondClaims", fmt_int(len(ours)), "claims.csv: predicted rows with paper_ref 'beyond the paper (...)', "
                 "verdict not NOT RUN"),
           Macro("nClaimsNotRun", fmt_int(len(not_run)), "claims.csv: rows with verdict NOT RUN (a code not installed)"),
           Macro("nBeyondAsPredicted", fmt_int((ours.verdict == ours.predicted).sum()),
                 "claims.csv: those rows with verdict == predicted"),
           Macro("nClaimsChecked", fmt_int(len(checked)), "claims.csv: rows with predicted PASS or FAIL"),
           Macro("nClaimsAsPredicted", fmt_int((checked.verdict == checked.predicted).sum()),
                 "claims.csv: rows with verdict == predicted"),
           Macro("nFindings", fmt_int(len(found)), "claims.csv: rows with predicted == finding"),
           Macro("nClaimsAll", fmt_int(len(claims)), "claims.csv: number of rows")]
    for v in VERDICTS:
        out.append(Macro(macro_name("nClaims", v.capitalize()), fmt_int((paper.verdict == v).sum()),
                         f"claims.csv: paper claims with verdict {v}"))
        out.append(Macro(macro_name("nFindings", v.capitalize()), fmt_int((found.verdict == v).sum()),
                         f"claims.csv: findings with verdict {v}"))
    for ref, g in claims.groupby("paper_ref", sort=True):
        n_pass = int((g.verdict == "PASS").sum())
        verdict = _group_verdict(g.verdict)
        out += [Macro(macro_name("refClaims", ref), fmt_int(len(g)), f"claims.csv: rows with paper_ref '{ref}'"),
                Macro(macro_name("refPass", ref), fmt_int(n_pass), f"claims.csv: PASS rows with paper_ref '{ref}'"),
                Macro(macro_name("refVerdict", ref), rf"\verdictfmt{{{verdict}}}",
                      f"claims.csv: of the rows with paper_ref '{ref}' that ran: PASS if all pass, else FAIL if one "
                      "fails, else INCONCLUSIVE; NOT RUN if none ran"),
                # the bare word, for \byverdict: a sentence that states an outcome is chosen by it
                Macro(macro_name("refOutcome", ref), _outcome(verdict), f"claims.csv: the verdict of refVerdict for '{ref}'"
                      " (NOT RUN: INCONCLUSIVE, undecided)")]
    for _, r in claims.iterrows():
        out.append(Macro(macro_name("claimVerdict", r.claim_id), rf"\verdictfmt{{{r.verdict}}}",
                         _src("claims.csv", "verdict", claim_id=r.claim_id)))
        out.append(Macro(macro_name("claimOutcome", r.claim_id), _outcome(str(r.verdict)),
                         _src("claims.csv", "verdict", claim_id=r.claim_id)))
        out.append(Macro(macro_name("claimEvidence", r.claim_id),
                         latex_escape(r.evidence, f"claims.csv evidence of {r.claim_id}"),
                         _src("claims.csv", "evidence", claim_id=r.claim_id)))
    return out


def _group_verdict(verdicts: pd.Series) -> str:
    """Of the verdicts that ran: PASS if all pass, else FAIL if one fails, else INCONCLUSIVE;
    NOT RUN if none ran (a group of one code's claims where it is not installed)."""
    ran = verdicts[verdicts != NOT_RUN]
    if not len(ran):
        return NOT_RUN
    return "PASS" if (ran == "PASS").all() else ("FAIL" if (ran == "FAIL").any() else "INCONCLUSIVE")


def _outcome(verdict: str) -> str:
    """The word ``\\byverdict`` chooses by: NOT RUN decides nothing, so it is the undecided branch."""
    return "INCONCLUSIVE" if verdict == NOT_RUN else verdict


def series_macros(claims: pd.DataFrame) -> list[Macro]:
    """Counts of the non-matching bounded claims per (series, multiplier mesh): all cases
    (``nSeries{Claims,Pass,Fail,Inconclusive}``), the paper's stable spaces T3, T4, T5
    (``nSeriesStable…``) and its unstable ones R5.2, R5.4 (``nSeriesUnstable…``): the groups
    are the registry's paper cases split by ``SpaceSpec.stable``, in the paper's order."""
    from ..discretization.spaces.registry import PAPER_CASES, SPACES
    from ..study.claims.membranes import nonmatching_claims

    nm = nonmatching_claims(_claims_checked(claims))
    out = []
    groups = {"": None, "Stable": tuple(c for c in PAPER_CASES if SPACES[c].stable),
              "Unstable": tuple(c for c in PAPER_CASES if not SPACES[c].stable)}
    for (series, mm), g in nm.groupby(["series", "mm"], sort=True):
        for label, cases in groups.items():
            gg = g if cases is None else g[g.case.isin(cases)]
            what = "all cases" if cases is None else "cases " + ", ".join(cases)
            src = f"claims.csv: non-matching bounded claims, series {series}, G_h {mm}, {what}"
            out.append(Macro(macro_name(f"nSeries{label}Claims", series, mm), fmt_int(len(gg)), src))
            for v in VERDICTS:
                out.append(Macro(macro_name(f"nSeries{label}{v.capitalize()}", series, mm),
                                 fmt_int((gg.verdict == v).sum()), f"{src}, verdict {v}"))
    return out


# --------------------------------------------------------------------------- speed


def speed_macros(speed: pd.DataFrame, primary: str) -> list[Macro]:
    s = speed_rows(speed)
    speed = speed_selection(speed)
    out = [Macro("speedRows", fmt_int(len(speed)), "speed_accuracy.csv: number of rows")]
    for _, r in s.iterrows():
        sel = dict(scene=r.scene, case=r.case, k=r.k, N=r.N)
        sel.update({"family": r.family} if "family" in r else {})
        parts = (_scene(r.scene, primary), r.case, _k(r.k))
        out += [Macro(macro_name("speedSeconds", *parts), fmt_sci(r.seconds), _src("speed_accuracy.csv", "seconds", **sel)),
                Macro(macro_name("speedEnergy", *parts), fmt_sci(r.energy_error),
                      _src("speed_accuracy.csv", "energy_error", **sel)),
                Macro(macro_name("speedLambdaH", *parts), fmt_sci(r.lambda_hm12_error),
                      _src("speed_accuracy.csv", "lambda_hm12_error", **sel))]
    for scene, g in speed.groupby("scene"):
        label = scene  # the primary scene too: "maxIterationsManufactured"
        fam = {"family": g.family.iloc[0]} if "family" in g.columns else {}
        out.append(Macro(macro_name("speedFastestSeconds", label), fmt_sci(g.seconds.min()),
                         _src("speed_accuracy.csv", "seconds", "min", scene=scene, **fam)))
        out.append(Macro(macro_name("speedSlowestSeconds", label), fmt_sci(g.seconds.max()),
                         _src("speed_accuracy.csv", "seconds", "max", scene=scene, **fam)))
        if "pareto_energy" in g.columns:
            out.append(Macro(macro_name("speedParetoCount", label), fmt_int(g.pareto_energy.astype(bool).sum()),
                             f"speed_accuracy.csv: rows with pareto_energy | scene={scene}"))
    for error, name in (("energy_error", "Energy"), ("lambda_hm12_error", "Lambda")):
        out.append(Macro(macro_name("speedFrontWinner", name), front_winner(speed, error),
                         f"speed_accuracy.csv: most frequent fastest (case, k) over the {error} targets"))
    return out


BENCH_OPTIONAL_ROUTES = {"beta": ("eigsh", "dense"), "contact": ("osqp", "clarabel", "kkt_sparse")}
"""Benchmark routes that depend on the configuration (sizes, peers)."""


def bench_macros(bench: pd.DataFrame, what: str) -> list[Macro]:
    """Speed ratios route/ours at the largest N (and k) of a benchmark table."""
    _require(bench, ["what", "route", "k", "N", "seconds_median", "ratio_to_ours"], f"benchmarks/{what}.csv")
    b = bench[bench.what == what]
    if b.empty:
        raise PaperTexError(f"benchmarks/{what}.csv: no rows with what={what}")
    top = b[b.N == b.N.max()]
    top = top[top.k == top.k.max()]
    n, k = int(top.N.iloc[0]), int(top.k.iloc[0])
    table = f"benchmarks/{what}.csv"
    out = [Macro(macro_name("bench", what, "N"), fmt_int(n), _src(table, "N", "max", what=what)),
           Macro(macro_name("bench", what, "K"), fmt_int(k), _src(table, "k", "max", what=what, N=n))]
    for _, r in top.iterrows():
        sel = dict(what=what, route=r.route, k=k, N=n)
        out.append(Macro(macro_name("bench", what, r.route, "Seconds"), fmt_sci(r.seconds_median),
                         _src(table, "seconds_median", **sel)))
        if r.route != "ours":
            out.append(Macro(macro_name("bench", what, r.route, "Ratio"), fmt_sci(r.ratio_to_ours),
                             _src(table, "ratio_to_ours", **sel)))
            if "max_abs_diff" in r and pd.notna(r.max_abs_diff):
                out.append(Macro(macro_name("bench", what, r.route, "Diff"), fmt_sci(r.max_abs_diff),
                                 _src(table, "max_abs_diff", **sel)))
    # routes a config may leave out (peers: [], eigsh_max_N) still get a macro the text can use
    for route in sorted(set(BENCH_OPTIONAL_ROUTES.get(what, ())) - set(top.route)):
        for kind in ("Seconds", "Ratio", "Diff"):
            out.append(Macro(macro_name("bench", what, route, kind), "n/a",
                             f"{table}: route {route} not run at N={n}, k={k}"))
    return out


# --------------------------------------------------------------------------- config, provenance

def config_macros(cfg: dict) -> list[Macro]:
    """Numbers of the study design (thresholds, windows, scene parameters) from the config."""
    cl, cc = cfg["claims"], cfg["contact"]
    out = [Macro("cfgSlopeTolerance", f"{cl['slope_tolerance']:g}", "config: claims.slope_tolerance"),
           Macro("cfgRateTolerance", f"{cl['rate_tolerance']:g}", "config: claims.rate_tolerance"),
           Macro("cfgConfidencePercent", f"{100 * cl['confidence']:g}", "config: claims.confidence"),
           Macro("cfgBetaFloor", f"{cl['beta_floor']:g}", "config: claims.beta_floor"),
           Macro("cfgFitWindow", fmt_int(cl["fit_window"]), "config: claims.fit_window"),
           Macro("cfgRateWindow", fmt_int(cc["rate_window"]), "config: contact.rate_window"),
           Macro("cfgReferenceN", fmt_int(cc["reference_N"]), "config: contact.reference_N")]
    for name, spec in cc["scenes"].items():
        for key in ("p", "q"):
            if key in spec:
                out.append(Macro(macro_name("cfg", name, key.upper()), f"{float(spec[key]):g}",
                                 f"config: contact.scenes.{name}.{key}"))
    bc = cfg.get("benchmarks", {})
    from ..bench.harness import ROUTE_BUDGET
    out.append(Macro("cfgRouteBudget", f"{float(bc.get('route_budget_s', ROUTE_BUDGET)):g}",
                     "config: benchmarks.route_budget_s (default: bench.harness.ROUTE_BUDGET)"))
    out.append(Macro("cfgBenchRepeats", fmt_int(bc.get("repeats", 3)), "config: benchmarks.repeats"))
    ic = cfg.get("infsup", {})
    if "alpha" in ic:
        out.append(Macro("cfgPerturbAlpha", f"{float(ic['alpha']):g}", "config: infsup.alpha"))
    if "seed" in ic:
        from ..discretization.gamma.mesh_series import seeds
        out.append(Macro("cfgNSeeds", fmt_int(len(seeds(ic))), "config: infsup.seed (number of seeds)"))
    return out


def provenance_macros(beta: pd.DataFrame, prov: dict) -> list[Macro]:
    out = []
    for col, name, f in (("git_commit", "provGitCommit", lambda s: str(s)[:10]),
                         ("config_hash", "provConfigHash", str), ("package_version", "provPackageVersion", str)):
        if col in beta.columns and beta[col].nunique() >= 1:
            vals = sorted(set(map(str, beta[col])))
            out.append(Macro(name, latex_escape(f(vals[0]) + (" (mixed)" if len(vals) > 1 else "")),
                             f"beta.csv: {col}"))
    for key, value in sorted((prov.get("versions") or {}).items()):
        out.append(Macro(macro_name("prov", key, "Version"), latex_escape(value), f"provenance.json: versions.{key}"))
    if "cpu_count" in prov:
        out.append(Macro("provCpuCount", fmt_int(prov["cpu_count"]), "provenance.json: cpu_count"))
    return out


def _ascii(text: str) -> str:
    return text.encode("ascii", "backslashreplace").decode()


def macros_tex(macros: list[Macro]) -> str:
    """``\\newcommand`` definitions, one per line, each with its source as a comment."""
    seen = {}
    for m in macros:
        if not is_generated_name(m.name):
            raise PaperTexError(f"macro name {m.name!r} is not letters-only or not in the generated namespace")
        if m.name in seen:
            raise PaperTexError(f"macro {m.name} defined twice: {seen[m.name]} and {m.source}")
        seen[m.name] = m.source
    lines = ["% Generated by infsup_contact.report (workflow rule paper_macros): do not edit.",
             "% Naming scheme: see the docstring of infsup_contact/report/texnames.py."]
    lines += [f"\\newcommand{{\\{m.name}}}{{{m.tex}}} % {_ascii(m.source)}" for m in macros]
    return "\n".join(lines) + "\n"


def all_macros(beta, contact, rates, claims, speed, bench_beta, bench_contact, cfg, prov) -> list[Macro]:
    primary = cfg["contact"]["primary_scene"]
    return (beta_macros(beta) + contact_macros(contact, primary) + rates_macros(rates, primary)
            + claims_macros(claims) + series_macros(claims)
            + speed_macros(speed, primary) + bench_macros(bench_beta, "beta") + bench_macros(bench_contact, "contact")
            + config_macros(cfg) + provenance_macros(beta, prov))
