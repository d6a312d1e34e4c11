"""LaTeX for the paper: every number, table and verdict of ``paper/paper.tex`` comes from here.

Pure functions from the result tables (pandas DataFrames) and plain dicts (config,
provenance) to LaTeX text; no I/O (``workflow/scripts/paper_macros.py`` reads and writes).

Macro naming scheme
-------------------
A macro name is a LaTeX control word: ASCII letters only. It is built from *tokens*:

* a token is a label with every maximal digit run spelled as an English number word in
  lower case (``64`` → ``sixtyfour``, ``128`` → ``onehundredtwentyeight``), every other
  non-letter dropped, and its first letter capitalized (:func:`token`):
  ``T3`` → ``Tthree``, ``R5.2`` → ``Rfivetwo``, ``k=1`` → ``Kone``, ``L2`` → ``Ltwo``;
  a label with several words/segments (separated by anything but letters, digits and ``.``)
  gives one capitalized token per segment: ``eq3.13-sign`` → ``EqthreethirteenSign``.
* a name is a lower-case *prefix* followed by tokens (:func:`macro_name`). Qualifiers equal
  to their default are omitted: family ``structured``, scene ``manufactured``, multiplier
  mesh ``omega2`` (the paper's G_h), the first (c1, c2) pair of the β table, and N = the
  finest matching N of the series.

Prefixes (``<Case>`` = Tthree | Rfivetwo | Tfour | Rfivefour | Tfive, ``<Norm>`` = H | Ltwo,
``<Family>`` = '' | Perturbed | Unstructured, ``<Scene>`` = '' | Membranes | ...,
``<Measure>`` = Energy | Ltwo | LambdaLtwo | LambdaH):

==========================================  ================================================
``\\beta<Norm><Case>K<k><Family>[N<n>]``      β_h (4 decimals), finest matching N or N = n
``\\betaMin<Norm><Case>K<k><Family>``         min / max of β_h over the matching N
``\\betaMax...``, ``\\smallestNonzero...``      (the latter: first eigenvalue above a kernel)
``\\kernelDim<Case>K<k>``                      numerical kernel dimension at the finest N
``\\dimM<Case>K<k>``, ``\\dimWK<k>``            dim M_h, dim W_h at the finest N
``\\finestN``, ``\\coarsestN``, ``\\nBetaRows``  β table: finest / coarsest matching N, rows
``\\slope<Scene><Measure><Case>K<k>``          fitted convergence slope (2 decimals)
``\\stderr...``, ``\\expected...``              its standard error, the expected rate
``\\error<Scene><Measure><Case>K<k>``          error at the finest N of the scene
``\\iterations<Scene><Case>K<k>``              PDAS iterations at the finest N
``\\nClaims[Pass|Fail|Inconclusive]``          ledger counts (findings excluded)
``\\nClaimsChecked``, ``\\nClaimsAsPredicted``  claims with a PASS/FAIL prediction, and met
``\\nFindings[Pass|Fail|Inconclusive]``        findings beyond the paper
``\\refClaims<Ref>``, ``\\refPass<Ref>``,       per paper reference (``Thm 3`` → ThmThree,
``\\refVerdict<Ref>``                          ``(3.13) erratum`` → ThreethirteenErratum)
``\\claimVerdict<Id>``, ``\\claimEvidence<Id>``  one claim (``eq3.13-sign`` → EqthreethirteenSign)
``\\speed<What><Scene><Case>K<k>``            speed–accuracy row at its finest N; What =
                                             Seconds | Energy | LambdaH | N
``\\bench<What><Route>[Seconds|Ratio|Diff]``   benchmark at its largest N and k: time, time /
                                             ours, max |difference| (``\\benchBetaN``, ``K``)
``\\maxIterations[<Scene>]``,                  PDAS iterations, penetration, solve counts
``\\maxPenetration<Scene>``, ``\\nContact...``
``\\cfg...``, ``\\prov...``                     config values (tolerances, windows, scene
                                             parameters); versions and git commit
==========================================  ================================================

Numbers are typeset as plain decimals (β_h: 4 decimals, slopes 2) or, for errors and
times, ``\\ensuremath{m\\times10^{e}}`` with 3 significant digits (:func:`fmt_sci`).
Verdicts are wrapped in ``\\verdictfmt{...}``, which ``paper.tex`` defines.

Each definition in ``macros.tex`` carries its source as a comment. For values read from a
table the source is machine-readable, ``table:column[:min|max] key=value ...`` (the value is
that column of the one row matching every key, or its min/max over the matching rows;
``matching=1`` means N1 = N2), so a test can check every number against its table.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
import pandas as pd

CASES = ("T3", "R5.2", "T4", "R5.4", "T5")
VERDICTS = ("PASS", "FAIL", "INCONCLUSIVE")
MEASURES = {"energy_error": "Energy", "l2_error": "Ltwo", "lambda_l2_error": "LambdaLtwo",
            "lambda_hm12_error": "LambdaH"}
SPEED_COLUMNS = ("scene", "case", "k", "N", "seconds", "energy_error", "lambda_hm12_error")
GENERATED_FILES = ("macros.tex", "claims_table.tex", "rates_table.tex", "beta_table.tex",
                   "speed_table.tex", "front_table.tex")
MACRO_PREFIXES = ("beta", "smallest", "kernel", "dim", "finest", "coarsest", "n", "slope", "stderr",
                  "expected", "error", "iterations", "max", "contact", "ref", "claim", "speed", "bench",
                  "cfg", "prov")
"""Generated names are one of these prefixes followed by an upper-case letter (so ``\\beta`` or
``\\ref`` are not generated names, ``\\betaHTthreeKone`` and ``\\refVerdictThmThree`` are);
``paper.tex`` defines no such name itself."""
_GENERATED = re.compile("(?:" + "|".join(MACRO_PREFIXES) + ")[A-Z][A-Za-z]*")


def is_generated_name(name: str) -> bool:
    """True if ``name`` lies in the generated namespace (prefix + upper-case letter + letters)."""
    return _GENERATED.fullmatch(name) is not None


class PaperTexError(ValueError):
    """A table lacks what the paper needs; the message names the table and what is missing."""


@dataclass(frozen=True)
class Macro:
    name: str    # control word, letters only
    tex: str     # replacement text
    source: str  # where the value comes from (written as a comment next to the definition)


# --------------------------------------------------------------------------- naming

_ONES = ("zero one two three four five six seven eight nine ten eleven twelve thirteen "
         "fourteen fifteen sixteen seventeen eighteen nineteen").split()
_TENS = "_ _ twenty thirty forty fifty sixty seventy eighty ninety".split()


def number_word(n: int) -> str:
    """English number word, letters only, lower case: 64 → 'sixtyfour'."""
    n = int(n)
    if n < 0:
        raise ValueError(f"no number word for {n}")
    if n < 20:
        return _ONES[n]
    if n < 100:
        return _TENS[n // 10] + (_ONES[n % 10] if n % 10 else "")
    if n < 1000:
        return _ONES[n // 100] + "hundred" + (number_word(n % 100) if n % 100 else "")
    if n < 10**6:
        return number_word(n // 1000) + "thousand" + (number_word(n % 1000) if n % 1000 else "")
    return "".join(_ONES[int(d)] for d in str(n))


def _segment(seg: str) -> str:
    out = re.sub(r"\d+", lambda m: number_word(int(m.group())), seg)
    out = re.sub(r"[^A-Za-z]", "", out)
    return out[:1].upper() + out[1:]


def token(label) -> str:
    """Letters-only CamelCase token of a label: 'T3' → 'Tthree', 'eq3.13-sign' → 'EqthreethirteenSign'."""
    segments = [s for s in re.split(r"[^A-Za-z0-9.]+", str(label)) if s.strip(".")]
    return "".join(_segment(s) for s in segments)


def macro_name(prefix: str, *labels) -> str:
    """prefix + tokens of the labels (empty labels are omitted)."""
    name = prefix + "".join(token(lab) for lab in labels if lab not in (None, ""))
    if not re.fullmatch(r"[A-Za-z]+", name):
        raise ValueError(f"not a letters-only control word: {name!r}")
    return name


def _k(k) -> str:
    return f"K{number_word(int(k))}"


def _n(n) -> str:
    return f"N{number_word(int(n))}"


def _family(f) -> str:
    return "" if f == "structured" else f


def _scene(s) -> str:
    return "" if s == "manufactured" else s


# --------------------------------------------------------------------------- formatting

def fmt_fixed(x, digits: int) -> str:
    """Fixed-point with ``digits`` decimals ('−0.0000' is printed '0.0000')."""
    x = float(x)
    if not math.isfinite(x):
        return "n/a"
    s = f"{x:.{digits}f}"
    return s[1:] if s.startswith("-") and float(s) == 0 else s


def fmt_sci(x, sig: int = 3) -> str:
    """m × 10^e in math mode with ``sig`` significant digits (plain decimal for 1e-2 ≤ |x| < 1e3)."""
    x = float(x)
    if not math.isfinite(x):
        return "n/a"
    if x == 0:
        return "0"
    if 1e-2 <= abs(x) < 1e3:
        return f"{x:.{sig}g}"
    mant, exp = f"{x:.{sig - 1}e}".split("e")
    return rf"\ensuremath{{{mant}\times10^{{{int(exp)}}}}}"


def fmt_int(x) -> str:
    return str(int(x))


def parse_number(tex: str) -> float:
    """Inverse of the formatters (for checks): '1.38' or '\\ensuremath{1.38\\times10^{-3}}'."""
    m = re.fullmatch(r"\\ensuremath\{(-?[\d.]+)\\times10\^\{(-?\d+)\}\}", tex)
    if m:
        return float(m.group(1)) * 10.0 ** int(m.group(2))
    return float(tex)


UNICODE_LATEX = {
    "β": r"$\beta$", "λ": r"$\lambda$", "μ": r"$\mu$", "Ω": r"$\Omega$", "Γ": r"$\Gamma$",
    "τ": r"$\tau$", "π": r"$\pi$", "∂": r"$\partial$", "∫": r"$\int$", "±": r"$\pm$",
    "−": r"$-$", "–": "--", "—": "---", "≠": r"$\neq$", "≤": r"$\leq$", "≥": r"$\geq$",
    "×": r"$\times$", "²": r"\textsuperscript{2}", "½": r"$\frac12$", "⊂": r"$\subset$",
    "⊃": r"$\supset$", "§": r"\S{}", "₊": r"$_+$", "→": r"$\to$", "∞": r"$\infty$",
    "≈": r"$\approx$", "·": r"$\cdot$", "√": r"$\sqrt{}$", "’": "'", "‘": "`", "“": "``", "”": "''",
    "…": r"\dots{}", "∈": r"$\in$", "ε": r"$\varepsilon$", "σ": r"$\sigma$", "φ": r"$\varphi$",
    "ψ": r"$\psi$", "∇": r"$\nabla$", "Π": r"$\Pi$", "⁻": r"$^{-}$", "¹": r"\textsuperscript{1}",
    "ᵀ": r"$^{\mathsf T}$", "\u00a0": "~",
}
_SPECIAL = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
            "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}",
            "<": r"\textless{}", ">": r"\textgreater{}"}


_SCRIPT = re.compile(r"([_^])(\{[^{}]*\}|\([^()]*\)|(?<=\^)[-+]?\d+(?:/\d+)?|[A-Za-z0-9]+)")


def _escape_chars(text: str, where: str) -> str:
    out = []
    for ch in text:
        if ch in _SPECIAL:
            out.append(_SPECIAL[ch])
        elif ch in UNICODE_LATEX:
            out.append(UNICODE_LATEX[ch])
        elif ord(ch) < 128:
            out.append(ch)
        else:
            raise PaperTexError(f"no LaTeX form for {ch!r} (U+{ord(ch):04X}) in {where}; "
                                "add it to infsup_contact.papertex.UNICODE_LATEX")
    return "".join(out)


def latex_escape(text, where: str = "text") -> str:
    """Plain (UTF-8) text → LaTeX: specials escaped, known symbols mapped (UNICODE_LATEX), and
    sub/superscripts written the plain way (``β_h``, ``H^-1/2_00``, ``h^(1/2)``, ``M^1_{0,k}``)
    set as math scripts.

    An unknown non-ASCII character raises :class:`PaperTexError` naming it and ``where``,
    rather than letting pdflatex fail later or print it wrongly."""
    out, pos = [], 0
    text = str(text)
    for m in _SCRIPT.finditer(text):
        if len(re.search(r"[^\W\d_]*$", text[:m.start()]).group()) > 2:
            continue  # an identifier such as kernel_dim, not a script: escaped literally
        out.append(_escape_chars(text[pos:m.start()], where))
        body = m.group(2)
        if body[0] in "{(":
            body = body[1:-1]
        out.append(f"${m.group(1)}{{{_escape_chars(body, where)}}}$")
        pos = m.end()
    out.append(_escape_chars(text[pos:], where))
    return "".join(out).replace("$$", "")


def _require(frame: pd.DataFrame, columns, table: str) -> None:
    missing = [c for c in columns if c not in frame.columns]
    if missing:
        raise PaperTexError(f"{table}: missing column(s) {', '.join(missing)} "
                            f"(has {', '.join(map(str, frame.columns))})")
    if frame.empty:
        raise PaperTexError(f"{table}: the table is empty")


def _src(table: str, column: str, agg: str | None = None, **filters) -> str:
    """Machine-readable source of a value: ``table:column[:min|max] key=value ...``; the value
    is the column of the one row matching the filters (or its min/max over the rows)."""
    head = f"{table}:{column}" + (f":{agg}" if agg else "")
    return " ".join([head] + [f"{k}={_plain(v)}" for k, v in filters.items()])


def _plain(v) -> str:
    if isinstance(v, (float, np.floating)) and float(v).is_integer():
        return str(int(v))
    return str(v.item() if isinstance(v, np.generic) else v)


def case_order(cases) -> list:
    return sorted(set(cases), key=lambda c: (CASES.index(c) if c in CASES else len(CASES), str(c)))


# --------------------------------------------------------------------------- β_h

def beta_default_rows(beta: pd.DataFrame) -> pd.DataFrame:
    """The paper's setting: G_h = trace of Ω2 (omega2), matching meshes, first (c1, c2) pair."""
    _require(beta, ["case", "k", "family", "N1", "N2", "multiplier_mesh", "c1", "c2", "norm", "beta",
                    "kernel_dim", "smallest_nonzero", "dim_M", "dim_W"], "beta.csv")
    b = beta[(beta.multiplier_mesh == "omega2") & (beta.N1 == beta.N2)]
    if b.empty:
        raise PaperTexError("beta.csv: no rows with multiplier_mesh=omega2 and N1 == N2")
    c1, c2 = b[["c1", "c2"]].iloc[0]
    return b[(b.c1 == c1) & (b.c2 == c2)]


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
    return out


def beta_table(beta: pd.DataFrame, ks=(1, 2, 3), even_only: bool = True) -> str:
    """Tabular of β_h (structured, omega2, matching, first c): rows (norm, k, case), columns N."""
    b = beta_default_rows(beta)
    b = b[(b.family == "structured") & b.k.isin(list(ks))]
    if b.empty:
        raise PaperTexError(f"beta.csv: no structured rows with k in {list(ks)}")
    ns = sorted({int(n) for n in b.N2 if (n % 2 == 0 or not even_only)})
    val = b.set_index(["norm", "k", "case", "N2"]).beta
    lines = [r"\begin{tabular}{ll" + "r" * len(ns) + "}", r"\toprule",
             r"$k$ & case & " + " & ".join(rf"$N={n}$" for n in ns) + r" \\"]
    for norm in [n for n in ("H", "L2") if n in set(b.norm)]:
        title = (r"$\|\cdot\|_M$ = dual norm of $H^{1/2}_{00}(\Gamma)$" if norm == "H"
                 else r"$\|\cdot\|_M$ = $L^2(\Gamma)$ norm (Remark 3.1)")
        lines += [r"\midrule", rf"\multicolumn{{{len(ns) + 2}}}{{l}}{{{title}}} \\", r"\midrule"]
        for k in sorted(set(b.k)):
            for case in case_order(b[(b.k == k) & (b.norm == norm)].case):
                cells = [fmt_fixed(val[(norm, k, case, n)], 4) if (norm, k, case, n) in val.index else "--"
                         for n in ns]
                lines.append(f"{k} & {case} & " + " & ".join(cells) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}", ""]
    return "\n".join(lines)


# --------------------------------------------------------------------------- rates and contact

def rates_macros(rates: pd.DataFrame) -> list[Macro]:
    _require(rates, ["scene", "case", "k", "family", "measure", "slope", "stderr", "expected"], "rates.csv")
    out = []
    for _, r in rates.sort_values(["scene", "family", "case", "k", "measure"]).iterrows():
        if r.measure not in MEASURES:
            continue
        parts = (_scene(r.scene), _family(r.family), MEASURES[r.measure], r.case, _k(r.k))
        sel = dict(scene=r.scene, family=r.family, case=r.case, k=r.k, measure=r.measure)
        out.append(Macro(macro_name("slope", *parts), fmt_fixed(r.slope, 2), _src("rates.csv", "slope", **sel)))
        out.append(Macro(macro_name("stderr", *parts), fmt_fixed(r.stderr, 3), _src("rates.csv", "stderr", **sel)))
        if pd.notna(r.expected):
            out.append(Macro(macro_name("expected", *parts), f"{float(r.expected):g}",
                             _src("rates.csv", "expected", **sel)))
    return out


def rates_table(rates: pd.DataFrame) -> str:
    """Tabular: slopes of the four error measures per (scene, case, k), structured family."""
    _require(rates, ["scene", "case", "k", "family", "measure", "slope", "stderr", "expected", "points"],
             "rates.csv")
    r = rates[rates.family == "structured"] if (rates.family == "structured").any() else rates
    slope = r.set_index(["scene", "case", "k", "measure"])
    cols = list(MEASURES)
    lines = [r"\begin{tabular}{llrrrrrr}", r"\toprule",
             r"scene & case & $k$ & expected & $\|u-u_h\|_a$ & $\|u-u_h\|_{L^2}$ & "
             r"$\|\lambda-\lambda_h\|_{L^2(\Gamma)}$ & $\|\lambda-\lambda_h\|_M$ \\", r"\midrule"]
    scenes = sorted(set(r.scene), key=lambda s: (s != "manufactured", s))
    for i, scene in enumerate(scenes):
        if i:
            lines.append(r"\midrule")
        keys = r[r.scene == scene][["case", "k"]].drop_duplicates()
        keys = sorted(map(tuple, keys.values),
                      key=lambda ck: (int(ck[1]), CASES.index(ck[0]) if ck[0] in CASES else 99, ck[0]))
        for case, k in keys:
            exp = slope.loc[(scene, case, k, "energy_error"), "expected"] \
                if (scene, case, k, "energy_error") in slope.index else np.nan
            cells = []
            for m in cols:
                if (scene, case, k, m) in slope.index:
                    cells.append(fmt_fixed(slope.loc[(scene, case, k, m), "slope"], 2))
                else:
                    cells.append("--")
            lines.append(f"{latex_escape(scene, 'rates.csv scene')} & {case} & {int(k)} & "
                         f"{'--' if pd.isna(exp) else format(float(exp), 'g')} & " + " & ".join(cells) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}", ""]
    return "\n".join(lines)


def contact_macros(contact: pd.DataFrame) -> list[Macro]:
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
        label = _scene(scene) or "Manufactured"
        out += [Macro(macro_name("contactFinestN", _scene(scene)), fmt_int(finest),
                      _src("contact.csv", "N2", "max", scene=scene, matching=1)),
                Macro(macro_name("maxIterations", label), fmt_int(gs.iterations.max()),
                      _src("contact.csv", "iterations", "max", scene=scene, matching=1)),
                Macro(macro_name("maxPenetration", label), fmt_sci(gs[gs.N2 == finest].max_penetration.max()),
                      _src("contact.csv", "max_penetration", "max", scene=scene, N1=finest, N2=finest))]
        for (fam, case, k), g in gs[gs.N2 == finest].groupby(["family", "case", "k"]):
            r = g.iloc[0]
            sel = dict(scene=scene, family=fam, case=case, k=k, N1=finest, N2=finest)
            for col, meas in MEASURES.items():
                out.append(Macro(macro_name("error", _scene(scene), _family(fam), meas, case, _k(k)),
                                 fmt_sci(r[col]), _src("contact.csv", col, **sel)))
            out.append(Macro(macro_name("iterations", _scene(scene), _family(fam), case, _k(k)),
                             fmt_int(r.iterations), _src("contact.csv", "iterations", **sel)))
    return out


# --------------------------------------------------------------------------- claims

def _claims_checked(claims: pd.DataFrame) -> pd.DataFrame:
    _require(claims, ["claim_id", "paper_ref", "statement", "evidence", "verdict", "predicted"], "claims.csv")
    bad = sorted(set(claims.verdict) - set(VERDICTS))
    if bad:
        raise PaperTexError(f"claims.csv: unknown verdict(s) {bad}")
    return claims


def claims_macros(claims: pd.DataFrame) -> list[Macro]:
    claims = _claims_checked(claims)
    paper = claims[claims.predicted != "finding"]
    found = claims[claims.predicted == "finding"]
    checked = paper[paper.predicted.isin(["PASS", "FAIL"])]
    out = [Macro("nClaims", fmt_int(len(paper)), "claims.csv: rows with predicted != finding"),
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
        verdict = "PASS" if n_pass == len(g) else ("FAIL" if (g.verdict == "FAIL").any() else "INCONCLUSIVE")
        out += [Macro(macro_name("refClaims", ref), fmt_int(len(g)), f"claims.csv: rows with paper_ref '{ref}'"),
                Macro(macro_name("refPass", ref), fmt_int(n_pass), f"claims.csv: PASS rows with paper_ref '{ref}'"),
                Macro(macro_name("refVerdict", ref), rf"\verdictfmt{{{verdict}}}",
                      f"claims.csv: PASS if all rows with paper_ref '{ref}' pass, else FAIL if one fails, "
                      "else INCONCLUSIVE")]
    for _, r in claims.iterrows():
        out.append(Macro(macro_name("claimVerdict", r.claim_id), rf"\verdictfmt{{{r.verdict}}}",
                         _src("claims.csv", "verdict", claim_id=r.claim_id)))
        out.append(Macro(macro_name("claimEvidence", r.claim_id),
                         latex_escape(r.evidence, f"claims.csv evidence of {r.claim_id}"),
                         _src("claims.csv", "evidence", claim_id=r.claim_id)))
    return out


def _breakable_id(claim_id: str) -> str:
    return r"\texttt{" + latex_escape(claim_id).replace("-", r"-\allowbreak{}") + "}"


def claims_table(claims: pd.DataFrame) -> str:
    """The ledger as a longtable: id, paper reference, verdict, statement and evidence."""
    claims = _claims_checked(claims)
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


# --------------------------------------------------------------------------- speed

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
    order = rows.case.map(lambda c: CASES.index(c) if c in CASES else len(CASES))
    return rows.assign(_order=order).sort_values(["scene", "k", "_order", "case"]).drop(columns="_order")


def speed_macros(speed: pd.DataFrame) -> list[Macro]:
    s = speed_rows(speed)
    speed = speed_selection(speed)
    out = [Macro("speedRows", fmt_int(len(speed)), "speed_accuracy.csv: number of rows")]
    for _, r in s.iterrows():
        sel = dict(scene=r.scene, case=r.case, k=r.k, N=r.N)
        sel.update({"family": r.family} if "family" in r else {})
        parts = (_scene(r.scene), r.case, _k(r.k))
        out += [Macro(macro_name("speedSeconds", *parts), fmt_sci(r.seconds), _src("speed_accuracy.csv", "seconds", **sel)),
                Macro(macro_name("speedEnergy", *parts), fmt_sci(r.energy_error),
                      _src("speed_accuracy.csv", "energy_error", **sel)),
                Macro(macro_name("speedLambdaH", *parts), fmt_sci(r.lambda_hm12_error),
                      _src("speed_accuracy.csv", "lambda_hm12_error", **sel))]
    for scene, g in speed.groupby("scene"):
        label = _scene(scene) or "Manufactured"
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


def front_winner(speed: pd.DataFrame, error: str) -> str:
    """The (case, k) that is fastest for the most accuracy targets (all scenes), as text;
    ties list every such pair."""
    front = fastest_for_targets(speed, error).dropna(subset=["seconds"])
    if front.empty:
        return "none"
    counts = front.groupby(["case", "k"]).size()
    best = counts[counts == counts.max()].index
    return " and ".join(f"{case} with $k={int(k)}$" for case, k in best) + \
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
                lines.append(f"{latex_escape(scene)} & {label} & {target} & {r.case} & "
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
            lines.append(f"{latex_escape(scene)} & {r.case} & {int(r.k)} & {int(r.N)} & {fmt_sci(r.seconds)} & "
                         f"{fmt_sci(r.energy_error)} & {fmt_sci(r.lambda_hm12_error)}{mark} \\\\")
    lines += [r"\bottomrule"]
    if front:
        lines.append(r"\multicolumn{8}{l}{\footnotesize $\bullet$: on the Pareto front (time, energy error) "
                     r"of its scene over all $N$} \\")
    lines += [r"\end{tabular}", ""]
    return "\n".join(lines)


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
    ic = cfg.get("infsup", {})
    if "alpha" in ic:
        out.append(Macro("cfgPerturbAlpha", f"{float(ic['alpha']):g}", "config: infsup.alpha"))
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


# --------------------------------------------------------------------------- assembly

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
    lines = ["% Generated by infsup_contact.papertex (workflow rule paper_macros): do not edit.",
             "% Naming scheme: see the docstring of infsup_contact/papertex.py."]
    lines += [f"\\newcommand{{\\{m.name}}}{{{m.tex}}} % {_ascii(m.source)}" for m in macros]
    return "\n".join(lines) + "\n"


def all_macros(beta, contact, rates, claims, speed, bench_beta, bench_contact, cfg, prov) -> list[Macro]:
    return (beta_macros(beta) + contact_macros(contact) + rates_macros(rates) + claims_macros(claims)
            + speed_macros(speed) + bench_macros(bench_beta, "beta") + bench_macros(bench_contact, "contact")
            + config_macros(cfg) + provenance_macros(beta, prov))


def paper_files(beta, contact, rates, claims, speed, bench_beta, bench_contact, cfg, prov) -> dict[str, str]:
    """Every generated file of results/paper/ (name → text)."""
    return {"macros.tex": macros_tex(all_macros(beta, contact, rates, claims, speed, bench_beta,
                                                bench_contact, cfg, prov)),
            "claims_table.tex": claims_table(claims),
            "rates_table.tex": rates_table(rates),
            "beta_table.tex": beta_table(beta),
            "speed_table.tex": speed_table(speed),
            "front_table.tex": front_table(speed)}


# --------------------------------------------------------------------------- checks on paper.tex

def _strip_comments(tex: str) -> str:
    return re.sub(r"(?<!\\)%.*", "", tex)


def used_generated_macros(tex: str) -> set[str]:
    """Control words of ``tex`` that belong to the generated namespace (MACRO_PREFIXES)."""
    words = set(re.findall(r"\\([A-Za-z]+)", _strip_comments(tex)))
    return {w for w in words if is_generated_name(w)}


def used_inputs(tex: str) -> set[str]:
    return set(re.findall(r"\\input\{([^}]+)\}", _strip_comments(tex)))


def defined_macros(macros_text: str) -> set[str]:
    return set(re.findall(r"\\newcommand\{\\([A-Za-z]+)\}", macros_text))


def check_paper(tex: str, files: dict[str, str]) -> None:
    """Raise PaperTexError unless every generated macro and \\input of ``tex`` is produced."""
    missing_inputs = sorted(f for f in used_inputs(tex) if f not in files)
    missing = sorted(used_generated_macros(tex) - defined_macros(files.get("macros.tex", "")))
    if missing_inputs or missing:
        raise PaperTexError(
            "paper/paper.tex uses what the tables do not provide: "
            + (f"\\input of {', '.join(missing_inputs)}; " if missing_inputs else "")
            + (f"macros {', '.join(missing)} (is that case/k/scene in the config?)" if missing else ""))
