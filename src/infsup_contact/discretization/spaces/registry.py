"""One registry of multiplier spaces: every consumer asks it, none special-cases a case id.

An entry (:class:`~.spec.SpaceSpec`) carries what the suite needs to know about a space besides
its basis (how to build it, on which Γ, for which k, what is expected of it). β_h, the contact
solver, the ledger, the figures and the paper iterate over the registry; a new space (built in,
or a user's, :func:`register`) appears in all of them, drawn in the colour and marker the
report's style gives its id.

The paper's five cases (Section 5, eqs. (5.3)/(5.5)) are registered here, in the paper's order,
then the dual bases, then the face-only spaces of :mod:`.face_entries`.
"""
from __future__ import annotations

import functools

import numpy as np

from ...errors import InputError
from ..face.shapes.square import CELL_BODIES
from ..gamma.multiplier_meshes import MULTIPLIER_MESHES, intervals_per_direction
from ..segment.dual import dual_space
from ..segment.multipliers import SegmentSpace, make_space
from .face_entries import FACE_SPACES
from .spec import SpaceSpec

SPACES: dict[str, SpaceSpec] = {}
"""Every registered space by id, in registration order (the paper's first)."""


def register(spec: SpaceSpec) -> SpaceSpec:
    """Add a space to the registry; an id can be registered once, a Petrov–Galerkin pair after its
    trial and test spaces."""
    if spec.id in SPACES and SPACES[spec.id] is not spec:
        raise InputError("space", f"an id not yet registered ({', '.join(SPACES)})", got=spec.id)
    for role in ("trial_space", "test_space") if spec.petrov_galerkin else ():
        if getattr(spec, role) not in SPACES:
            raise InputError(role, f"a registered id ({', '.join(SPACES)})", got=getattr(spec, role))
    SPACES[spec.id] = spec
    return spec


def space_spec(case: str) -> SpaceSpec:
    """The registry entry of ``case``; :class:`InputError` names the known ids otherwise."""
    if case not in SPACES:
        raise InputError("case", ", ".join(SPACES), got=case)
    return SPACES[case]


GAMMA_DIMS = (1, 2)
"""The dimensions Γ takes: a curve between 2D bodies, a surface between 3D bodies."""


def space_ids(gamma_dim: int | None) -> tuple:
    """The registered ids defined on an interface of dimension ``gamma_dim`` (the request's
    ``Γ.dim``; None: all, e.g. the command line's choices), in registry order."""
    return tuple(c for c, spec in SPACES.items() if gamma_dim is None or spec.defined_on(gamma_dim))


def ids_valid_for(k: int, ids) -> list:
    """The ids of ``ids`` defined for displacement degree k (``ids``: a config's list, or
    :func:`space_ids` of the request's Γ)."""
    return [c for c in ids if SPACES[c].valid_for(k)]


def common_ids(k: int | None = None) -> list:
    """The registered ids every Γ builds (defined on curves and surfaces alike: the paper's list
    and the duals), valid for degree k (None: any), in registry order: a request's default
    cases, to which a 3D request's ``--case all`` adds its face's own (``cli.request.face_cases``)."""
    common = [c for c, spec in SPACES.items() if all(spec.defined_on(d) for d in GAMMA_DIMS)]
    return common if k is None else ids_valid_for(k, common)


def ids_built_on(k: int, gamma, partition) -> list:
    """The registered ids valid for degree k that ``gamma`` builds on ``partition``: defined on
    its dimension and its cells (``gamma.builds``, a face's rectangles or triangles), and not
    refused there (an entry that refuses its construction, e.g. a dual basis with a weight
    ≤ 0 such as DUAL-Q8, raises :class:`InputError` "case" naming its remedy; it is left out)."""
    out = []
    for case in ids_valid_for(k, space_ids(gamma.dim)):
        if not gamma.builds(SPACES[case]):
            continue
        try:
            gamma.space(SPACES[case], k, partition)
        except InputError as err:
            if err.key != "case":
                raise
            continue
        out.append(case)
    return out


def edge_cases(k: int) -> list:
    """Registered spaces that make sense on a moving face boundary (edge dropping, a face clipped
    at x = L, :mod:`infsup_contact.study.face.edge_dropping`): every case valid for k whose 1D factor does not
    vanish at the ends (a space vanishing on ∂(Ω1's face) does not vanish on the edge x = L of
    Γ: not the natural analogue)."""
    x = np.linspace(0.0, 1.0, 5)
    return [c for c in common_ids(k) if not space_spec(c).build(k, x).vanish_at_ends]


def check_case(case: str, k: int) -> None:
    """Raise :class:`InputError` unless ``case`` is registered and valid for degree ``k``."""
    spec = space_spec(case)
    if k < spec.min_k:
        raise InputError("k", f"k >= {spec.min_k} for case {case} ({spec.paper_ref} needs k >= {spec.min_k})")


def case_space(case: str, k: int, partition, gamma, pair: bool = False) -> SegmentSpace:
    """The multiplier space of a registered case for displacement degree k on G_h, a
    ``partition`` of Γ = ``gamma`` (:mod:`.gamma.interface`; for the paper's segment the sorted
    breakpoints of G_h, what ``SpaceSpec.build(k, x)`` receives; for the face
    :class:`~.face.shapes.square.Square` a tensor partition, on which the space is the tensor product of
    the 1D builds, :meth:`~.gamma.interface.Interface.space`). A Petrov–Galerkin pair (``trial_space``,
    ``test_space``) is refused after those checks unless ``pair`` (its caller knows it has two bases):
    then its trial space is returned.

    Raises
    ------
    InputError
        For a partition with no interval or a space of dimension 0 on it (nothing to compute:
        the eigenproblems and solves would fail deep inside numpy), naming the case, N and k.
    """
    return space_on(check_on_gamma(case, k, gamma), k, partition, gamma, pair)


def check_on_gamma(case: str, k: int, gamma) -> SpaceSpec:
    """The entry of ``case``, checked once, before any mesh: registered, valid for degree k,
    defined on Γ's dimension and built on its cells (:meth:`~.gamma.interface.Interface.builds`);
    else one :class:`InputError` naming ``case`` (or ``k``)."""
    check_case(case, k)
    spec = SPACES[case]
    if not spec.defined_on(gamma.dim):
        bodies = " and ".join(CELL_BODIES.get(c, c) for c in spec.face_cells)
        raise InputError("case", f"a space defined on this Γ (dimension {gamma.dim}): {case} ({spec.paper_ref}) is "
                         f"defined on the face of a 3D model only, on {bodies} (e.g. --model membranes3d)", got=case)
    gamma.check_builds(spec)
    return spec


def space_on(spec: SpaceSpec, k: int, partition, gamma, pair: bool = False):
    """The multiplier space of a checked entry (:func:`check_on_gamma`) on G_h = ``partition`` of
    ``gamma`` (:func:`case_space`'s construction and its refusals of an empty space or a pair)."""
    case = spec.id
    space = gamma.space(spec, k, partition)  # the interface builds it (a face: tensor products)
    n = gamma.cells(space.breakpoints)
    if space.dim < 1:
        low = min_intervals(case, k)
        raise InputError("N", f"a multiplier mesh on which case {case} with k = {k} is not empty (dim M_h = 0 "
                         f"on N = {n} intervals{'' if low is None else f'; it needs N >= {low}'})", got=n)
    if spec.petrov_galerkin and not pair:  # two bases: a consumer of one would silently take the trial space's
        raise InputError("case", f"a space with one basis for trial and test ({case} is the Petrov–Galerkin "
                         f"pair {spec.trial_space} × {spec.test_space}: infsup-contact beta and verdict only)",
                         got=case)
    return space


# --- empty spaces: refused before any computation ----------------------------------------
MAX_MIN_INTERVALS = 64
"""Search limit of :func:`min_intervals` (a space empty on 64 intervals is empty for the suite)."""


def case_name(case) -> str:
    """A registered id, the id of an (unregistered) :class:`SpaceSpec`, or the label of a
    general triple ``(label, s, continuous, vanish)``."""
    if isinstance(case, SpaceSpec):
        return case.id
    return case if isinstance(case, str) else str(case[0])


def space_dim(case, k: int, n: int) -> int:
    """dim M_h of ``case`` (an id, its entry, or a triple ``(label, s, continuous, vanish)``,
    eqs. (5.3)/(5.5)) for degree k on N uniform intervals, built (1D, cheap): the build, not the
    ``dimension`` count, is what a run uses, and a user's build is guarded (user_spaces.guarded_build)."""
    if not isinstance(case, (str, SpaceSpec)):
        _, s, continuous, vanish = case
        return make_space(np.linspace(0.0, 1.0, n + 1), s, continuous, vanish).dim
    spec = case if isinstance(case, SpaceSpec) else space_spec(case)
    try:
        hash(spec)
    except TypeError:  # a user's entry with a list in a field: built every time
        return _built_dim(spec, k, n)
    return _cached_dim(spec, k, n)


@functools.lru_cache(maxsize=4096, typed=True)
def _cached_dim(spec: SpaceSpec, k: int, n: int) -> int:
    """:func:`_built_dim` once per (entry, k, N): a config check asks for the same small meshes
    of every list (the mutation test: thousands of configs). A build depends on its arguments
    only (a user's is guarded on its first build, :func:`~.user_spaces.guarded_build`; a user
    space loaded again is a new entry, a new key); a failing build raises, and is not cached."""
    return _built_dim(spec, k, n)


def _built_dim(spec: SpaceSpec, k: int, n: int) -> int:
    """dim M_h of ``spec`` built for degree k on N uniform intervals (face-only: the n × n grid)."""
    if not spec.defined_on(1):
        return int(spec.face_space(k, n).dim)
    return int(spec.build(k, np.linspace(0.0, 1.0, n + 1)).dim)


def is_empty(case, k: int, n: int) -> bool:
    """dim M_h = 0 for ``case`` and degree k on N intervals. Above :data:`MAX_MIN_INTERVALS`
    nothing is built (N may be huge here, before the memory check): the suite's spaces grow
    with N, so a space is empty there only if it is empty on every N up to the limit."""
    if n <= MAX_MIN_INTERVALS:
        return space_dim(case, k, n) < 1
    return min_intervals(case, k) is None


def min_intervals(case, k: int) -> int | None:
    """Smallest number of intervals N on which ``case`` is not empty for degree k (None if it is
    empty up to :data:`MAX_MIN_INTERVALS`)."""
    return next((n for n in range(1, MAX_MIN_INTERVALS + 1) if space_dim(case, k, n) > 0), None)


MULTIPLIER_CHOICES = MULTIPLIER_MESHES
"""The choices of G_h (:data:`~.gamma.interface.MULTIPLIER_MESHES`)."""


def multiplier_intervals(n1: int, n2: int, choice: str = "omega2") -> int:
    """Intervals per direction of G_h when the traces on Γ have N1 and N2 equal cells per
    direction, on every Γ (:func:`~.gamma.interface.intervals_per_direction`; the checks count
    a space's dimension on that many intervals per direction). The perturbed family's union has
    at least as many intervals; every space here grows with N."""
    return intervals_per_direction(n1, n2, choice)


def check_nonempty(case, k: int, n: int, key: str = "N", where: str = "") -> None:
    """:class:`InputError` (one line naming the case, N and k) if ``case`` has dim M_h = 0 for
    degree k on a multiplier mesh of N intervals, or the mesh has no interval."""
    name = case_name(case)
    if n < 1:
        raise InputError(key, f"a multiplier mesh with at least one interval (case {name}, k = {k}{where})", got=n)
    if is_empty(case, k, n):
        low = min_intervals(case, k)
        need = f"a multiplier mesh of at least {low} intervals" if low else "a larger multiplier mesh"
        raise InputError(key, f"{need} for case {name} with k = {k} (dim M_h = 0 on N = {n} "
                         f"interval{'s' if n != 1 else ''}{where}: nothing to compute)", got=n)


def check_pair_spaces(cases, k: int, n1: int, n2: int, multiplier_meshes=("omega2",), key=None) -> None:
    """:func:`check_nonempty` for every case on the multiplier mesh of the pair (N1, N2) for
    each choice of G_h; the error names ``key``, by default the N that sets the multiplier mesh."""
    for choice in multiplier_meshes:
        n = multiplier_intervals(n1, n2, choice)
        name = key or {"omega2": "N2", "omega1": "N1"}.get(choice, "N1, N2")
        where = "" if n1 == n2 else f" of the {choice} multiplier mesh, N1 = {n1}, N2 = {n2}"
        for case in cases:
            check_nonempty(case, k, n, name, where)


def structural_kernel_dim(case: str, k: int, n_intervals: int) -> int:
    """max(dim M − dim W, 0) on matching meshes: 2 for R5.2, 1 for R5.4, 0 otherwise."""
    return space_spec(case).structural_kernel(k, n_intervals)


def _paper_case(id, ref, definition, s_of_k, continuous, vanish, min_k, dimension, finding_meshes=()):
    def build(k, x):
        return make_space(x, s_of_k(k), continuous, vanish)
    return register(SpaceSpec(id, ref, definition, build, s_of_k, min_k,
                              expected="unstable" if ref.startswith("Rem") else "stable",
                              dimension=dimension, finding_meshes=finding_meshes, lagrange=(continuous, vanish)))


# --- the paper's five cases (Section 5), in the paper's order ---------------------------
_paper_case("T3", "Thm 3", "M^1_{0,k}", lambda k: k, True, True, 1, lambda k, n: n * k - 1, finding_meshes=("union",))
_paper_case("R5.2", "Rem 5.2", "M^1_k", lambda k: k, True, False, 1, lambda k, n: n * k + 1, finding_meshes=("omega2",))
_paper_case("T4", "Thm 4", "M^0_{k-2}", lambda k: k - 2, False, False, 2, lambda k, n: n * (k - 1))
_paper_case("R5.4", "Rem 5.4", "M^0_{k-1}", lambda k: k - 1, False, False, 1, lambda k, n: n * k,
            finding_meshes=("omega2",))
_paper_case("T5", "Thm 5", "M^1_{k-1}", lambda k: k - 1, True, False, 2, lambda k, n: n * (k - 1) + 1)

PAPER_CASES = tuple(SPACES)
"""The paper's five case ids, in its order."""

# --- dual (biorthogonal) mortar multipliers (module dual) ---------------------------------
register(SpaceSpec(
    "DUAL", "Wohlmuth 2000", "dual basis of M^1_{0,k} (on tetrahedral faces at k = 2, where the TRI6 "
    "vertex weights ∫N = 0 leave no plain dual basis: the Popp-transformed one, α = 1/5, i.e. TDUAL-T6)",
    lambda k, x: dual_space(x, k, True), lambda k: k, expected="stable", dimension=lambda k, n: n * k - 1,
    nodal_basis=False, claim_tag="DUAL", finding_meshes=("omega2", "union"), lagrange=(True, True), dual=True))
register(SpaceSpec(
    "DUAL-ALL", "dual of Rem 5.2", "dual basis of M^1_k", lambda k, x: dual_space(x, k, False), lambda k: k,
    expected="unstable", dimension=lambda k, n: n * k + 1, nodal_basis=False, claim_tag="DUAL-ALL",
    lagrange=(True, False), dual=True))

# --- spaces of the face only (the 3D models' quadratic elements) -------------------------
for _spec in FACE_SPACES:
    register(_spec)


# --- roles the study gives to particular spaces (the one place they are spelled) --------
REFERENCE_SPACE = "T3"
"""Multipliers of every reference solution and of the default contact benchmark: stable for
every k (Thm 3)."""
SIGN_CHECK_SPACE = "T5"
"""Multipliers of the (3.13) sign check: continuous, stable, nonzero at Γ's ends."""
