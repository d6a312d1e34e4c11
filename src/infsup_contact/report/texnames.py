"""Names of the paper's generated macros: every number of ``paper/paper.tex`` is a macro named here.

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
``\\lambdaMin<Scene><Case>K<k>``               min_x λ_h(x) at the finest N (sampled)
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
Verdicts are wrapped in ``\\verdictfmt{...}``, which ``paper.tex`` defines; ``\\refOutcome<Ref>``
and ``\\claimOutcome<Id>`` hold the bare word, which ``\\byverdict{...}{if PASS}{if FAIL}{if
INCONCLUSIVE}`` uses to choose a sentence that states an outcome (:mod:`.consistency` checks it).

Each definition in ``macros.tex`` carries its source as a comment. For values read from a
table the source is machine-readable, ``table:column[:min|max] key=value ...`` (the value is
that column of the one row matching every key, or its min/max over the matching rows;
``matching=1`` means N1 = N2), so a test can check every number against its table.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

MACRO_PREFIXES = ("beta", "smallest", "kernel", "dim", "finest", "coarsest", "n", "slope", "stderr",
                  "expected", "error", "iterations", "max", "contact", "ref", "claim", "speed", "bench",
                  "cfg", "prov", "lambda")
"""Generated names are one of these prefixes followed by an upper-case letter (so ``\\beta`` or
``\\ref`` are not generated names, ``\\betaHTthreeKone`` and ``\\refVerdictThmThree`` are);
``paper.tex`` defines no such name itself."""
_GENERATED = re.compile("(?:" + "|".join(MACRO_PREFIXES) + ")[A-Z][A-Za-z]*")


def is_generated_name(name: str) -> bool:
    """True if ``name`` lies in the generated namespace (prefix + upper-case letter + letters)."""
    return _GENERATED.fullmatch(name) is not None


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


def _scene(s, primary: str) -> str:
    """A scene's part of a macro name: none for the primary scene (config
    ``contact.primary_scene``), whose macros the paper's text reads unqualified."""
    return "" if s == primary else s
