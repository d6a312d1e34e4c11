"""The face section's generated files (paper/face.tex): macros and the β_h table of the 3D face.

Pure functions from ``results/tables/face_beta.csv`` and ``results/tables/face_claims.csv``
to LaTeX text; ``workflow/scripts/face_paper.py`` reads and writes. Macro names start with
``face`` (letters only, :func:`~infsup_contact.report.texnames.macro_name`), apart from the
main paper's generated namespace. Every number of the section is one of these macros or a
cell of the table, each computed from the tables here.
"""
from __future__ import annotations


import pandas as pd

from .sections import check_section_tex, section_macros_tex
from .texformat import PaperTexError, case_order, fmt_fixed, fmt_int, latex_id
from .texnames import Macro, macro_name

FACE_FILES = ("face_macros.tex", "face_beta_table.tex")
KINDS = (("kernel", "face-kernel-"), ("nonmatching", "face-nonmatching-kernel-"), ("ltwo", "face-Rem3.1-"),
         ("bounded", "face-"))
"""Claim kinds by id prefix (study/claims/membranes3d.py), the first matching prefix wins."""
VERDICTS = ("PASS", "FAIL", "INCONCLUSIVE")


def _name(*labels) -> str:
    return macro_name("face", *labels)


def claim_kind(claim_id: str) -> str:
    return next(kind for kind, prefix in KINDS if claim_id.startswith(prefix))


def _outcome(verdicts) -> str:
    """PASS if every verdict is PASS, FAIL if every one is FAIL, else INCONCLUSIVE (mixed)."""
    vs = set(verdicts)
    return "PASS" if vs == {"PASS"} else "FAIL" if vs == {"FAIL"} else "INCONCLUSIVE"


def face_macros(beta: pd.DataFrame, claims: pd.DataFrame) -> list[Macro]:
    """Every number of paper/face.tex: claim counts (all, predicted, as predicted, findings;
    per kind and verdict), the aggregate outcome of each kind (``\\faceOutcome<Kind>``, for
    ``\\byverdict``), the meshes, and the range of β_h of the spaces without kernel at the finest N."""
    out = []
    checked = claims[claims.predicted.isin(["PASS", "FAIL"])]
    out += [Macro(_name("NClaims"), fmt_int(len(claims)), "face_claims.csv: rows"),
            Macro(_name("NPredicted"), fmt_int(len(checked)), "face_claims.csv: predicted PASS/FAIL"),
            Macro(_name("NAsPredicted"), fmt_int(int((checked.verdict == checked.predicted).sum())),
                  "face_claims.csv: verdict == predicted"),
            Macro(_name("NFindings"), fmt_int(len(claims) - len(checked)), "face_claims.csv: findings")]
    kinds = claims.claim_id.map(claim_kind)
    for kind, _ in KINDS:
        rows = claims[kinds == kind]
        out.append(Macro(_name("N", kind), fmt_int(len(rows)), f"face_claims.csv: {kind} claims"))
        out.append(Macro(_name("Outcome", kind), _outcome(rows.verdict) if len(rows) else "INCONCLUSIVE",
                         f"face_claims.csv: {kind} claims, all PASS / all FAIL / else"))
        for v in VERDICTS:
            out.append(Macro(_name("N", kind, v.lower()), fmt_int(int((rows.verdict == v).sum())),
                             f"face_claims.csv: {kind} claims with verdict {v}"))
        pred = rows[rows.predicted.isin(["PASS", "FAIL"])]
        out.append(Macro(_name("N", kind, "as predicted"), fmt_int(int((pred.verdict == pred.predicted).sum())),
                         f"face_claims.csv: {kind} claims, verdict == predicted"))
        out.append(Macro(_name("N", kind, "predicted fail"), fmt_int(int((rows.predicted == "FAIL").sum())),
                         f"face_claims.csv: {kind} claims predicted FAIL"))
        failing = rows[rows.predicted == "FAIL"]
        out.append(Macro(_name("Outcome", kind, "predicted fail"),
                         _outcome(failing.verdict) if len(failing) else "INCONCLUSIVE",
                         f"face_claims.csv: {kind} claims predicted FAIL, all PASS / all FAIL / else"))
    m = beta[beta.N1 == beta.N2]
    nm = beta[beta.N1 != beta.N2]
    out += [Macro(_name("FinestN"), fmt_int(m.N2.max()), "face_beta.csv: max matching N"),
            Macro(_name("CoarsestN"), fmt_int(m.N2.min()), "face_beta.csv: min matching N"),
            Macro(_name("NMeshes"), fmt_int(m.N2.nunique()), "face_beta.csv: matching N count"),
            Macro(_name("NRows"), fmt_int(len(beta)), "face_beta.csv: rows"),
            Macro(_name("Elements"), ", ".join(latex_id(e) for e in dict.fromkeys(beta.element)),
                  "face_beta.csv: elements"),
            Macro(_name("Degrees"), ", ".join(str(int(k)) for k in sorted(set(beta.k))), "face_beta.csv: k"),
            Macro(_name("Pairs"), ", ".join(f"${a}{{:}}{b}$" for a, b in sorted({(int(a), int(b))
                                                                                for a, b in zip(nm.N1, nm.N2)})),
                  "face_beta.csv: non-matching pairs")]
    if len(nm):
        last = nm.sort_values(["N2", "N1"]).iloc[-1]
        out.append(Macro(_name("FinestPair"), f"${int(last.N1)}{{:}}{int(last.N2)}$",
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
    return section_macros_tex(macros, "face", "infsup_contact.report.face (rule face_paper)")


def _kernel_cell(rows: pd.DataFrame) -> str:
    """``d (c)``: the kernel dimension and the dimension count of the row (``--`` if none)."""
    if rows.empty:
        return "--"
    r = rows.iloc[0]
    return f"{int(r.kernel_dim)} ({int(r.structural_kernel_dim)})"


def _beta_cell(rows: pd.DataFrame) -> str:
    if rows.empty:
        return "--"
    r = rows.iloc[0]
    return fmt_fixed(r.beta, 4) if r.kernel_dim == 0 else "0"


def face_beta_table(beta: pd.DataFrame) -> str:
    """Rows (element, case), per k: β_h in the H^{-1/2}_00(Γ) and L²(Γ) norms on the finest
    matching mesh, the kernel dimension there with the dimension count in parentheses, and the
    same on the finest non-matching pair."""
    m, nm = beta[beta.N1 == beta.N2], beta[beta.N1 != beta.N2]
    n = int(m.N2.max())
    pair = nm.sort_values(["N2", "N1"]).iloc[-1] if len(nm) else None
    ks = sorted(int(k) for k in set(beta.k))
    per_k = 4 if pair is not None else 3
    head = [r"$\beta_h$ ($H$)", r"$\beta_h$ ($L^2$)", "kernel"] + (["kernel n.m."] if pair is not None else [])
    lines = [r"\begin{tabular}{ll" + "rrr" * len(ks) + ("r" * len(ks) if pair is not None else "") + "}",
             r"\toprule",
             " & & " + " & ".join(rf"\multicolumn{{{per_k}}}{{c}}{{$k={k}$}}" for k in ks) + r" \\",
             "element & case & " + " & ".join(head * len(ks)) + r" \\", r"\midrule"]
    for element in dict.fromkeys(beta.element):
        me, nme = m[(m.element == element) & (m.N2 == n)], nm[nm.element == element]
        if pair is not None:
            nme = nme[(nme.N1 == pair.N1) & (nme.N2 == pair.N2)]
        for case in case_order(me.case.unique()):
            cells = []
            for k in ks:
                r = me[(me.case == case) & (me.k == k)]
                cells += [_beta_cell(r[r.norm == "H"]), _beta_cell(r[r.norm == "L2"]), _kernel_cell(r)]
                if pair is not None:
                    cells.append(_kernel_cell(nme[(nme.case == case) & (nme.k == k) & (nme.norm == "H")]))
            lines.append(f"{latex_id(element)} & {latex_id(case)} & " + " & ".join(cells) + r" \\")
        lines.append(r"\midrule")
    lines[-1] = r"\bottomrule"
    lines.append(r"\end{tabular}")
    caption_pair = (rf"; kernel n.m.: on the non-matching pair $N_1{{:}}N_2={int(pair.N1)}{{:}}{int(pair.N2)}$"
                    if pair is not None else "")
    lines.append(f"% finest matching N = {n}{caption_pair.replace('$', '')}")
    return "\n".join(lines) + "\n"


def face_paper_files(beta: pd.DataFrame, claims: pd.DataFrame, patch: pd.DataFrame | None = None,
                     alpha: pd.DataFrame | None = None, edge: pd.DataFrame | None = None,
                     study_claims: pd.DataFrame | None = None) -> dict[str, str]:
    """Every generated file of the face section (name → text); with the three study tables and
    their claims also the study tables and macros (:mod:`.face_studies`)."""
    for col in ("element", "case", "k", "N1", "N2", "norm", "beta", "kernel_dim", "structural_kernel_dim"):
        if col not in beta.columns:
            raise PaperTexError(f"face_beta.csv lacks column {col!r}")
    macros, files = face_macros(beta, claims), {}
    if patch is not None:
        from .face_studies import study_files

        more, files = study_files(patch, alpha, edge, study_claims)
        macros += more
    return {"face_macros.tex": face_macros_tex(macros), "face_beta_table.tex": face_beta_table(beta), **files}


def check_face_tex(tex: str, files: dict[str, str]) -> None:
    """PaperTexError unless every \\face… macro and \\input of ``tex`` is generated."""
    check_section_tex(tex, files, "face")
