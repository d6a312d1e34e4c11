"""The multiplier basis of a foreign system described on a flat Γ → the exact Gram matrices.

A code cannot export the H^{-1/2}_00(Γ) Gram of its multipliers; it can say what its
multipliers are. With ``norm: H`` the manifest gives Γ (``gamma``: a segment of length L, or a
rectangle a × b) and per level ``multipliers``: row i of B as a function on Γ. This module
reads that description (inline mapping or a ``.yaml`` file), builds the space with the suite's
own constructors (:func:`~infsup_contact.discretization.segment.multipliers.local_basis_space`,
:func:`~infsup_contact.discretization.segment.multipliers.make_space`,
:func:`~infsup_contact.discretization.segment.dual.dual_space`, tensor products
:class:`~infsup_contact.discretization.face.spaces.tensor.FaceSpace`) and assembles its Gram by the
routes ``beta --norm H`` uses (:mod:`.multiplier_gram`).

Segment forms (coordinate t ∈ [0, L] along Γ)::

    {breakpoints: [...], degree: s, dofs: [[...], ...], coefficients: ...}   # general
    {basis: lagrange, degree: k, breakpoints: [...], ends: keep|drop, nodes: equispaced|gll}  # continuous P_k
    {basis: discontinuous, degree: k, breakpoints: [...], nodes: equispaced|gll}              # discontinuous P_k
    {basis: dual, degree: k, breakpoints: [...], ends: keep|drop}              # biorthogonal dual

The general form is :func:`local_basis_space`'s arguments (``dofs`` = the rows of B, −1 = none;
``coefficients`` = the local basis in the equispaced Lagrange shapes). The helper forms number
their functions left to right; ``rows: [...]`` (``rows[j]`` = the row of B holding the j-th)
says otherwise. ``breakpoints``, ``dofs``, ``coefficients`` and ``rows`` may be file names
(``.txt``: whitespace-separated numbers; ``.npy``). A rectangle face takes ``{x: <segment
form>, y: <segment form>, rows: ...}``: ψ_ij(x, y) = ψ_i(x) ψ_j(y) in row i + n_x j of B.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from .readers import SystemFileError

GAMMA_SHAPES = {"segment": "segment", "rectangle": "square"}  # gamma.shape → its pull-back's shape in the Γ table
BASES = ("lagrange", "discontinuous", "dual")
ENDS = ("keep", "drop")
MAX_DEGREE = 7
"""Largest local degree: the equispaced Lagrange shapes every route uses have positive
Newton–Cotes weights up to 7 (a dual basis exists only there, :func:`~.dual.nodal_integrals`);
the suite's own spaces use s ≤ 4."""
NODES = ("equispaced", "gll")
"""Nodes of a ``lagrange`` / ``discontinuous`` basis: equispaced on each interval, ends included
(t_a = a/s; the midpoint at s = 0), or Gauss–Lobatto–Legendre (the ends and the roots of P_s'):
basix's default variant (``gll_warped``), the GLL points on an interval, so DOLFINx's P_s, s >= 3."""
SEGMENT_KEYS = ("basis", "degree", "breakpoints", "ends", "nodes", "dofs", "coefficients", "rows")
FACE_KEYS = ("x", "y", "rows")
ENDS_RTOL = 1e-12
"""Relative distance to 0 and L within which the first and last breakpoints are Γ's ends (a
producer's coordinates are computed in floating point)."""
DESCRIPTION_MAX_BYTES = 64 << 20
"""Largest ``multipliers`` ``.yaml`` file or ``.txt`` number file read (64 MiB: ~4 million numbers)."""


@dataclass(frozen=True)
class Gamma:
    """Γ as the manifest's ``gamma`` describes it: ``segment`` of ``size`` (L,) or ``rectangle`` of ``size`` (a, b)."""

    shape: str
    size: tuple

    @property
    def interface(self):
        """The Interface of Γ's pull-back (:data:`GAMMA_SHAPES`): the manifest names Γ, nothing is assumed."""
        from ..discretization.spaces.gammas import gamma_of  # the Γ table: imported when asked
        return gamma_of(GAMMA_SHAPES[self.shape])


@dataclass(frozen=True)
class Described:
    """A level's multipliers: ``space`` on the unit interval or square (the pull-back of Γ),
    ``rows[j]`` the row of B holding the space's basis function j, and Γ."""

    space: object
    rows: np.ndarray
    gamma: Gamma
    source: Path
    key: str

    @property
    def m(self) -> int:
        return int(self.space.dim)


def parse_gamma(path, value) -> Gamma:
    """The manifest's ``gamma`` mapping; :class:`SystemFileError` naming the key."""
    if not isinstance(value, dict):
        raise SystemFileError(path, "gamma: expected {shape: segment, length: L} or {shape: rectangle, "
                              f"size: [a, b]}} (found {value!r:.60})")
    shape = value.get("shape")
    if shape not in GAMMA_SHAPES:
        raise SystemFileError(path, f"gamma.shape: {shape!r} is not one of {', '.join(GAMMA_SHAPES)}")
    key = "length" if shape == "segment" else "size"
    unknown = sorted(set(map(str, value)) - {"shape", key})
    if unknown:
        raise SystemFileError(path, f"gamma: unknown key {unknown[0]!r} for a {shape} (allowed: shape, {key})")
    raw = value.get(key)
    size = [raw] if shape == "segment" else raw
    if not isinstance(size, list) or len(size) != (1 if shape == "segment" else 2) or not all(
            _positive(v) for v in size):
        what = "a finite number > 0" if shape == "segment" else "[a, b], two finite numbers > 0"
        raise SystemFileError(path, f"gamma.{key}: expected {what} (found {raw!r:.60})")
    return Gamma(shape, tuple(float(v) for v in size))


def _positive(v) -> bool:
    return not isinstance(v, bool) and isinstance(v, (int, float)) and math.isfinite(v) and v > 0


def describe(manifest_path, index: int, value, gamma: Gamma) -> Described:
    """Level ``index``'s ``multipliers`` (inline mapping, or a ``.yaml`` file relative to the
    manifest) as a :class:`Described` space; :class:`SystemFileError` naming the file and key."""
    where, key = Path(manifest_path), f"levels[{index}].multipliers"
    if isinstance(value, str):  # a file: its arrays' file names are relative to it
        where, key = _load_file(where, key, where.parent / value), "multipliers"
        value = _read_yaml(where)
    space, rows = describe_space(where, key, value, where.parent, gamma)
    return Described(space, rows, gamma, where, key)


def describe_space(where, key, value, base, gamma: Gamma) -> tuple:
    """(space on the pull-back of Γ, the position of each of its functions in the description's
    numbering) of one segment form, or of ``{x, y, rows}`` on a rectangle."""
    if not isinstance(value, dict):
        raise SystemFileError(where, f"{key}: expected a mapping (a segment form, or {{x: ..., y: ...}} on a "
                              f"rectangle) or a .yaml file name (found {value!r:.60})")
    if gamma.shape == "segment":
        return _segment(where, key, value, base, gamma.size[0], face=False)
    return _face(where, key, value, base, gamma)


def _load_file(where, key, path: Path) -> Path:
    if path.suffix.lower() not in (".yaml", ".yml"):
        raise SystemFileError(where, f"{key}: {path.name!r}: expected an inline mapping or a .yaml file")
    if not path.is_file():
        raise SystemFileError(where, f"{key}: no such file {path}")
    return path


def _read_yaml(path: Path):
    import yaml

    from ..yaml_limits import YamlLimitError, load

    if path.stat().st_size > DESCRIPTION_MAX_BYTES:
        raise SystemFileError(path, f"{path.stat().st_size} bytes: a multiplier description is read up to "
                              f"{DESCRIPTION_MAX_BYTES >> 20} MiB; give long arrays as .npy files")
    try:
        return load(path.read_text())
    except YamlLimitError as err:
        raise SystemFileError(path, f"{err.key or 'the document'} (line {err.line}): {err.problem}") from None
    except (yaml.YAMLError, UnicodeDecodeError) as err:
        raise SystemFileError(path, f"not readable YAML ({' '.join(str(err).split())[:120]})") from None


def _face(where, key, value, base, gamma):
    from ..discretization.face.spaces.tensor import FaceSpace
    from ..discretization.face.partitions.tensor_grid import TensorPartition

    _keys(where, key, value, FACE_KEYS, "a rectangle's multipliers")
    factors = []
    for axis, length in zip("xy", gamma.size):
        if axis not in value:
            raise SystemFileError(where, f"{key}: missing key {axis!r} (a rectangle takes {{x: <segment form>, "
                                  "y: <segment form>}})")
        if not isinstance(value[axis], dict):
            raise SystemFileError(where, f"{key}.{axis}: expected a segment form (a mapping; found "
                                  f"{value[axis]!r:.60})")
        if "rows" in value[axis]:
            raise SystemFileError(where, f"{key}.{axis}.rows: give the face's row order once, as {key}.rows "
                                  "(row of B = i + n_x j by default)")
        factors.append(_segment(where, f"{key}.{axis}", value[axis], base, length, face=True)[0])
    sx, sy = factors
    _fits(where, key, sx.dim * sy.dim)
    space = FaceSpace(sx, sy, TensorPartition(sx.breakpoints, sy.breakpoints))
    # FaceSpace numbers ψ_i(x) ψ_j(y) as i n_y + j; the description counts it i + n_x j
    i, j = np.divmod(np.arange(space.dim), sy.dim)
    counted = i + sx.dim * j
    order = _rows(where, f"{key}.rows", value.get("rows"), base, space.dim)
    return space, counted if order is None else order[counted]


BYTES_PER_FUNCTION = 64
"""Bytes per described function of the arrays made before B's rows are compared (the numbering,
its inverse, the face's counting): a face of n_x × n_y functions is refused here when even those
do not fit (two 10⁵-interval axes are 10¹⁰ functions), before its Gram is estimated."""


def _fits(where, key, m: int) -> None:
    from .. import resources

    avail = resources.available_bytes()
    if avail is not None and BYTES_PER_FUNCTION * m > avail:
        raise SystemFileError(where, f"{key}: describes {m} functions: their numbering alone needs "
                              f"~{resources.human_bytes(BYTES_PER_FUNCTION * m)}, {resources.human_bytes(avail)} available")


def _keys(where, key, value, allowed, what):
    unknown = sorted(set(map(str, value)) - set(allowed))
    if unknown:
        raise SystemFileError(where, f"{key}: unknown key {unknown[0]!r} in {what} (allowed: {', '.join(allowed)})")


def _segment(where, key, value, base, length: float, face: bool):
    """(SegmentSpace on the pull-back (0, 1), rows of B in its numbering) of a segment form."""
    from ..discretization.segment.dual import dual_space
    from ..discretization.segment.multipliers import local_basis_space, make_space

    _keys(where, key, value, SEGMENT_KEYS, "a segment form")
    basis = value.get("basis")
    if basis is not None and basis not in BASES:
        raise SystemFileError(where, f"{key}.basis: {basis!r} is not one of {', '.join(BASES)} (or leave it out "
                              "for the general form: breakpoints, degree, dofs, coefficients)")
    s = value.get("degree")
    low = 1 if basis in ("lagrange", "dual") else 0
    if isinstance(s, bool) or not isinstance(s, int) or not low <= s <= MAX_DEGREE:
        raise SystemFileError(where, f"{key}.degree: expected an integer in {low}..{MAX_DEGREE}"
                              f"{' for basis ' + basis if basis else ''} (found {s!r:.40})")
    x = _breakpoints(where, f"{key}.breakpoints", value.get("breakpoints"), base, length)
    if basis is None:
        for extra in ("ends", "rows"):
            if extra in value:
                raise SystemFileError(where, f"{key}.{extra}: only with a helper form (basis: {', '.join(BASES)}); "
                                      "the general form's dofs give the rows of B")
        if "dofs" not in value:
            raise SystemFileError(where, f"{key}: missing key 'dofs' (the general form: breakpoints, degree, dofs "
                                  "[, coefficients]; or a helper form with basis: " + ", ".join(BASES) + ")")
        n = len(x) - 1
        dofs = _array(where, f"{key}.dofs", value["dofs"], base, integer=True)
        if dofs.ndim == 1 and dofs.size == n * (s + 1):
            dofs = dofs.reshape(n, s + 1)  # a file holds them flat, interval by interval
        coef = value.get("coefficients")
        if coef is not None:
            coef = _array(where, f"{key}.coefficients", coef, base, integer=False)
            if coef.ndim == 1 and coef.size in ((s + 1) ** 2, n * (s + 1) ** 2):
                coef = coef.reshape(-1, s + 1, s + 1)
                coef = coef[0] if len(coef) == 1 else coef
        try:
            space = local_basis_space(x, s, dofs, coef)
        except InputError as err:
            raise SystemFileError(where, f"{key}.{err.key}: expected {err.allowed}"
                                  + ("" if err.got is None else f" (found {err.got!r})")) from None
        _nonzero(where, key, space)
        return space, np.arange(space.dim)
    if "dofs" in value or "coefficients" in value:
        bad = "dofs" if "dofs" in value else "coefficients"
        raise SystemFileError(where, f"{key}.{bad}: only in the general form (without basis:); basis {basis} "
                              "numbers its functions left to right (rows: to permute)")
    ends = value.get("ends", "keep")
    if ends not in ENDS or (basis == "discontinuous" and s == 0 and ends == "drop"):
        allowed = "keep (discontinuous P_0 has no end nodes)" if basis == "discontinuous" and s == 0 else \
            " or ".join(ENDS)
        raise SystemFileError(where, f"{key}.ends: {ends!r}: expected {allowed}")
    drop = ends == "drop"
    nodes = value.get("nodes", "equispaced")
    if nodes not in NODES or (nodes != "equispaced" and basis == "dual"):
        raise SystemFileError(where, f"{key}.nodes: {nodes!r}: expected " + (" or ".join(NODES) if basis != "dual"
                              else "equispaced (nodes: only with basis lagrange or discontinuous)"))
    if basis == "dual":
        space = dual_space(x, s, drop)
    else:
        space = make_space(x, s, basis == "lagrange", drop)
        space = gll_nodes(space) if nodes == "gll" else space
    if space.dim < 1:
        raise SystemFileError(where, f"{key}: the {basis} basis of degree {s} with ends {ends} on {len(x) - 1} "
                              "interval(s) is empty")
    order = None if face else _rows(where, f"{key}.rows", value.get("rows"), base, space.dim)
    return space, (np.arange(space.dim) if order is None else order)


def gll_nodes(space):
    """The same space with its Lagrange basis on the GLL nodes of each interval: per interval
    ψ_a = Σ_b ℓ_a(t_b) L_b (ℓ_a the GLL Lagrange polynomial, L_b the equispaced shape of node t_b).
    Up to s = 2 the GLL nodes are the equispaced ones: the space itself."""
    from dataclasses import replace

    from ..discretization.segment.multipliers import reference_nodes

    s, eq = space.degree, reference_nodes(space.degree)
    if s <= 2:
        return space
    t = np.concatenate([[0.0], (np.sort(np.polynomial.legendre.Legendre.basis(s).deriv().roots().real) + 1) / 2, [1]])
    C = [[np.prod([(eq[b] - t[c]) / (t[a] - t[c]) for c in range(s + 1) if c != a]) for b in range(s + 1)]
         for a in range(s + 1)]
    return replace(space, local_coefficients=np.broadcast_to(C, (space.n_intervals, s + 1, s + 1)).copy())


def _nonzero(where, key, space) -> None:
    """Every basis function of a general form has a non-zero piece (cheap, before any Gram; a
    subtler linear dependence is found where the Gram is factorized)."""
    if space.local_coefficients is None:
        return
    size = np.zeros(space.dim)
    live = space.dofs >= 0
    np.add.at(size, space.dofs[live], np.abs(space.local_coefficients).sum(axis=2)[live])
    if np.any(size == 0):
        j = int(np.flatnonzero(size == 0)[0])
        raise SystemFileError(where, f"{key}.coefficients: basis function {j} (row {j} of B) is zero on every "
                              "interval: a basis has no zero function")


def _breakpoints(where, key, value, base, length: float) -> np.ndarray:
    """The breakpoints mapped to (0, 1): strictly increasing from 0 to L (to :data:`ENDS_RTOL`)."""
    if value is None:
        raise SystemFileError(where, f"{key}: missing (the partition of Γ, 0 = t_0 < ... < t_N = {length:g})")
    x = _array(where, key, value, base, integer=False)
    if x.ndim != 1 or len(x) < 2:
        raise SystemFileError(where, f"{key}: expected at least 2 numbers in a flat list (found shape {x.shape})")
    if not np.all(np.diff(x) > 0):
        i = int(np.flatnonzero(~(np.diff(x) > 0))[0])
        raise SystemFileError(where, f"{key}: not strictly increasing (entries {i} and {i + 1}: {float(x[i])!r}, "
                              f"{float(x[i + 1])!r})")
    if abs(x[0]) > ENDS_RTOL * length or abs(x[-1] - length) > ENDS_RTOL * length:
        raise SystemFileError(where, f"{key}: runs from {float(x[0])!r} to {float(x[-1])!r}; it must cover "
                              f"Γ = [0, {length!r}] "
                              "(gamma's length), first and last breakpoint its ends")
    t = x / length
    t[0], t[-1] = 0.0, 1.0
    if not np.all(np.diff(t) > 0):
        raise SystemFileError(where, f"{key}: breakpoints closer than the round-off of their scale")
    return t


def _rows(where, key, value, base, m: int):
    """The permutation ``rows`` (None if not given): a permutation of 0..m-1."""
    if value is None:
        return None
    rows = _array(where, key, value, base, integer=True).ravel()
    if len(rows) != m or not np.array_equal(np.sort(rows), np.arange(m)):
        raise SystemFileError(where, f"{key}: expected a permutation of 0..{m - 1} (the row of B of each of the "
                              f"{m} basis functions; found {len(rows)} entries"
                              + ("" if len(rows) != m else ", not each row once") + ")")
    return rows


def _array(where, key, value, base, integer: bool) -> np.ndarray:
    """A list (nested lists) of numbers, or a file (``.txt`` / ``.npy``) relative to ``base``."""
    if isinstance(value, str):
        return _read_numbers(where, key, base / value, integer)
    try:
        arr = np.array(value, dtype=object)
        if arr.dtype == object and arr.size and any(isinstance(v, (bool, str, list, dict, type(None)))
                                                   for v in arr.ravel()):
            raise ValueError
        arr = arr.astype(float)
    except (TypeError, ValueError):
        raise SystemFileError(where, f"{key}: expected {'integers' if integer else 'numbers'} in a (nested) list of "
                              f"equal lengths, or a .txt/.npy file name (found {str(value)[:60]!r})") from None
    return _checked(where, key, arr, integer)


def _checked(where, key, arr, integer):
    if not np.all(np.isfinite(arr)):
        raise SystemFileError(where, f"{key}: holds a non-finite number")
    if integer:
        if np.any(arr != np.round(arr)):
            raise SystemFileError(where, f"{key}: expected integers")
        return arr.astype(np.int64)
    return arr


def _read_numbers(where, key, path: Path, integer: bool) -> np.ndarray:
    """Numbers of a ``.npy`` file (its header checked against its size and the memory first) or
    of a ``.txt`` file (whitespace- or comma-separated, ``#`` comments; ends with a newline)."""
    from .file_checks import check_read_memory
    from .readers import check_npy_file

    if not path.is_file():
        raise SystemFileError(where, f"{key}: no such file {path}")
    if path.suffix == ".npy":
        check_npy_file(path)
        try:
            arr = np.load(path, allow_pickle=False)
        except (OSError, ValueError) as err:
            raise SystemFileError(path, f"not a numpy array file ({type(err).__name__})") from None
        if not (np.issubdtype(arr.dtype, np.integer) or np.issubdtype(arr.dtype, np.floating)):
            raise SystemFileError(path, f"{key}: dtype {arr.dtype}, expected numbers")
        return _checked(path, key, arr.astype(float), integer)
    if path.suffix != ".txt":
        raise SystemFileError(where, f"{key}: {path.name!r}: expected a .txt or .npy file")
    size = path.stat().st_size
    if size > DESCRIPTION_MAX_BYTES:
        raise SystemFileError(path, f"{size} bytes: a .txt number file is read up to {DESCRIPTION_MAX_BYTES >> 20} "
                              "MiB; give long arrays as .npy")
    check_read_memory(path, size // 2 + 1, 1, None, "numbers")
    raw = path.read_bytes()
    if raw and not raw.endswith(b"\n"):
        raise SystemFileError(path, f"{key}: the file does not end with a newline: cut short? (its last number "
                              "may be incomplete)")
    try:
        text = raw.decode()
        tokens = [t for line in text.splitlines() for t in line.split("#", 1)[0].replace(",", " ").split()]
        arr = np.array([float(t) for t in tokens])
    except (UnicodeDecodeError, ValueError) as err:
        raise SystemFileError(path, f"{key}: not whitespace-separated numbers ({' '.join(str(err).split())[:80]})") \
            from None
    return _checked(path, key, arr, integer)
