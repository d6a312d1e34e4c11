"""Numbers and text as LaTeX: fixed/scientific formatting, escaping, and source notes.

Every generated value is typeset here (β_h 4 decimals, slopes 2, errors and times as
m × 10^e with 3 significant digits), and every source comment is written by :func:`_src`
(``table:column[:min|max] key=value ...``), so a test can check each number against its row.
"""
from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd

from ..criteria.claims import NOT_RUN
from ..discretization.spaces.registry import common_ids

VERDICTS = ("PASS", "FAIL", "INCONCLUSIVE")
LEDGER_VERDICTS = VERDICTS + (NOT_RUN,)
"""A ledger row may also be NOT RUN (an optional code not installed where it was built): it is
typeset and counted on its own, never as one of the three computed verdicts."""
MEASURES = {"energy_error": "Energy", "l2_error": "Ltwo", "lambda_l2_error": "LambdaLtwo",
            "lambda_hm12_error": "LambdaH"}
SPEED_COLUMNS = ("scene", "case", "k", "N", "seconds", "energy_error", "lambda_hm12_error")


class PaperTexError(ValueError):
    """A table lacks what the paper needs; the message names the table and what is missing."""


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
    "ν": r"$\nu$", "∝": r"$\propto$", "δ": r"$\delta$",  # the elastic claims (study/claims/elastic.py)
    "α": r"$\alpha$", "θ": r"$\theta$", "κ": r"$\kappa$", "Ñ": r"$\tilde N$",  # the face studies' claims
    "Δ": r"$\Delta$",  # the curved Γ's claims (study/claims/arc.py)
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
                                "add it to infsup_contact.report.texformat.UNICODE_LATEX")
    return "".join(out)


def latex_id(text, where: str = "an id") -> str:
    """An identifier (case, scene, series, claim id) → LaTeX, every character literal: ``P0_2h``
    stays P0_2h and ``A&B`` stays A&B (no sub/superscripts, unlike :func:`latex_escape`). The one
    path every id of a generated table takes."""
    return _escape_chars(str(text), where)


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


def case_rank(case) -> int:
    """Position of a case in the registry (the paper's order first); unknown ids last."""
    ids = common_ids()
    return ids.index(case) if case in ids else len(ids)


def case_order(cases) -> list:
    return sorted(set(cases), key=lambda c: (case_rank(c), str(c)))
