"""The manifest of a foreign system: a YAML list of mesh levels, paths relative to it.

Minimal form (works as written)::

    levels:
      - {h: 0.25,  A: A4.mtx,  B: B4.mtx,  G: G4.mtx}
      - {h: 0.125, A: A8.mtx,  B: B8.mtx,  G: G8.mtx}
      - {h: 0.0625, A: A16.mtx, B: B16.mtx, G: G16.mtx}

A (n × n) SPD, B (m × n), G (m × m) the multiplier norm. Optional keys:

``name``
    the pair of spaces, printed in the verdict row (default: the manifest's file name);
``norm``
    what G is: ``given`` (default: the norm the inf-sup condition is stated in, e.g. the
    pressure L² mass of Stokes, or an H^{-1/2} Gram), ``L2`` (the L² mass of *contact*
    multipliers, whose proper norm is H^{-1/2}: the row is the L² verdict, Remark 3.1) or
    ``h-L2`` (G replaced by h·G, the mesh-dependent norm, with its caveat printed) or ``H``
    (the H^{-1/2}_00(Γ) Gram assembled here from a description of the multipliers: the top
    key ``gamma`` and per level ``multipliers``, :mod:`.multiplier_basis`; G is then
    optional and, where given, the L² mass of the described basis, checked against it);
``known_kernel``
    dimension of a kernel of Bᵀ the producer knows of (the constant pressure of an enclosed
    Stokes flow: 1); β_h is reported on its complement, and a larger kernel is UNSTABLE;
``tgv``
    ``eliminate`` (default) or ``refuse`` dofs fixed by a huge diagonal penalty (in A or G);
``entry_rtol``
    the accuracy of B's entries relative to max |b_ij| (a number in [0, 1); ``1e-15`` for
    entries summed from quadrature products): it raises the kernel threshold η (module
    :mod:`.roundoff`); where the data show more round-off than declared, that is used;
``expect``
    ``stable`` or ``unstable``: the verdict the producer expects (the exit code of ``verdict``
    without ``--expect`` and of the pre-commit hook follows it);
per level, ``constrained``
    the 0-based dofs the producer fixed but left in A (identity or penalty rows): a list,
    or a file (``.txt``: whitespace-separated integers, ``.npy``); they are removed;
per level, ``C``
    the stabilisation of the (2,2) block, a file like G (m × m, symmetric positive
    semidefinite): the system is [[A, Bᵀ], [B, −C]] and β_C² = λ_min(B A⁻¹ Bᵀ + C, G) is
    certified beside the unstabilised β_h (:mod:`.stabilised`);
per level, ``multipliers`` (required with ``norm: H``) and ``traces``, with the top key ``gamma``
    the description of B's rows on Γ (:mod:`.multiplier_basis`) and of the bodies' trace bases
    (:mod:`.mortar_distance`). With ``norm: H`` G is optional and the Gram is assembled from the
    description; with ``L2`` or ``h-L2`` G (the L² mass) is checked against it; with ``given``
    G is taken as it is. ``traces`` add B's distance to the exact coupling to the row.
"""
from __future__ import annotations

import math
import unicodedata
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..io import TableError, read_integer_list

from .readers import SystemFileError

NORMS = ("given", "L2", "h-L2", "H")
TGV_POLICIES = ("eliminate", "refuse")
LEVEL_KEYS = ("h", "A", "B", "G", "constrained", "multipliers", "traces", "C")
TOP_KEYS = ("levels", "name", "norm", "known_kernel", "tgv", "expect", "entry_rtol", "gamma")
EXPECTS = ("stable", "unstable")
MANIFEST_MAX_BYTES = 1 << 20
"""Largest manifest read (a manifest of 1,000 levels is ~60 kB)."""
MIN_LEVELS = 3
"""A slope's confidence interval needs n − 2 ≥ 1 degrees of freedom (as ``verdict --case``)."""


@dataclass(frozen=True)
class Level:
    """One mesh level: its size and its three files (absolute paths; G None when ``norm: H``
    leaves it out)."""

    index: int
    h: float
    A: Path
    B: Path
    G: Path | None
    constrained: object = None  # None, a list of ints, or a Path
    multipliers: object = None  # with norm H: the description (a mapping) or its file (a str)
    traces: object = None  # with norm H, optional: the bodies' trace bases (mortar_distance)
    C: Path | None = None  # the stabilisation: the (2,2) block is −C (module .stabilised)


@dataclass(frozen=True)
class Manifest:
    """A parsed, checked manifest (module docstring)."""

    path: Path
    name: str
    norm: str
    known_kernel: int
    tgv: str
    levels: tuple
    expect: str | None = None
    entry_rtol: float | None = None
    gamma: object = None  # with norm H: a multiplier_basis.Gamma


def load_manifest(path, min_levels: int = MIN_LEVELS) -> Manifest:
    """Read and check ``path``; :class:`SystemFileError` naming the manifest and the key."""
    import yaml

    path = Path(path)
    try:
        given, path = path, path.resolve(strict=True)  # a symlinked manifest: its matrices lie beside the target
    except (OSError, RuntimeError) as err:  # missing, or a symlink loop (ELOOP; RuntimeError before Python 3.13)
        raise SystemFileError(path, "no such manifest file" + (" (a symlink loop)" if "loop" in str(err).lower()
                                                               or isinstance(err, RuntimeError) else "")) from None
    if not path.is_file():
        raise SystemFileError(given, "no such manifest file")
    if path.stat().st_size > MANIFEST_MAX_BYTES:
        raise SystemFileError(path, f"{path.stat().st_size} bytes: a manifest lists a few levels (at most "
                              f"{MANIFEST_MAX_BYTES // 2 ** 20} MiB read); is this the manifest?")
    from ..yaml_limits import YamlLimitError, load

    try:
        data = load(path.read_text())
    except YamlLimitError as err:
        raise SystemFileError(path, f"{err.key or 'the document'} (line {err.line}): {err.problem}") from None
    except (yaml.YAMLError, UnicodeDecodeError) as err:
        raise SystemFileError(path, f"not readable YAML ({' '.join(str(err).split())[:120]})") from None
    if not isinstance(data, dict):
        raise SystemFileError(path, f"expected a mapping with the key 'levels' (found {type(data).__name__})")
    unknown = sorted(set(map(str, data)) - set(TOP_KEYS))
    if unknown:
        raise SystemFileError(path, f"unknown key {unknown[0]!r} (allowed: {', '.join(TOP_KEYS)})")
    levels = data.get("levels")
    if not isinstance(levels, list) or not levels:
        raise SystemFileError(path, f"'levels' must be a non-empty list of {{h, A, B, G}} (found {levels!r:.60})")
    if len(levels) < min_levels:
        raise SystemFileError(path, f"'levels' has {len(levels)} entries; a verdict needs at least {min_levels} "
                              "(the slope's confidence interval needs n - 2 >= 1)")
    name = data.get("name", given.stem)
    if isinstance(name, bool) or not isinstance(name, (str, int, float)):
        raise SystemFileError(path, f"name: expected one line of text (found a {type(name).__name__})")
    _one_line(path, "name", str(name))
    norm = data.get("norm", "given")
    if norm not in NORMS:
        raise SystemFileError(path, f"norm: {norm!r} is not one of {', '.join(NORMS)}")
    tgv = data.get("tgv", "eliminate")
    if tgv not in TGV_POLICIES:
        raise SystemFileError(path, f"tgv: {tgv!r} is not one of {', '.join(TGV_POLICIES)}")
    known = data.get("known_kernel", 0)
    if isinstance(known, bool) or not isinstance(known, int) or known < 0:
        raise SystemFileError(path, f"known_kernel: expected an integer >= 0 (found {known!r})")
    expect = data.get("expect")
    if expect is not None and expect not in EXPECTS:
        raise SystemFileError(path, f"expect: {expect!r} is not one of {', '.join(EXPECTS)}")
    entry_rtol = _entry_rtol(path, data.get("entry_rtol"))
    parsed = tuple(_level(path, i, entry, norm) for i, entry in enumerate(levels))
    gamma = _gamma(path, data, norm, parsed)
    with_c = [lv.index for lv in parsed if lv.C is not None]
    if with_c and len(with_c) < len(parsed):  # a β_C series needs every level
        gap = next(lv.index for lv in parsed if lv.C is None)
        raise SystemFileError(path, f"levels[{gap}]: no key 'C' where levels[{with_c[0]}] has one: give the "
                              "stabilisation C on every level or on none")
    hs = [lv.h for lv in parsed]
    for i in range(1, len(hs)):
        if not hs[i] < hs[i - 1]:
            raise SystemFileError(path, f"levels[{i}].h = {hs[i]:g} does not decrease (levels[{i - 1}].h = "
                                  f"{hs[i - 1]:g}): list the levels coarse to fine, each h once")
    return Manifest(path, str(name), norm, known, tgv, parsed, expect=expect, entry_rtol=entry_rtol,
                    gamma=gamma)


def _gamma(path, data, norm: str, levels):
    """The top key ``gamma``: required with norm H, and wherever a level describes its multipliers
    (with norm L2 or h-L2 they check G, the L² mass, and give the traces' distance); refused
    where nothing is described (it would be read for nothing)."""
    from .multiplier_basis import parse_gamma

    described = [lv.index for lv in levels if lv.multipliers is not None]
    if "gamma" not in data:
        if norm == "H" or described:
            raise SystemFileError(path, "norm: H and a level's 'multipliers' need the key 'gamma' ({shape: segment, "
                                  "length: L} or {shape: rectangle, size: [a, b]})")
        return None
    if not described:
        raise SystemFileError(path, "gamma: no level describes its multipliers (levels[i].multipliers), so Γ "
                              "has no use here")
    return parse_gamma(path, data["gamma"])


def _entry_rtol(path, value):
    """The declared ``entry_rtol`` (None when absent). YAML 1.1 reads ``1e-15`` (no dot) as text,
    so a string that is a plain number is taken as that number."""
    if value is None:
        return None
    try:
        rtol = float(value) if isinstance(value, (str, int, float)) and not isinstance(value, bool) else math.nan
    except ValueError:
        rtol = math.nan
    if not (math.isfinite(rtol) and 0.0 <= rtol < 1.0):
        raise SystemFileError(path, f"entry_rtol: expected a number in [0, 1), the accuracy of B's entries relative "
                              f"to max |b_ij| (e.g. 1e-15; found {value!r:.40})")
    return rtol


def _one_line(path, key: str, text: str) -> None:
    """Refuse a control character (CR, LF, tab, ESC ...) or a line separator in a value that is
    printed into a CSV row or a message: it would split the row or rewrite the terminal."""
    for pos, ch in enumerate(text):
        if unicodedata.category(ch) in ("Cc", "Zl", "Zp"):
            raise SystemFileError(path, f"{key}: the control character {ch!r} (U+{ord(ch):04X}) at position {pos}; "
                                  "a name or file name is one line of printable text")


def _level(path: Path, i: int, entry, norm: str = "given") -> Level:
    where = f"levels[{i}]"
    if not isinstance(entry, dict):
        raise SystemFileError(path, f"{where}: expected a mapping {{h, A, B, G}} (found {entry!r:.60})")
    unknown = sorted(set(map(str, entry)) - set(LEVEL_KEYS))
    if unknown:
        raise SystemFileError(path, f"{where}: unknown key {unknown[0]!r} (allowed: {', '.join(LEVEL_KEYS)})")
    needed = ("h", "A", "B", "multipliers") if norm == "H" else ("h", "A", "B", "G")
    missing = [k for k in needed if k not in entry]
    if missing:
        raise SystemFileError(path, f"{where}: missing key {missing[0]!r} (each level needs {', '.join(needed)}"
                              + (")" if norm != "H" else "; G optional: the L2 mass)"))
    if "traces" in entry and "multipliers" not in entry:
        raise SystemFileError(path, f"{where}.traces: only with {where}.multipliers (the coupling is measured "
                              "against the described multipliers)")
    for key in ("multipliers", "traces", "constrained"):  # a key written with no value: never "absent"
        if key in entry and entry[key] is None:
            raise SystemFileError(path, f"{where}.{key}: no value (null); give one or leave the key out")
    mult = entry.get("multipliers")
    if isinstance(mult, str):
        _one_line(path, f"{where}.multipliers", mult)
    elif mult is not None and not isinstance(mult, dict):
        raise SystemFileError(path, f"{where}.multipliers: expected a mapping or a .yaml file name "
                              f"(found {mult!r:.60})")
    h = entry["h"]
    if isinstance(h, bool) or not isinstance(h, (int, float)) or not math.isfinite(h) or h <= 0:
        raise SystemFileError(path, f"{where}.h: expected a finite number > 0 (found {h!r})")
    files = {}
    for key in ("A", "B", "G", "C"):
        if key in ("G", "C") and key not in entry:
            files[key] = None
            continue
        if not isinstance(entry[key], str) or not entry[key]:
            raise SystemFileError(path, f"{where}.{key}: expected a file name (found {entry[key]!r})")
        _one_line(path, f"{where}.{key}", entry[key])
        files[key] = (path.parent / entry[key]).resolve()
    con = entry.get("constrained")
    if isinstance(con, str):
        _one_line(path, f"{where}.constrained", con)
        con = (path.parent / con).resolve()
    elif con is not None:
        if not isinstance(con, list) or any(isinstance(c, bool) or not isinstance(c, int) or c < 0 for c in con):
            raise SystemFileError(path, f"{where}.constrained: expected a file or a list of integers >= 0")
    return Level(i, float(h), files["A"], files["B"], files["G"], con, mult, entry.get("traces"), files["C"])


def constrained_dofs(level: Level, n: int) -> np.ndarray:
    """The level's declared constrained dofs as a sorted int array, checked against n."""
    con = level.constrained
    if con is None:
        return np.zeros(0, int)
    if isinstance(con, Path):
        if not con.is_file():
            raise SystemFileError(con, "no such file (levels[{}].constrained)".format(level.index))
        if con.suffix == ".npy":
            from .readers import check_npy_file

            shape = check_npy_file(con)  # a header declaring more than the file holds: refused before reading
            count = int(np.prod(shape, dtype=object)) if shape else 1
            if count > n:  # more dofs than A has rows: refused before its body is read
                raise SystemFileError(con, f"its header declares {count} constrained dofs, more than the {n} rows "
                                      "of A (each dof once, 0-based)")
        try:
            raw = read_integer_list(con)
        except TableError as err:
            raise SystemFileError(con, f"not a list of integers ({err})") from None
        except OverflowError:  # an index beyond int64: outside any A
            raise SystemFileError(con, f"a constrained dof beyond 64-bit integers, outside 0..{n - 1} (A has {n} "
                                  "rows; indices are 0-based)") from None
        where = con
    else:
        where = f"levels[{level.index}].constrained"
        big = [c for c in con if c >= n]
        if big:  # Python ints of any size: checked before numpy (10**20 is no int64)
            raise SystemFileError(where, f"constrained dof {big[0]} outside 0..{n - 1} (A has {n} rows; indices "
                                  "are 0-based)")
        raw = np.asarray(con, dtype=np.int64)
    dofs = np.asarray(raw).ravel()
    if dofs.size and (not np.all(np.isfinite(dofs)) or np.any(dofs != np.round(dofs))):
        raise SystemFileError(where, "constrained dofs must be integers")
    dofs = np.unique(dofs.astype(int))
    if dofs.size and (dofs[0] < 0 or dofs[-1] >= n):
        raise SystemFileError(where, f"constrained dof {int(dofs[-1] if dofs[-1] >= n else dofs[0])} outside "
                              f"0..{n - 1} (A has {n} rows; indices are 0-based)")
    return dofs
