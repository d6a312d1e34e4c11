"""Speed of the 3D β_h (issue 28, item 7): the Γ-reduced route on the contact face of
:data:`~infsup_contact.models.membranes3d.MEMBRANES3D` as a ratio to its limit — one sparse
factorization per body + one dense generalized ``eigh`` of multiplier size per (case, norm).
The problem is the one of :mod:`.beta_routes` one dimension up: every registered space valid
for k (as ``infsup-contact beta --model membranes3d --case all`` runs them) × both norms
(H = the exact H^{-1/2}_00(Γ) double sine series, L2) on the structured N × N × N pair of
hexahedra or tetrahedra (``element``).

Routes (``includes`` column), measured interleaved by :func:`~.harness.run_interleaved`:

``ours``
    End to end, :func:`~infsup_contact.solvers.infsup.beta_rows_all` for the (N, N) pair:
    meshes, NGSolve assembly, one Γ-last factorization + Schur complement per body, per case
    the couplings, the kernel decision from Bᵀ, the interface operator, per norm the Gram
    matrix, its Cholesky factor and the dense eigenproblem (and β with v1 = 0).
``ours_core``
    Given the assembled stiffness matrices (Γ dofs last) and the multiplier spaces: the Γ-last
    factorization + Schur complement per body, couplings, interface operator, Gram matrix and
    one dense ``eigh`` per (case, norm) — exactly what β_h needs.
``limit``
    Given the assembled stiffness and the (precomputed) interface operators and Gram matrices:
    one sparse Cholesky factorization of each body's stiffness by the fastest factorization
    measured here (MKL PARDISO, METIS order; SuperLU's ``MMD_AT_PLUS_A`` where MKL does not
    load) + one dense generalized ``eigh`` per (case, norm). ``ours_core / limit`` is the
    overhead of the Γ-reduced route (Bathe & Brezzi 2001: β_h² = λ_min(B A⁻¹ Bᵀ, G)).

The Schur complement alone (``what`` = ``face_schur``): each body's S = K_ΓΓ − K_ΓI K_II⁻¹ K_IΓ
by :func:`~infsup_contact.la.schur.gamma_factorization`'s routes, ``ratio_to_ours``
against PARDISO's partial factorization: the measurement behind the route ``"auto"`` takes on
a face (CHOLMOD and MUMPS have no wheel for this Python and numpy on PyPI; scikit-sparse and
python-mumps 0.0.2 were tried, see the README).

``max_abs_diff``: the largest |β_route − β_ours| over all (case, norm), β being the first
value above the kernel ``ours`` decided (β_h itself for the stable spaces); ``limit`` solves the
same (S, G) as ``ours`` builds them, so its difference checks the eigensolve only.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from ..discretization.spaces import registry
from ..discretization.gamma.coupling import coupling_matrix
from ..errors import InputError
from ..models.membranes3d import ELEMENTS, MEMBRANES3D
from ..la import pardiso
from ..models.contract import factorized_side
from ..la.schur import gamma_factorization
from ..solvers.interface_operator import interface_operator
from ..solvers.side_cache import SideCache
from ..solvers.infsup import beta_rows_all
from .harness import ROUTE_BUDGET, _log, _row, run_interleaved

NORMS = ("H", "L2")
FAMILY = "structured"
FACE_COLUMNS = ("what", "route", "element", "k", "N", "seconds_median", "seconds_min", "seconds_max",
                "ratio_to_ours", "ratio_to_limit", "max_abs_diff", "repeats", "n_problems", "ndof",
                "dim_M_max", "includes")
INCLUDES = {
    "ours": "meshes+assembly+Γ-last LU+Schur per body+couplings+kernel from Bᵀ+interface+Gram+eigh "
            "(+β with v1=0), every case × norm",
    "ours_core": "Γ-last LU+Schur per body+couplings+interface+Gram+eigh per (case,norm) (assembled stiffness given)",
    "limit": "one sparse Cholesky per body (PARDISO, else splu MMD_AT_PLUS_A) + one eigh per (case,norm) "
             "(interface operators, Grams given)",
    "pardiso": "Schur complement per body: PARDISO partial factorization (METIS)",
    "nested": "Schur complement per body: SuperLU, Γ-last nested dissection, S from the factors",
    "solves": "Schur complement per body: SuperLU MMD_AT_PLUS_A + one solve per Γ dof",
}
SCHUR_ROUTES = ("pardiso", "nested", "solves")
SOLVES_MAX_GAMMA = 600
"""The solves route (n_Γ solves) is timed only up to this many Γ dofs: beyond it, minutes."""


class FaceSetup:
    """Assembled data of one (element, N, k), built outside every timing: the two sides
    (their stiffness matrices, Γ dofs last), Γ, the multiplier space of each case."""

    def __init__(self, n: int, k: int, element: str = "hex"):
        if element not in ELEMENTS:
            raise InputError("element", ", ".join(ELEMENTS), got=element)
        self.n, self.k, self.element = n, k, element
        self.sides = SideCache().pair(MEMBRANES3D, FAMILY, k, n, n, element=element)
        self.gamma = self.sides[0].trace.gamma
        g_h = self.gamma.multiplier_partition(*(s.trace.partition for s in self.sides), "omega2")
        self.cases = registry.ids_built_on(k, self.gamma, g_h)  # what beta --case all runs
        self.spaces = {c: registry.case_space(c, k, g_h, self.gamma) for c in self.cases}
        self.ndof = sum(s.ndof for s in self.sides)

    def keys(self):
        return [(c, nm) for c in self.cases for nm in NORMS]

    def operators(self) -> dict:
        """{(case, norm): (S = B A⁻¹ Bᵀ, G)}: the limit route's given inputs."""
        ops = {}
        for c in self.cases:
            S = interface_operator([coupling_matrix(s.trace, self.spaces[c], self.k) for s in self.sides],
                                   self.sides)
            for nm in NORMS:
                ops[c, nm] = (S, self.gamma.gram(self.spaces[c], nm)[0])
        return ops


def _eig_bottom(S, G) -> np.ndarray:
    return sla.eigh(S, G, eigvals_only=True, check_finite=False)


def face_ours(setup: FaceSetup) -> dict:
    """{(case, norm): (kernel_dim, first β above the kernel)} from ``beta_rows_all``."""
    rows = beta_rows_all(FAMILY, setup.k, setup.n, setup.n, setup.cases, norms=NORMS, model=MEMBRANES3D,
                         element=setup.element)
    return {(r["case"], r["norm"]): (r["kernel_dim"], r["smallest_nonzero"] if r["kernel_dim"] else r["beta"])
            for r in rows}


def face_ours_core(setup: FaceSetup) -> dict:
    """{(case, norm): eigenvalues β²}: factorization, couplings, interface, Gram, eigh. The
    setup's sides are first returned to their state right after the build (their traces'
    basis values, cached by :meth:`FaceSetup.operators`, are not reused: a fresh run has none)."""
    for s in setup.sides:
        s.forget_cached()
    sides = [factorized_side(s.trace, s.free, s.stiffness) for s in setup.sides]
    out = {}
    with setup.gamma.gram_session():  # as ours: spaces sharing a piece space share its series
        for c in setup.cases:
            S = interface_operator([coupling_matrix(s.trace, setup.spaces[c], setup.k) for s in sides], sides)
            for nm in NORMS:
                out[c, nm] = _eig_bottom(S, setup.gamma.gram(setup.spaces[c], nm)[0])
    return out


def face_limit(setup: FaceSetup, ops: dict):
    """The floor as a callable: one sparse Cholesky per body + one ``eigh`` per (case, norm)."""
    def run():
        for s in setup.sides:
            if pardiso.available():
                pardiso.Factor(s.stiffness).handle.release()
            else:
                spla.splu(s.stiffness, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                          options=dict(SymmetricMode=True))
        return {key: _eig_bottom(S, G) for key, (S, G) in ops.items()}

    return run


def schur_routes(setup: FaceSetup) -> dict:
    """{route: callable} giving both bodies' Schur complements by that route of
    :func:`~infsup_contact.la.schur.gamma_factorization` (the solves route only while
    n_Γ ≤ :data:`SOLVES_MAX_GAMMA`; PARDISO only where it loads)."""
    n_gamma = max(len(s.trace.gamma_dofs) for s in setup.sides)
    names = [r for r in SCHUR_ROUTES if (r != "solves" or n_gamma <= SOLVES_MAX_GAMMA)
             and (r != "pardiso" or pardiso.available())]
    return {r: (lambda r=r: [gamma_factorization(s.stiffness, len(s.trace.gamma_dofs), r).schur
                             for s in setup.sides]) for r in names}


def _schur_diff(got: list, ref: list) -> float:
    """max relative |S_route − S_ref| over both bodies."""
    return float(max(np.abs(a - b).max() / np.abs(b).max() for a, b in zip(got, ref)))


def _diff(got: dict, ref: dict) -> float:
    """max |β_route − β_ours| over (case, norm), β the first value above ``ours``' kernel
    (a space that is all kernel has no such value in either route: NaN in both counts as equal)."""
    out = 0.0
    for key, (kern, beta) in ref.items():
        ev = got[key]
        b = float(np.sqrt(max(ev[kern], 0.0))) if kern < len(ev) else np.nan
        if np.isnan(b) and np.isnan(beta):
            continue
        d = abs(b - beta)
        out = np.nan if np.isnan(d) else max(out, d)
        if np.isnan(out):
            break
    return float(out)


def _schur_rows(setup: FaceSetup, repeats: int, budget: float) -> list:
    """The ``face_schur`` rows of one setup: each Schur route timed interleaved, ratios to the
    first route (PARDISO where it loads), ``max_abs_diff`` the relative difference of S."""
    res = run_interleaved(schur_routes(setup), repeats, budget)
    first = next(iter(res))
    ref, t_ref = res[first]
    rows = []
    for name, (got, times) in res.items():
        rows.append(_row("face_schur", name, setup.k, setup.n, times, float(np.median(t_ref)), np.nan,
                         other="ratio_to_limit", element=setup.element,
                         max_abs_diff=_schur_diff(got, ref), n_problems=len(setup.sides),
                         ndof=setup.ndof, dim_M_max=max(len(s.trace.gamma_dofs) for s in setup.sides),
                         includes=INCLUDES[name]))
        _log(f"  schur {name:8s} {np.median(times):9.4f} s  rel diff {rows[-1]['max_abs_diff']:.2e}")
    return rows


def bench_face(ns, ks, element: str = "hex", repeats: int = 3, budget: float = ROUTE_BUDGET) -> list:
    """β_h routes of the 3D membranes on the structured N × N × N pairs, every valid case × norm.

    Parameters
    ----------
    ns, ks : cells per direction N and degrees k.
    element : ``hex`` or ``tet`` (:data:`~infsup_contact.models.membranes3d.ELEMENTS`).
    repeats : repetitions per route (interleaved; median, min, max reported).
    budget : a route is not repeated once its accumulated time exceeds this (seconds).

    Returns
    -------
    list of dict with the columns :data:`FACE_COLUMNS` (one row per route, k, N).
    """
    rows = []
    for k in ks:
        for n in ns:
            _log(f"face {element} k={k} N={n}: setup")
            setup = FaceSetup(n, k, element)
            ops = setup.operators()
            routes = {"ours": lambda: face_ours(setup), "ours_core": lambda: face_ours_core(setup),
                      "limit": face_limit(setup, ops)}
            res = run_interleaved(routes, repeats, budget)
            ref, t_ours = res["ours"]
            med_ours, med_limit = float(np.median(t_ours)), float(np.median(res["limit"][1]))
            dim_m = max(s.dim for s in setup.spaces.values())
            for name, (got, times) in res.items():
                diff = 0.0 if name == "ours" else _diff(got, ref)
                rows.append(_row("face_beta", name, k, n, times, med_ours, med_limit, other="ratio_to_limit",
                                 element=element, max_abs_diff=diff, n_problems=len(setup.keys()),
                                 ndof=setup.ndof, dim_M_max=dim_m, includes=INCLUDES[name]))
                _log(f"  {name:10s} {np.median(times):9.4f} s  diff {diff:.2e}")
            rows += _schur_rows(setup, repeats, budget)
    return [{c: r[c] for c in FACE_COLUMNS} for r in rows]
