"""The face section's generated files (paper/face.tex): macros and the β_h table of the 3D face.

Pure functions from ``results/tables/face_beta.csv`` and ``results/tables/face_claims.csv``
to LaTeX text; ``workflow/scripts/face_paper.py`` reads and writes. Macro names start with
``face`` (letters only, :func:`~infsup_contact.report.texnames.macro_name`), apart from the
main paper's generated namespace. Every number of the section is one of these macros or a
cell of the table, each computed from the tables here.
"""
from __future__ import annotations


import pandas as pd

from .sections import (check_section_tex, claim_count_macros, n_as_predicted, outcome, section_macros_tex,
                       verdict_macros)
from .templates import Group, beta_cell, case_blocks, case_table, ids_tex, ints_tex, kernel_cell, pair_tex, pairs_tex
from .texformat import PaperTexError, fmt_fixed, fmt_int, latex_id
from .texnames import Macro, macro_name

FACE_FILES = ("face_macros.tex", "face_beta_table.tex")
KINDS = (("kernel", "face-kernel-"), ("nonmatching", "face-nonmatching-kernel-"), ("ltwo", "face-Rem3.1-"),
         ("bounded", "face-"))
"""Claim kinds by id prefix (study/claims/membranes3d.py), the first matching prefix wins."""


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
    return section_macros_tex(macros, "face", "infsup_contact.report.face (rule face_paper)")


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

    note = f"; kernel n.m.: on the non-matching pair N_1{{:}}N_2={int(pair.N1)}{{:}}{int(pair.N2)}" if pair is not None else ""
    return case_table("ll" + "rrr" * len(ks) + ("r" * len(ks) if pair is not None else ""), ("element", "case"),
                      lambda key: [latex_id(key[0]), latex_id(key[1])],
                      [Group(heads, cells(k), f"$k={k}$") for k in ks],
                      case_blocks(m, "element", order=dict.fromkeys(beta.element)), after=[f"% finest matching N = {n}{note}"])


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
