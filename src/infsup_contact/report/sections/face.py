"""The face section's generated files (paper/face.tex): its macros, the β_h table of the 3D
face and the three study tables (the 3D patch test, the α sweep of the transformed dual bases,
edge dropping), each declared through the section templates (:mod:`.templates`, :mod:`.sections`).

Pure functions from the membranes3d study's tables (``results/tables/membranes3d_beta.csv``,
``results/tables/membranes3d/{patch,alpha,edge_dropping}.csv``) and its claims
(``results/tables/membranes3d_claims.csv``: :mod:`infsup_contact.study.claims.membranes3d` and
:mod:`~infsup_contact.study.claims.membranes3d_studies`) to LaTeX text;
``workflow/scripts/model_paper.py`` reads and writes (plans/membranes3d.py). Macro names start with
``face`` (letters only, :func:`~infsup_contact.report.texnames.macro_name`), apart from the
main paper's generated namespace. Every number of the section is one of these macros or a
cell of a table, each computed from the tables here; each outcome macro (``\\faceOutcome…``)
aggregates the verdicts of one kind of claim for ``\\byverdict``.
"""
from __future__ import annotations

import pandas as pd

from ...criteria.claims import slope_interval
from ...study.claims.membranes3d_studies import edge_claim_id, patch_claim_id
from .blocks import (check_section_tex, claim_count_macros, n_as_predicted, outcome, section_macros_tex,
                       verdict_macros)
from .templates import (Group, at, beta_cell, case_blocks, case_table, error_cells, ids_tex, ints_tex, kernel_cell,
                        pair_tex, pairs_tex, verdict_cell)
from ..texformat import PaperTexError, fmt_fixed, fmt_int, fmt_sci, latex_id
from ..texnames import Macro, macro_name

KINDS = (("kernel", "face-kernel-"), ("nonmatching", "face-nonmatching-kernel-"), ("ltwo", "face-Rem3.1-"),
         ("bounded", "face-"))
"""Claim kinds by id prefix (study/claims/membranes3d.py), the first matching prefix wins."""


_COLUMNS = {"patch": ("element", "case", "k", "N1", "N2", "lambda_max_rel_error", "u_max_rel_error", "kernel_dim"),
            "alpha": ("element", "alpha", "N", "norm", "min_weight", "accepted", "beta"),
            "edge": ("case", "k", "N", "theta", "beta_H", "beta_H_resolved", "cond_D", "cond_D_kappa", "cond_S",
                     "cond_S_kappa", "fit_theta_max")}
EDGE_KINDS = {"decay": "d", "bounded": "b", "kappa-cond": "c", "kappa-beta": "i"}
"""Edge claim kinds and their letters in the table's verdict column."""


def _name(*labels) -> str:
    return macro_name("face", *labels)


def claim_kind(claim_id: str) -> str:
    return next(kind for kind, prefix in KINDS if claim_id.startswith(prefix))


def face_macros(beta: pd.DataFrame, claims: pd.DataFrame) -> list[Macro]:
    """Every number of paper/face.tex: claim counts (all, predicted, as predicted, findings;
    per kind and verdict), the aggregate outcome of each kind (``\\faceOutcome<Kind>``, for
    ``\\byverdict``), the meshes, and the range of β_h of the spaces without kernel at the finest N."""
    out = claim_count_macros(claims, _name, "face_claims.csv")
    kinds = claims.claim_id.map(claim_kind)
    for kind, _ in KINDS:
        rows = claims[kinds == kind]
        failing, src = rows[rows.predicted == "FAIL"], f"face_claims.csv: {kind} claims"
        out += verdict_macros(rows, _name, kind, src)
        out += [Macro(_name("N", kind, "as predicted"), fmt_int(n_as_predicted(rows)), f"{src}, verdict == predicted"),
                Macro(_name("N", kind, "predicted fail"), fmt_int(len(failing)), f"{src} predicted FAIL"),
                Macro(_name("Outcome", kind, "predicted fail"), outcome(failing.verdict),
                      f"{src} predicted FAIL, all PASS / all FAIL / else")]
    m = beta[beta.N1 == beta.N2]
    nm = beta[beta.N1 != beta.N2]
    out += [Macro(_name("FinestN"), fmt_int(m.N2.max()), "face_beta.csv: max matching N"),
            Macro(_name("CoarsestN"), fmt_int(m.N2.min()), "face_beta.csv: min matching N"),
            Macro(_name("NMeshes"), fmt_int(m.N2.nunique()), "face_beta.csv: matching N count"),
            Macro(_name("NRows"), fmt_int(len(beta)), "face_beta.csv: rows"),
            Macro(_name("Elements"), ids_tex(beta.element), "face_beta.csv: elements"),
            Macro(_name("Degrees"), ints_tex(beta.k), "face_beta.csv: k"),
            Macro(_name("Pairs"), pairs_tex(nm.N1, nm.N2), "face_beta.csv: non-matching pairs")]
    if len(nm):
        last = nm.sort_values(["N2", "N1"]).iloc[-1]
        out.append(Macro(_name("FinestPair"), pair_tex(last.N1, last.N2),
                         "face_beta.csv: non-matching pair of the largest N2"))
    fin = m[(m.N2 == m.N2.max()) & (m.kernel_dim == 0)]
    for norm in ("H", "L2"):
        f = fin[fin.norm == norm]
        if len(f):
            out += [Macro(_name("Beta", norm, "min"), fmt_fixed(f.beta.min(), 3),
                          f"face_beta.csv: min beta, norm={norm}, finest N, kernel 0"),
                    Macro(_name("Beta", norm, "max"), fmt_fixed(f.beta.max(), 3),
                          f"face_beta.csv: max beta, norm={norm}, finest N, kernel 0")]
    return out


def face_macros_tex(macros: list[Macro]) -> str:
    """The section's macro file (:func:`~.sections.section_macros_tex`)."""
    return section_macros_tex(macros, "face", "infsup_contact.report.sections.face (rule face_paper)")


def face_beta_table(beta: pd.DataFrame) -> str:
    """Rows (element, case), per k: β_h in the H^{-1/2}_00(Γ) and L²(Γ) norms on the finest
    matching mesh, the kernel dimension there with the dimension count in parentheses, and the
    same on the finest non-matching pair."""
    m, nm = beta[beta.N1 == beta.N2], beta[beta.N1 != beta.N2]
    n = int(m.N2.max())
    m = m[m.N2 == n]
    pair = nm.sort_values(["N2", "N1"]).iloc[-1] if len(nm) else None
    if pair is not None:
        nm = nm[(nm.N1 == pair.N1) & (nm.N2 == pair.N2) & (nm.norm == "H")]
    ks = sorted(int(k) for k in set(beta.k))
    heads = (r"$\beta_h$ ($H$)", r"$\beta_h$ ($L^2$)", "kernel") + (("kernel n.m.",) if pair is not None else ())

    def cells(k):
        def at_k(key):
            r = m[(m.element == key[0]) & (m.case == key[1]) & (m.k == k)]
            out = [beta_cell(r[r.norm == "H"]), beta_cell(r[r.norm == "L2"]), kernel_cell(r)]
            return out + ([kernel_cell(nm[(nm.element == key[0]) & (nm.case == key[1]) & (nm.k == k)])]
                          if pair is not None else [])
        return at_k

    note = (f"; kernel n.m.: on the non-matching pair N_1{{:}}N_2={int(pair.N1)}{{:}}{int(pair.N2)}"
            if pair is not None else "")
    return case_table("ll" + "rrr" * len(ks) + ("r" * len(ks) if pair is not None else ""), ("element", "case"),
                      lambda key: [latex_id(key[0]), latex_id(key[1])],
                      [Group(heads, cells(k), f"$k={k}$") for k in ks],
                      case_blocks(m, "element", order=dict.fromkeys(beta.element)),
                      after=[f"% finest matching N = {n}{note}"])


# --------------------------------------------------------------------------- the face studies

def _kind_macros(claims: pd.DataFrame, label: str, prefix: str, predicted: str | None = None) -> list:
    """:func:`~.sections.verdict_macros` of the claims whose id starts with ``prefix`` (and,
    given, whose prediction is ``predicted``)."""
    rows = claims[claims.claim_id.str.startswith(prefix)]
    if predicted is not None:
        rows = rows[rows.predicted == predicted]
    src = f"face_study_claims.csv: {prefix}* claims" + (f" predicted {predicted}" if predicted else "")
    return verdict_macros(rows, _name, label, src, "{src}: all PASS / all FAIL / else", "{src}, verdict {v}")


def study_macros(patch: pd.DataFrame, alpha: pd.DataFrame, edge: pd.DataFrame, claims: pd.DataFrame) -> list:
    """Every number of the studies' text in paper/face.tex (module docstring)."""
    out = claim_count_macros(claims, lambda *labels: _name("Study", *labels), "face_study_claims.csv", findings=False)
    # patch test
    out += [Macro(_name("Patch", "pairs"), pairs_tex(patch.N1, patch.N2), "patch.csv: pairs"),
            Macro(_name("Patch", "elements"), ids_tex(patch.element), "patch.csv: elements"),
            Macro(_name("Patch", "degrees"), ints_tex(patch.k), "patch.csv: k")]
    out += _kind_macros(claims, "Patch holding", "face-patch-", "PASS")
    out += _kind_macros(claims, "Patch lacking", "face-patch-", "FAIL")
    ids = [patch_claim_id(c, k, e) for c, k, e in zip(patch.case, patch.k, patch.element)]
    pred = dict(zip(claims.claim_id, claims.predicted))
    hold = patch[[pred.get(i) == "PASS" for i in ids]]
    lack = patch[[pred.get(i) == "FAIL" for i in ids]]
    if len(hold):
        out.append(Macro(_name("Patch", "holding", "err max"), fmt_sci(hold.lambda_max_rel_error.max(), 2),
                         "patch.csv: max λ error, claims predicted PASS"))
    if len(lack):
        out.append(Macro(_name("Patch", "lacking", "err min"), fmt_sci(lack.lambda_max_rel_error.min(), 2),
                         "patch.csv: min λ error, claims predicted FAIL"))
    # α sweep
    out += [Macro(_name("Alpha", "N"), fmt_int(alpha.N.max()), "alpha.csv: N"),
            Macro(_name("Alpha", "count"), fmt_int(alpha.alpha.nunique()), "alpha.csv: distinct α")]
    out += _kind_macros(claims, "Alpha accept", "face-alpha-accept-")
    ok = alpha[alpha.accepted.astype(bool) & (alpha.norm == "H")]
    if len(ok):
        out += [Macro(_name("Alpha", "beta min"), fmt_fixed(ok.beta.min(), 3), "alpha.csv: min β_H, accepted α"),
                Macro(_name("Alpha", "beta max"), fmt_fixed(ok.beta.max(), 3), "alpha.csv: max β_H, accepted α")]
    # edge dropping
    out += [Macro(_name("Edge", "N"), fmt_int(edge.N.max()), "edge_dropping.csv: N"),
            Macro(_name("Edge", "theta min"), f"{edge.theta.min():g}", "edge_dropping.csv: min θ"),
            Macro(_name("Edge", "fit theta max"), f"{edge.fit_theta_max.iloc[0]:g}",
                  "edge_dropping.csv: fit_theta_max")]
    out += _kind_macros(claims, "Edge decay", "face-edge-decay-", "PASS")
    out += _kind_macros(claims, "Edge bounded", "face-edge-bounded-")
    out += _kind_macros(claims, "Edge kappa cond", "face-edge-kappa-cond-")
    out += _kind_macros(claims, "Edge kappa beta", "face-edge-kappa-beta-")
    return out


def patch_table(patch: pd.DataFrame, claims: pd.DataFrame) -> str:
    """Rows (element, case); per k: the largest relative λ and u errors over the pairs, the
    kernel dimensions seen, and the claim's verdict (``*``: a finding, no prediction)."""
    ks = sorted(int(k) for k in set(patch.k))

    def cells(k):
        def at_k(key):
            r = patch[(patch.element == key[0]) & (patch.case == key[1]) & (patch.k == k)]
            if r.empty:
                return ["--"] * 4
            return error_cells(r, ("lambda_max_rel_error", "u_max_rel_error")) + [
                ",".join(map(str, sorted(set(r.kernel_dim.astype(int).tolist())))),
                verdict_cell(claims, patch_claim_id(key[1], k, key[0]))]
        return at_k

    heads = (r"$\lambda$ err.", "$u$ err.", "kernel", "verdict")
    return case_table("ll" + "rrcc" * len(ks), ("element", "case"), lambda key: [latex_id(key[0]), latex_id(key[1])],
                      [Group(heads, cells(k), f"$k={k}$") for k in ks],
                      case_blocks(patch, "element", order=dict.fromkeys(patch.element)))


def alpha_table(alpha: pd.DataFrame, claims: pd.DataFrame) -> str:
    """Rows α; per element: the smallest transformed weight (fraction of the cell area),
    accepted or refused, β_h in the H norm (-- where refused)."""
    elements = list(dict.fromkeys(alpha.element))
    h = alpha[alpha.norm == "H"] if (alpha.norm == "H").any() else alpha.drop_duplicates(["element", "alpha", "N"])

    def cells(element):
        def at_alpha(key):
            r = at(h[h.element == element], "alpha", key[0], rtol=0, atol=1e-12)
            if r.empty:
                return ["--"] * 3
            r = r.iloc[0]
            acc = bool(r.accepted)
            return [fmt_sci(r.min_weight, 2) if abs(r.min_weight) > 1e-12 else "0", "yes" if acc else "no",
                    fmt_fixed(r.beta, 4) if acc else "--"]
        return at_alpha

    groups = [Group((r"$\min\int\tilde N_k/|K|$", "built", r"$\beta_h$"), cells(e),
                    f"{latex_id(e)} ({verdict_cell(claims, f'face-alpha-accept-{e}')})") for e in elements]
    return case_table("r" + "rcr" * len(elements), (r"$\alpha$",), lambda key: [f"{key[0]:.4g}"], groups,
                      [[(a,) for a in sorted(set(h.alpha))]])


def edge_table(edge: pd.DataFrame, claims: pd.DataFrame) -> str:
    """Rows (k, case): β_H at θ = 1 and at the smallest θ (``n.r.``: below round-off), the
    slope of log β_H against log θ over the resolved θ ≤ fit_theta_max, cond₂ of D and S
    without and with κ scaling at the smallest θ, and the verdicts of the case's claims."""
    top = float(edge.fit_theta_max.iloc[0])

    def cells(key):
        k, n, case = key
        r = edge[(edge.k == k) & (edge.N == n) & (edge.case == case)].sort_values("theta")
        last, first = r.iloc[0], r.iloc[-1]
        fit = r[(r.theta <= top + 1e-12) & r.beta_H_resolved.astype(bool)]
        verdicts = " ".join(f"{tag}:{verdict_cell(claims, edge_claim_id(kind, case, k, n))}"
                            for kind, tag in EDGE_KINDS.items()
                            if (claims.claim_id == edge_claim_id(kind, case, k, n)).any())
        return [fmt_fixed(first.beta_H, 4), fmt_sci(last.beta_H, 2) if bool(last.beta_H_resolved) else "n.r.",
                fmt_fixed(slope_interval(fit.theta, fit.beta_H)[0], 2) if len(fit) >= 2 else "--",
                *(fmt_sci(last[c], 3) for c in ("cond_D", "cond_D_kappa", "cond_S", "cond_S_kappa")), verdicts]

    heads = (r"$\beta_H(1)$", r"$\beta_H(\theta_{\min})$", "slope", "cond $D$", r"cond $D_\kappa$", "cond $S$",
             r"cond $S_\kappa$", "verdicts")
    return case_table("llrrrrrrrl", ("$k$", "case"), lambda key: [str(int(key[0])), latex_id(key[2])],
                      [Group(heads, cells)], case_blocks(edge, "k", "N"))


def study_files(patch: pd.DataFrame, alpha: pd.DataFrame, edge: pd.DataFrame, claims: pd.DataFrame) -> tuple:
    """(macros, {file name: text}) of the three study tables."""
    for kind, frame in (("patch", patch), ("alpha", alpha), ("edge", edge)):
        missing = [c for c in _COLUMNS[kind] if c not in frame.columns]
        if missing or frame.empty:
            raise PaperTexError(f"the face {kind} table lacks column(s) {missing} or rows")
    files = {"face_patch_table.tex": patch_table(patch, claims), "face_alpha_table.tex": alpha_table(alpha, claims),
             "face_edge_table.tex": edge_table(edge, claims)}
    return study_macros(patch, alpha, edge, claims), files


def face_paper_files(beta: pd.DataFrame, claims: pd.DataFrame, patch: pd.DataFrame | None = None,
                     alpha: pd.DataFrame | None = None, edge: pd.DataFrame | None = None,
                     study_claims: pd.DataFrame | None = None) -> dict[str, str]:
    """Every generated file of the face section (name → text); with the three study tables and
    their claims also the study tables and their macros (:func:`study_files`)."""
    for col in ("element", "case", "k", "N1", "N2", "norm", "beta", "kernel_dim", "structural_kernel_dim"):
        if col not in beta.columns:
            raise PaperTexError(f"face_beta.csv lacks column {col!r}")
    macros, files = face_macros(beta, claims), {}
    if patch is not None:
        more, files = study_files(patch, alpha, edge, study_claims)
        macros += more
    return {"face_macros.tex": face_macros_tex(macros), "face_beta_table.tex": face_beta_table(beta), **files}


def check_face_tex(tex: str, files: dict[str, str]) -> None:
    """PaperTexError unless every \\face… macro and \\input of ``tex`` is generated."""
    check_section_tex(tex, files, "face")
