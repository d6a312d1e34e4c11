"""Speed of β_h for any model: the Γ-reduced route as a ratio to its limit, in one run.

The problem is β_h of every case a model's benchmark runs (:class:`BetaBench` ``cases``) × its
norms on the structured N × N pair (N × N × N for the 3D bodies, with the model's mesh options);
every route answers all of them. What each time includes (also in the ``includes`` column):

``ours``
    End to end, as ``infsup-contact beta`` runs it (:func:`~infsup_contact.solvers.infsup.beta_rows`):
    meshes, NGSolve assembly, one Γ-last factorization + Schur complement per body, per case the
    couplings and the interface operator, per norm the Gram matrix and the dense eigenproblem
    (and β with v1 = 0).
``ours_core``
    Given the assembled stiffness matrices (Γ dofs last) and the multiplier spaces: the Γ-last
    factorization + Schur complement per body, couplings, interface operator, Gram matrix and
    one dense ``eigh`` per (case, norm) — exactly what β_h = λ_min(B A⁻¹ Bᵀ, G)^{1/2} needs. A
    model whose ``ours`` solves in blocks times its own engine here instead (``core_route``: the
    face's :func:`beta_ours_engine`), so that ``ours_core`` is ours without mesh and assembly.
``limit``
    The floor of any route, given the assembled stiffness and the (precomputed) interface
    operators and Gram matrices: one sparse factorization of each body's stiffness by the
    model's fastest factorization (``limit_factor``) + one dense generalized ``eigh`` of
    multiplier size per (case, norm). ``ours_core / limit`` is the overhead of the Γ-reduced route.

A model adds its own routes or rows beside these (the membranes' full-pencil routes,
:mod:`.beta_pencil`; the face's Schur-complement routes, :mod:`.face_schur`).

``max_abs_diff``: the largest |β_route − β_ours| over all (case, norm), β being the first value
above the reference kernel (``kernel``: the structural one, the one ``ours`` decided, or none);
``kernel_ok`` says whether a route's kernel values are all below :data:`KERNEL_BETA`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from ..discretization.gamma.coupling import coupling_matrix
from ..discretization.spaces import registry
from ..errors import InputError
from ..models.contract import Model, factorized_side, mirrored_side
from ..solvers.infsup import beta_rows
from ..solvers.interface_operator import interface_operator
from ..solvers.request import MeshOptions
from ..solvers.side_cache import SideCache
from .harness import ROUTE_BUDGET, _log, _row, run_interleaved
from .phases import phase_rows

FAMILY = "structured"
KERNEL_BETA = 1e-6
"""An inf-sup value below this counts as a (structural) kernel value in ``kernel_ok``."""


@dataclass(frozen=True)
class BetaBench:
    """What one model's β_h benchmark is; the routes and the rows are the same for every model.

    Attributes
    ----------
    what : str
        The ``what`` column of the β rows.
    model : Model
        The bodies' model (:class:`~infsup_contact.models.contract.Model`).
    norms : tuple of str
        The multiplier norms solved per case.
    columns : tuple of str
        The output columns, in order.
    second_ratio : str
        ``ratio_to_ours_core`` or ``ratio_to_limit``: the second ratio column (route / that route).
    cases : callable
        ``cases(k, gamma, g_h, ids) -> list``: the spaces run (``ids``: the caller's choice or None).
    kernel : callable
        ``kernel(case, k, n, row) -> int``: the kernel the compared β lies above, from ``ours``' row.
    limit_factor : callable
        ``limit_factor(K)``: the limit's sparse factorization of one body's stiffness.
    includes : dict
        Route → what its time includes.
    compare_limit : bool
        Whether the limit's β is compared with ours (else its ``max_abs_diff`` is empty).
    extra_routes : callable or None
        ``extra_routes(setup) -> {name: callable}``: more routes timed with the three, each
        returning {(case, norm): ascending β² values}.
    extra_rows : callable or None
        ``extra_rows(setup, repeats, budget) -> list``: rows of another measurement on the setup.
    limit_route : callable or None
        ``limit_route(setup, operators) -> (run, gflop)``: the model's own limit (:mod:`.face_limit`)
        in place of ``limit_factor`` + one ``eigh`` per pencil, and its flop count (GFLOP, after a
        run); the rows then carry ``limit_gflop`` and ``gflop_per_s``.
    core_route : callable or None
        ``core_route(setup) -> {(case, norm): β² values}``: the model's ``ours_core`` in place of
        :func:`beta_ours_core` (the face's: :func:`beta_ours_engine`, ours' own route).
    """

    what: str
    model: Model
    norms: tuple
    columns: tuple
    second_ratio: str
    cases: Callable
    kernel: Callable
    limit_factor: Callable
    includes: dict
    compare_limit: bool = True
    extra_routes: Callable | None = None
    extra_rows: Callable | None = None
    limit_route: Callable | None = None
    core_route: Callable | None = None


def splu_best_order(K):
    """SuperLU in its best order for a stiffness (``MMD_AT_PLUS_A``, symmetric mode)."""
    return spla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))


def check_mesh_options(model, mesh_options: dict) -> None:
    """:class:`InputError` naming the first mesh option the model does not take or allow."""
    allowed = dict(model.mesh_options)
    for key, value in mesh_options.items():
        if key not in allowed:
            takes = f"takes {', '.join(allowed)}" if allowed else "takes no mesh option"
            raise InputError(key, f"nothing: model {model.name} {takes}", got=value)
        if value not in allowed[key]:
            raise InputError(key, ", ".join(allowed[key]), got=value)


class BetaSetup:
    """Assembled data of one (N, k), built outside every timing: the two sides (stiffness,
    Γ dofs last), Γ, the cases and their multiplier spaces on G_h = the trace of Ω2."""

    def __init__(self, bench: BetaBench, n: int, k: int, cases=None, **mesh_options):
        check_mesh_options(bench.model, mesh_options)
        self.bench, self.n, self.k, self.mesh_options = bench, n, k, mesh_options
        self.sides = SideCache().pair(bench.model, FAMILY, k, n, n, MeshOptions(**mesh_options))
        self.gamma = self.sides[0].trace.gamma
        self.g_h = g_h = self.gamma.multiplier_partition(*(s.trace.partition for s in self.sides), "omega2")
        self.cases = bench.cases(k, self.gamma, g_h, cases)
        self.spaces = {c: registry.case_space(c, k, g_h, self.gamma) for c in self.cases}
        self.limit_gflop = None  # the limit's flops, where its route counts them
        self.ndof = sum(s.ndof for s in self.sides)

    def keys(self) -> list:
        return [(c, nm) for c in self.cases for nm in self.bench.norms]

    def operators(self) -> dict:
        """{(case, norm): (S = B A⁻¹ Bᵀ, G)}: the limit route's given inputs."""
        ops = {}
        for c in self.cases:
            S = interface_operator([coupling_matrix(s.trace, self.spaces[c], self.k) for s in self.sides],
                                   self.sides)
            for nm in self.bench.norms:
                ops[c, nm] = (S, self.gamma.gram(self.spaces[c], nm)[0])
        return ops


def _eigvals(S, G) -> np.ndarray:
    return sla.eigh(S, G, eigvals_only=True, check_finite=False)


def beta_ours(setup: BetaSetup) -> dict:
    """{(case, norm): row of ``beta_rows``} for the setup's pair, end to end."""
    rows = beta_rows(FAMILY, setup.k, setup.n, setup.n, setup.cases, norms=setup.bench.norms,
                     model=setup.bench.model, mesh=MeshOptions(**setup.mesh_options))
    return {(r["case"], r["norm"]): r for r in rows}


def _factorized_sides(setup: BetaSetup) -> list:
    """The setup's two bodies factorized from their assembled stiffness, as ours factorizes them
    (the parity parts, side 2 side 1's mirror where checked), after returning the sides to their
    state right after the build (a fresh run has no cached basis)."""
    for s in setup.sides:
        s.forget_cached()
    s1, s2 = setup.sides
    side1 = factorized_side(s1.trace, s1.free, s1.stiffness, signature=getattr(s1, "signature", None))
    return [side1, mirrored_side(side1, s2.trace, s2.free, s2.stiffness, getattr(s2, "signature", None))]


class _GivenSides(SideCache):
    """A side cache that serves one given pair (the engine run from assembled stiffness)."""

    def __init__(self, sides: list):
        super().__init__()
        self._given = sides

    def pair(self, *args, **kwargs) -> list:
        return self._given[0].trace.gamma.paired(list(self._given))


def row_values(row: dict) -> np.ndarray:
    """A β row's bottom as ascending β² values: its kernel values (``beta``, ``kernel_dim`` times)
    then the first above (``smallest_nonzero``), or ``beta`` alone without a kernel: what
    :func:`compare` reads of a route, told by the row ours' engine wrote."""
    if row["kernel_dim"] == 0:
        return np.array([row["beta"] ** 2])
    return np.array([row["beta"] ** 2] * row["kernel_dim"] + [row["smallest_nonzero"] ** 2])


def beta_ours_engine(setup: BetaSetup) -> dict:
    """{(case, norm): β² values (:func:`row_values`)}: ours' own route (the engine,
    :func:`~infsup_contact.solvers.infsup.beta_rows`) from the assembled stiffness: the bodies'
    factorization, couplings, Grams, the kernel decision, the interface operator, the pencils in
    their blocks and β with v1 = 0; no mesh, no assembly."""
    rows = beta_rows(FAMILY, setup.k, setup.n, setup.n, setup.cases, norms=setup.bench.norms,
                     model=setup.bench.model, mesh=MeshOptions(**setup.mesh_options),
                     side_cache=_GivenSides(_factorized_sides(setup)))
    return {(r["case"], r["norm"]): row_values(r) for r in rows}


def beta_ours_core(setup: BetaSetup) -> dict:
    """{(case, norm): eigenvalues β²}: factorization, couplings, interface, Gram, eigh
    (:func:`_factorized_sides`: as ours factorizes the bodies)."""
    sides = _factorized_sides(setup)
    out = {}
    with setup.gamma.gram_session():  # as ours: spaces sharing a piece space share its series
        for c in setup.cases:
            S = interface_operator([coupling_matrix(s.trace, setup.spaces[c], setup.k) for s in sides], sides)
            for nm in setup.bench.norms:
                out[c, nm] = _eigvals(S, setup.gamma.gram(setup.spaces[c], nm)[0])
    return out


def beta_limit(setup: BetaSetup, operators: dict | None = None):
    """The floor as a callable: one ``limit_factor`` per body + one ``eigh`` per (case, norm)."""
    ops = operators if operators is not None else setup.operators()

    def run():
        for s in setup.sides:
            setup.bench.limit_factor(s.stiffness)
        return {key: _eigvals(S, G) for key, (S, G) in ops.items()}

    return run


def reference(setup: BetaSetup, rows: dict) -> dict:
    """{(case, norm): (kernel values, first β above the kernel)} of ``ours``: the kernel is the
    model's ``kernel``; a row whose own kernel differs from it has no comparable β (NaN)."""
    out = {}
    for key, r in rows.items():
        kern = setup.bench.kernel(key[0], setup.k, setup.n, r)
        beta = r["beta"] if kern == 0 else (r["smallest_nonzero"] if r["kernel_dim"] == kern else np.nan)
        out[key] = (np.full(kern, r["beta"]), float(beta))
    return out


def bottom(beta2: np.ndarray, kern: int) -> tuple:
    """(β values of the kernel, first β above it) from β² values."""
    b = np.sqrt(np.clip(np.sort(beta2), 0.0, None))
    return b[:kern], float(b[kern]) if kern < len(b) else np.nan


def compare(got: dict, ref: dict) -> tuple:
    """(max |β − β_ref| over (case, norm), all kernel values < KERNEL_BETA) of a route's β² values
    against :func:`reference` (a space that is all kernel has no β in either: NaN = NaN). Two β
    both below KERNEL_BETA are both zero: each is the square root of an eigenvalue at round-off
    (~1e-16 → ~1e-8, differing between BLAS code paths), so their difference measures no route."""
    diff, kernel_ok = 0.0, True
    for key, (ref_kernel, ref_beta) in ref.items():
        kern_b, beta = bottom(got[key], len(ref_kernel))
        kernel_ok &= bool(np.all(kern_b < KERNEL_BETA) and len(kern_b) == len(ref_kernel))
        if not (np.isnan(beta) and np.isnan(ref_beta)):
            d = 0.0 if max(beta, ref_beta) < KERNEL_BETA else abs(beta - ref_beta)
            diff = np.nan if np.isnan(d) or np.isnan(diff) else max(diff, d)
    return float(diff), kernel_ok


def _routes(setup: BetaSetup) -> dict:
    ops = setup.operators()
    if setup.bench.limit_route is not None:
        limit, setup.limit_gflop = setup.bench.limit_route(setup, ops)
    else:
        limit = beta_limit(setup, ops)
    core = setup.bench.core_route or beta_ours_core
    routes = {"ours": lambda: beta_ours(setup), "ours_core": lambda: core(setup), "limit": limit}
    return routes | (setup.bench.extra_routes(setup) if setup.bench.extra_routes else {})


def _setup_rows(setup: BetaSetup, repeats: int, budget: float) -> list:
    """The β rows of one setup: the routes timed interleaved, each compared with ours."""
    bench = setup.bench
    res = run_interleaved(_routes(setup), repeats, budget)
    ref = reference(setup, res["ours"][0])
    med_ours = float(np.median(res["ours"][1]))
    med_second = float(np.median(res[bench.second_ratio.removeprefix("ratio_to_")][1]))
    dim_m = max(s.dim for s in setup.spaces.values())
    rows = []
    for name, (got, times) in res.items():
        if name == "ours":  # the reference itself; its kernel values are its β of a kernel case
            diff, kok = 0.0, bool(all(np.all(k < KERNEL_BETA) for k, _ in ref.values()))
        elif name == "limit" and not bench.compare_limit:
            diff, kok = np.nan, np.nan
        else:
            diff, kok = compare(got, ref)
        rows.append(_row(bench.what, name, setup.k, setup.n, times, med_ours, med_second, other=bench.second_ratio,
                         max_abs_diff=diff, kernel_ok=kok, n_problems=len(setup.keys()), ndof=setup.ndof,
                         dim_M_max=dim_m, includes=bench.includes[name], **_flops(setup, times),
                         **setup.mesh_options))  # options: columns
        _log(f"  {name:10s} {np.median(times):9.4f} s  diff {diff:.2e}")
    return rows


def _flops(setup: BetaSetup, times) -> dict:
    """``limit_gflop`` and the rate of a route doing that work in its median time (none where the
    limit does not count its flops)."""
    if setup.limit_gflop is None:
        return {}
    gflop = setup.limit_gflop()
    return {"limit_gflop": gflop, "gflop_per_s": gflop / float(np.median(times))}


class Rows(list):
    """The rows of :func:`bench_beta`; ``phases``: the breakdown rows where asked (:mod:`.phases`)."""

    phases: tuple = ()


def bench_beta(bench: BetaBench, ns, ks, repeats: int = 3, budget: float = ROUTE_BUDGET, cases=None,
               phases: list | None = None, **mesh_options) -> list:
    """β_h routes of one model on the structured pairs, every case of the benchmark × its norms.

    Parameters
    ----------
    bench : the model's benchmark (:mod:`.beta_models`).
    ns, ks : mesh sizes N and degrees k.
    repeats : repetitions per route (interleaved; median, min, max reported).
    budget : a route is not repeated once its accumulated time exceeds this (seconds).
    cases : the space ids to run where the benchmark's ``cases`` takes them (None: its default).
    phases : a list that receives the breakdown rows of one ``ours`` run per setup (:mod:`.phases`),
        also returned as the result's ``phases``; None: not measured.
    mesh_options : the model's mesh options (``element`` for the 3D bodies).

    Returns
    -------
    list of dict with the columns ``bench.columns`` (one row per route, k, N, then the model's
    extra rows of that setup).
    """
    rows = []
    for k in ks:
        for n in ns:
            _log(f"{bench.what} {' '.join(f'{o}={v}' for o, v in mesh_options.items())} k={k} N={n}: setup")
            setup = BetaSetup(bench, n, k, cases, **mesh_options)
            rows += _setup_rows(setup, repeats, budget)
            if bench.extra_rows:
                rows += bench.extra_rows(setup, repeats, budget)
            if phases is not None:
                phases += phase_rows(setup, lambda: beta_ours(setup))
    out = Rows({c: r.get(c, np.nan) for c in bench.columns} for r in rows)  # a column a row lacks: empty
    out.phases = phases or []
    return out
