"""Memory and time of a request, estimated from its sizes before anything is allocated.

Pure arithmetic (no numpy, no NGSolve): the command line checks a request against the
available memory before it imports the solvers, and the workflow gives every β_h and contact
job its ``mem_mb`` from the same numbers (``workflow/rules/common.smk``).

The model
---------
A 2D membrane (N segments on Γ, degree k) has nd = (N k)(N k − 1) free dofs (× 1.3 unstructured)
and costs C · nd · log2(nd) bytes while kept (nested-dissection fill), plus the dense interface
operators, couplings, the H^{-1/2}_00 Gram and the eigenproblem, explicitly; a 3D face:
:func:`face_beta_estimate`; a foreign system: :func:`system_estimate`. Constants measured with
``/usr/bin/time -v`` (max RSS) and ``tracemalloc`` (docs/refusals.md, "The memory estimate").
The time is the CPU time of one thread (a sparse LU is O(nd^1.5) in 2D); both are checked
within a factor 2 on the docs' examples (docs/performance.md, ``snakemake bench_estimates``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .memory import available_bytes, total_bytes  # noqa: F401  (the readings, here for the estimates' callers)

MIB = 1024 ** 2

PROCESS_BYTES = {"beta": 200 * MIB, "contact": 230 * MIB, "bench": 220 * MIB}
"""Resident memory of the process before the request (Python, NumPy, SciPy, NGSolve, pandas):
measured 190 MB (``beta``), 220 MB (``contact``), 210 MB (``bench``) on the smallest sizes."""

SIDE_BYTES_PER_DOF_LOG = {"beta": 175.0, "contact": 330.0, "reference": 250.0}
"""C in C · nd · log2(nd) bytes per side: β_h (mesh, stiffness, Γ-last LU), a contact solve
(the same plus loads, solutions and the error integrals), the membranes reference solve."""

CONTACT_EXTRA_BYTES = 150 * MIB
"""Error integration of a contact row (exact solution or reference on the coarse mesh)."""

FAMILY_DOF_FACTOR = {"structured": 1.0, "perturbed": 1.0, "unstructured": 1.3}

BENCH_FACTOR = {"beta": 2.7, "contact": 1.6, "face": 2.7, "elastic": 2.7, "arc": 2.7}
"""Bench holds each route's own factorization (eigsh: the full pencil; peers: the full KKT)
next to ours: measured 2.3× (β, N = 128, k = 2) and 1.4× (contact, N = 64, k = 2)."""

SECONDS_PER_DOF15 = {"beta": 5e-8, "contact": 1.6e-7, "eigsh": 1.8e-6, "kkt": 3e-6}
"""Seconds per nd^1.5 (a 2D sparse LU): measured β N = 256, 512 (k = 1, 2); contact N = 512,
k = 1 and the membranes reference; bench's eigsh (per case × norm) and sparse-KKT routes."""
START_SECONDS = 2.5
"""Start-up: imports of NGSolve, SciPy and pandas."""


@dataclass(frozen=True)
class Estimate:
    """Peak resident memory (bytes, interpreter included) and time (seconds: the CPU time of one core,
    module text) of a request."""

    bytes: float
    seconds: float

    @property
    def mb(self) -> int:
        """Megabytes (10⁶ B, Snakemake's ``mem_mb``), rounded up."""
        return int(math.ceil(self.bytes / 1e6))

    def describe(self) -> str:
        return f"~{human_bytes(self.bytes)} peak memory, ~{human_seconds(self.seconds)} of CPU time"


def human_bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"):
        if n < 1024 or unit == "EiB":
            return f"{n:.3g} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024
    return f"{n:.3g} EiB"  # pragma: no cover


def human_seconds(s: float) -> str:
    for unit, size in (("years", 365.25 * 86400), ("days", 86400), ("h", 3600), ("min", 60)):
        if s >= size:
            return f"{s / size:.2g} {unit}"
    return f"{max(s, 1):.2g} s"


def side_dofs(family: str, n: int, k: int) -> float:
    """Free dofs of one membrane: (N k)(N k − 1) on the structured meshes (× family factor)."""
    nk = float(n) * float(k)
    return max(nk * (nk - 1.0), 1.0) * FAMILY_DOF_FACTOR.get(family, 1.3)


def _side_bytes(nd: float, what: str) -> float:
    return SIDE_BYTES_PER_DOF_LOG[what] * nd * math.log2(max(nd, 2.0))


def _dense_bytes(k: int, ns, n_mult: float, s: int, norms, h_route: str, gamma_dim: int) -> float:
    """Dense Γ work of one multiplier space: interface operators, couplings, Gram, eigh (Γ of dim ``gamma_dim``)."""
    m = n_mult * (s + 1)                        # dim M: at most (s + 1) per interval
    n_quad = sum(ns) * (k + s + 2) / 2          # quadrature points on the common refinement
    total = 0.0
    for n in ns:
        g = float((n * k + 1) ** gamma_dim)  # Γ dofs of side i: Interface.trace_nodes of a Lagrange Γ
        total += 8 * (4 * g * g + g * (m + n_quad) + n_quad * m)
    total += 8 * 10 * m * m                     # B X Bᵀ, its copies, eigh of two pencils
    if "H" in norms:
        if h_route == "series":
            total += 1600 * m * m
        else:                                   # log kernel: per pair of intervals
            total += (600 + 110 * (s + 1) ** 2) * n_mult * (n_mult + 1) / 2
    return total


def _multiplier_intervals(multiplier_mesh: str, n1: int, n2: int) -> float:
    return {"omega1": n1, "omega2": n2}.get(multiplier_mesh, n1 + n2)


SIDE_BYTES_3D = {("pardiso", 1): 260.0, ("pardiso", 2): 450.0, ("nested", 1): 1500.0, ("nested", 2): 1500.0}
"""C in C · nd^{4/3} bytes per side of a 3D body, by the route that gives its Schur complement
(:func:`face_route`) and the degree (k ≥ 2 counts as 2): the fill of a 3D sparse factorization
is O(nd^{4/3}), and so are the dense Γ arrays, n_Γ² ~ (N k)⁴ = nd^{4/3}; at equal nd, k = 1 has
8× the cells and so more quadrature points per Γ basis function. Everything of a β_h request but
the process included; the ``pardiso`` route adds :data:`MKL_BYTES`. Above every peak resident
memory measured (hexahedra, every case; docs/refusals.md, "The memory estimate", lists them)."""
MKL_BYTES = 64 * MIB
"""Resident size of MKL once PARDISO is loaded (measured: 42 MB more than the package alone)."""
SECONDS_PER_DOF2_3D = 1.3e-8
"""Seconds per nd² of the ``nested`` route (the sparse LU, fitted to N = 16 and 20 at k = 2 and
N = 40 at k = 1); PARDISO's routes: :data:`DENSE_ROUTE_SECONDS_3D`,
:data:`LARGE_ROUTE_3D`."""


def face_route() -> str:
    """The Schur route a face takes above the solves route's limit: ``pardiso`` where MKL loads
    (:func:`infsup_contact.la.schur.gamma_factorization`), else ``nested``."""
    from .la import pardiso

    return "pardiso" if pardiso.available() else "nested"


def face_side_dofs(n: int, k: int) -> float:
    """Free dofs of one 3D body on N × N × N cells: (N k − 1)² N k (u = 0 on five faces)."""
    nk = float(n) * float(k)
    return max((nk - 1.0) ** 2 * nk, 1.0)


LARGE_ROUTE_3D = {1: (1530.0, 197.0, 6.06e-5, 5.28e-10), 2: (3026.0, 81.3, 4.56e-5, 3.00e-10)}
"""(a, b, c, d) of the large route (dim M above :data:`~.la.bottom.DENSE_MAX_M`: sparse
couplings, exponential-sum Grams in the reflections' parity blocks, bottom pencils; PARDISO):
bytes a Σ nd + b m² and seconds c Σ nd + d m³ beyond the process, m = (k N₂ + 1)² (R5.2 on
G_h = the trace of Ω2). Non-negative least squares, relative residuals, on ``beta --model
membranes3d --case all --norm all`` (hexahedra; k = 1, N = 40…64; k = 2 refitted with
:func:`~.bench.estimates.fit_large_route_3d` after the interface terms and the kernel decision's
rows went into the parity components, N = 20…36 and 48; the peaks and CPU times in
docs/refusals.md, "The memory estimate"). The sparse factors grow like nd here (nd^{4/3}
only asymptotically), the Grams, the pencils' and the shared series' dense arrays like m², their
factorizations like m³. × :data:`LARGE_ROUTE_MARGIN`: above every measurement (by 15 % to 25 %; at N = 20
the dense route's floor, 81 %)."""
LARGE_ROUTE_3D_VECTOR = {2: (4856.0, 124.9, 3.72e-5, 4.22e-10)}
"""The same constants for the 3D elastic bodies (three components a node, ``components`` = 3),
where they are measured: their bodies are factorized whole, not in parity parts, and hold more per
dof. Fitted on ``beta --model elastic3d --case all --k 2 --norm all`` at N = 12, 16, 20, 24
(2026-12-06; peaks 1.08, 2.44, 5.99, 9.25 GB, CPU 8.3, 23.1, 70.4, 188 s): the membranes' fit put
N = 16 at 0.80 of its peak. Elsewhere :data:`LARGE_ROUTE_3D`."""
LARGE_ROUTE_MARGIN = 1.2


def _large_route_constants(k: int, components: int) -> tuple:
    """(a, b, c, d) of the large route for degree ``k`` and ``components`` a node."""
    if components > 1 and min(k, 2) in LARGE_ROUTE_3D_VECTOR:
        return LARGE_ROUTE_3D_VECTOR[min(k, 2)]
    return LARGE_ROUTE_3D[min(k, 2)]

DENSE_ROUTE_SECONDS_3D = {1: 2.2e-9, 2: 1.0e-9}
"""d of c Σ nd + d m³ seconds (c of :data:`LARGE_ROUTE_3D`) on PARDISO's dense route, where the
dense SVDs and pencils cost more per m³ (fitted at k = 1, N = 32, ``--case all``; k = 2 on
N = 8…18 after the pencils went into parity blocks: 1.2–1.3× the CPU time measured). At the gate the large route is the faster one (k = 1: the
large route at N = 40 takes about 1.5× the dense route at N = 32, for twice the multipliers)."""


TRI_GRAM_SECONDS = 2.2e-9
"""Seconds per n_local · T · n_max² of a triangle space's H Gram (``--element tet``, ``face.norms.
triangles.gram_h_tri``: the sine coefficients of T triangles' n_local basis functions for all
(m, n) ≤ n_max, over the partial sums n0, 2 n0, … n_max). Measured, one thread, ``beta --model
membranes3d --element tet --case all --k 2 --N1 8 --N2 8`` (T = 128; the nine Grams 8.8 s): P2
1.9e-9 (n_max 768; its duals 2.7–3.0e-9), P1 1.7–3.8e-9, P0 3.2e-9 (1024); 5e-9 before 2026-12-08
(the Grams 14.6–15.2 s). Hexahedra: Kronecker products of 1D Grams."""
TRI_GRAM_BYTES = 8 * 2 ** 23
"""Its working array (``triangles._BUDGET`` doubles: the coefficients of a block of m; the stacked
U it also held whole until 2026-12-08 is made by blocks of columns since). Measured at N = 8, k = 2:
335 MiB against 439 estimated with two arrays."""


def tet_gram_seconds(k: int, n: int, n_spaces: int) -> float:
    """The H Grams of ``n_spaces`` triangle spaces on Ω2's face (T = 2 N², each counted at degree k,
    n_local = (k + 1)(k + 2)/2), at the n_max where ``gram_h_tri`` stops at its cap (an upper bound):
    n0 = max(16, 2 (k + 1) N) doubled while ≤ N_MAX_CAP // 64."""
    from .discretization.segment.norms import N_MAX_CAP

    n0, cap = max(16, 2 * (k + 1) * n), N_MAX_CAP // 64
    n_max = n0 * 2 ** max(int(math.floor(math.log2(cap / n0))), 0) if n0 <= cap else n0
    return n_spaces * TRI_GRAM_SECONDS * (k + 1) * (k + 2) / 2 * 2.0 * n * n * n_max ** 2


def _large_route_dim(k: int, n: int, components: int) -> int:
    """dim M of the largest space the face builds (R5.2: (k N + 1)² nodes, per component)."""
    return components * (k * n + 1) ** 2


def face_beta_estimate(k: int, n1: int, n2: int, components: int = 1, process: bool = True,
                       element: str | None = None, n_spaces: int = 1, norms=("H", "L2")) -> Estimate:
    """One ``beta_rows`` call of a 3D model (a contact face): both sides kept. The dense route
    (dim M up to :data:`~.la.bottom.DENSE_MAX_M`, and every size on the ``nested`` route):
    C nd^{4/3} per side (:data:`SIDE_BYTES_3D`); above it with PARDISO, :data:`LARGE_ROUTE_3D`.
    On tetrahedra (``element`` ``tet``) with the H norm, the ``n_spaces`` triangle Grams
    (:func:`tet_gram_seconds`, :data:`TRI_GRAM_BYTES`) come on top."""
    est = _face_bodies_estimate(k, n1, n2, components, process)
    if element == "tet" and "H" in norms:  # the hexahedra's Grams: Kronecker products of 1D ones
        return Estimate(est.bytes + TRI_GRAM_BYTES, est.seconds + tet_gram_seconds(k, n2, max(n_spaces, 1)))
    return est


def _face_bodies_estimate(k: int, n1: int, n2: int, components: int = 1, process: bool = True) -> Estimate:
    """:func:`face_beta_estimate` but the triangle Grams."""
    from .la.bottom import DENSE_MAX_M

    nds = [components * face_side_dofs(n, k) for n in (n1, n2)]
    route = face_route()
    base = PROCESS_BYTES["beta"] if process else 0
    m = float(_large_route_dim(k, n2, components))
    if route == "pardiso" and m > DENSE_MAX_M:
        a, b, c, d = _large_route_constants(k, components)
        # memory never below the dense route's estimate at the gate (that one is the looser:
        # measured k = 2, 0.93 GB at N = 18 dense, 1.12 GB at N = 19 large), so it grows with N; per
        # component, so the gate's components (k gate + 1)^2 <= DENSE_MAX_M takes the dense route (no recursion)
        gate = int((math.isqrt(DENSE_MAX_M // components) - 1) // k)
        floor = _face_bodies_estimate(k, gate, gate, components, process).bytes if gate >= 1 else 0.0
        return Estimate(max(base + MKL_BYTES + LARGE_ROUTE_MARGIN * (a * sum(nds) + b * m * m), floor),
                        START_SECONDS + LARGE_ROUTE_MARGIN * (c * sum(nds) + d * m ** 3))
    volume = sum(SIDE_BYTES_3D[route, min(k, 2)] * nd ** (4.0 / 3.0) for nd in nds)
    if route == "nested":
        return Estimate(base + volume, START_SECONDS + SECONDS_PER_DOF2_3D * sum(nd ** 2 for nd in nds))
    c, d = _large_route_constants(k, components)[2], DENSE_ROUTE_SECONDS_3D[min(k, 2)]
    return Estimate(base + MKL_BYTES + volume, START_SECONDS + LARGE_ROUTE_MARGIN * (c * sum(nds) + d * m ** 3))


def beta_estimate(family: str, k: int, n1: int, n2: int, multiplier_mesh="omega2",
                  norms=("H", "L2"), h_route: str = "logkernel", process: bool = True,
                  components: int = 1, dim: int = 2, element: str | None = None,
                  n_spaces: int = 1) -> Estimate:
    """One ``beta_rows`` call: both sides kept, then every multiplier space in turn (the
    largest degree s ≤ k counts: a space of degree s has at most N(s + 1) functions).
    ``components``: displacement components per node (2 for the elastic model: the side
    volume is that of ``components`` × the dofs; not separately measured). ``dim`` = 3: the
    bodies of a 3D model (:func:`face_beta_estimate`, which also takes the ``element`` and the
    number of spaces, ``n_spaces``)."""
    if dim == 3:
        return face_beta_estimate(k, n1, n2, components, process, element, n_spaces, norms)
    mms = [multiplier_mesh] if isinstance(multiplier_mesh, str) else list(multiplier_mesh)
    nds = [components * side_dofs(family, n, k) for n in (n1, n2)]
    volume = sum(_side_bytes(nd, "beta") for nd in nds)
    dense = max(_dense_bytes(k, (n1, n2), _multiplier_intervals(mm, n1, n2), k, norms, h_route, dim - 1)
                for mm in mms)
    seconds = START_SECONDS + SECONDS_PER_DOF15["beta"] * sum(nd ** 1.5 for nd in nds) * len(mms)
    return Estimate((PROCESS_BYTES["beta"] if process else 0) + volume + dense, seconds)


def contact_estimate(family: str, k: int, n1: int, n2: int, n_ref: int | None = None,
                     n_cases: int = 1, process: bool = True) -> Estimate:
    """One contact solve per case on (N1, N2); with ``n_ref`` (a scene measured against a
    reference solve) first the reference (degree k + 1, structured N_ref × N_ref, kept for
    the whole request)."""
    nds = [side_dofs(family, n, k) for n in (n1, n2)]
    total = sum(_side_bytes(nd, "contact") for nd in nds) + CONTACT_EXTRA_BYTES
    total += _dense_bytes(k, (n1, n2), n2, k, ("H",), "logkernel", 1)  # a 2D scene: Γ a curve
    seconds = START_SECONDS + SECONDS_PER_DOF15["contact"] * sum(nd ** 1.5 for nd in nds) * max(n_cases, 1)
    if n_ref is not None:
        nd_ref = side_dofs("structured", n_ref, k + 1)
        total += 2 * _side_bytes(nd_ref, "reference") + _dense_bytes(k + 1, (n_ref, n_ref), n_ref, k + 1,
                                                                    ("H",), "logkernel", 1)
        seconds += SECONDS_PER_DOF15["contact"] * 2 * nd_ref ** 1.5
    return Estimate((PROCESS_BYTES["contact"] if process else 0) + total, seconds)


def verdict_estimate(family: str, k: int, ns, norm: str, multiplier_mesh: str = "omega2", dim: int = 2,
                     n1_offset: int = 0, components: int = 1) -> Estimate:
    """β_h on the pairs (N + ``n1_offset``, N), one N after the other: the largest sets the memory."""
    ests = [beta_estimate(family, k, n + n1_offset, n, multiplier_mesh, (norm,), components=components, dim=dim)
            for n in ns]
    return Estimate(max(e.bytes for e in ests), START_SECONDS + sum(e.seconds - START_SECONDS for e in ests))


VECTOR_BENCHES = ("elastic",)
"""``bench --what`` targets whose bodies carry two displacement components (the plane-strain β routes)."""


def bench_estimate(what: str, ns, ks, repeats: int = 3, eigsh_max_n=None, kkt_max_n: int = 64,
                   n_problems: int = 10) -> Estimate:
    """``bench``: every (N, k) in turn, each route next to ours (factor :data:`BENCH_FACTOR`);
    β's shift-invert eigsh route and contact's sparse-KKT route dominate the time; ``face`` the 3D
    β routes, ``elastic`` the plane-strain β routes (:mod:`~infsup_contact.bench.beta_models`)."""
    peak, seconds = 0.0, START_SECONDS
    for n in ns:
        for k in ks:
            if what == "face":  # 3D: ours + its factorization again (ours_core, limit)
                inner = face_beta_estimate(k, n, n, process=False)
                peak = max(peak, BENCH_FACTOR[what] * inner.bytes)
                seconds += repeats * 3 * (inner.seconds - START_SECONDS)
                continue
            nd_total = 2 * side_dofs("structured", n, k)
            if what in VECTOR_BENCHES:  # two components per node, the H norm; no pencil route
                inner = beta_estimate("structured", k, n, n, norms=("H",), process=False, components=2)
            elif what in ("beta", "arc"):  # arc: flat, exact and projection β side by side, all spaces
                inner = beta_estimate("structured", k, n, n, process=False)
                if eigsh_max_n is None or n <= eigsh_max_n:
                    seconds += SECONDS_PER_DOF15["eigsh"] * nd_total ** 1.5 * n_problems
            else:
                inner = contact_estimate("structured", k, n, n, process=False)
                if kkt_max_n is None or n <= kkt_max_n:
                    seconds += repeats * SECONDS_PER_DOF15["kkt"] * nd_total ** 1.5
            peak = max(peak, BENCH_FACTOR[what] * inner.bytes)
            seconds += repeats * 6 * (inner.seconds - START_SECONDS)
    return Estimate(PROCESS_BYTES["bench"] + peak, seconds)


def job_mem_mb(estimate: Estimate, margin: float = 1.25) -> int:
    """``mem_mb`` of a workflow job: the estimate with a margin, rounded up to 100 MB."""
    return int(math.ceil(margin * estimate.bytes / 1e8)) * 100


SYSTEM_MARGIN = 1.4
"""Factor on the foreign-system memory formula (measured/formula = 1.00 on its one calibration run)."""
INTERFACE_FRACTION = 0.1
"""B touching at most this fraction of a system's dofs is an interface (contact), not a Stokes
pressure (which touches ~n): the systems engine keeps such a system on the Γ route above its
dense gate (``systems.engine.choose_route``), and :func:`looks_3d` reads its dimension."""
SURFACE_EXPONENT = 0.6
"""B touching at least n^SURFACE_EXPONENT of n dofs (and at most :data:`INTERFACE_FRACTION` of
them) marks a 3D body's surface: n_Γ ~ n^{2/3} on a 3D interface, n^{1/2} on a 2D one."""
SYSTEM_BYTES_3D = 900.0
"""C in C · n^{4/3} bytes of a 3D system's sparse factorization (the fill of nested dissection in
3D): a membranes3d export, R5.2, k = 2, N = 20 (121,680 dofs, two bodies, ``gamma-dense``)
peaked at 4.4 GB, i.e. C ≈ 900 on n^{4/3} of one body's half, times two."""
SYSTEM_SECONDS_3D = 3e-9
"""Seconds per n² of a 3D system (fitted to the same export)."""


KERNEL_SVD_MAX_BYTES = 3e7
"""``systems.engine.SVD_MAX_BYTES`` (the largest W, n_touched × m doubles, decided by a dense SVD)."""
CERTIFICATE_COPIES = 2.0
"""Dense m × m arrays of ``bottom_kernel``'s certificate above it (``la.bottom.at_most_below``):
measured 2.0 × 8 m² bytes at m = 16,641 (Stokes P2-P1, N = 128), 2.1 at m = 4,225."""
KERNEL_SECONDS_PER_M3 = 1.6e-11
"""Seconds per m³ of that whole decision (CPU time; 72 s at m = 16,641, its dense Cholesky alone
``dpotrf`` 7e-12 m³ at m = 8,000)."""


def kernel_decision_cost(m: int, n_touched: int) -> tuple:
    """(bytes, seconds) of a foreign level's kernel decision: a dense SVD of W (three copies,
    ≤ :data:`KERNEL_SVD_MAX_BYTES`) or ``bottom_kernel``'s dense certificate, what a level with
    thousands of multipliers costs most (Taylor–Hood N = 128: 4.4 GB, its LUs a few hundred MB)."""
    w_bytes = 8.0 * m * n_touched
    if w_bytes <= KERNEL_SVD_MAX_BYTES:
        return 3 * w_bytes, KERNEL_SECONDS_PER_M3 * n_touched * m * min(m, n_touched)
    return CERTIFICATE_COPIES * 8.0 * m * m, KERNEL_SECONDS_PER_M3 * float(m) ** 3


def looks_3d(n: int, n_touched: int) -> bool:
    """Whether B touches a 3D body's surface (:data:`SURFACE_EXPONENT`); a foreign system does not
    declare its dimension."""
    return n > 1 and n ** SURFACE_EXPONENT <= n_touched <= INTERFACE_FRACTION * n


def system_estimate(levels) -> Estimate:
    """A foreign system (``verdict --system``, ``beta --system``): one level at a time, the
    largest sets the memory. ``levels``: (n, m, n_touched, nnz of A, route) per level. Sparse
    factors as a 2D problem's, C · n · log2 n bytes (C = 175 as for a side), the dense blocks of
    the dense routes (X or A⁻¹ Bᵀ, S, the pencil's copies) explicitly, the shift-invert route's
    LUs of [[A, Bᵀ], [B, −δG]] and of A, all × :data:`SYSTEM_MARGIN`; before them the kernel
    decision (:func:`kernel_decision_cost`). Where B touches a 3D body's surface
    (:func:`looks_3d`) the sparse part is at least the 3D fill :data:`SYSTEM_BYTES_3D` (n/2)^{4/3}
    per body and the time gains :data:`SYSTEM_SECONDS_3D` n². Measured against
    (docs/performance.md, "The dry run's estimates, measured"): Taylor–Hood 16..128 (scikit-fem,
    130k + 16.6k dofs at 128; 4.6 GiB, 82 s CPU, 88 % of both in the kernel decision) and a
    membranes3d export."""
    peak, seconds = 0.0, START_SECONDS
    for n, m, nt, nnz, route in levels:
        sparse = _side_bytes(n + m, "beta") + 2 * 12.0 * nnz
        three_d = looks_3d(n, nt)
        if three_d:  # the fill of a 3D factorization, two bodies of n/2 (:data:`SYSTEM_BYTES_3D`)
            sparse = max(sparse, 2 * SYSTEM_BYTES_3D * (n / 2) ** (4.0 / 3.0) + 2 * 12.0 * nnz)
        if route == "gamma-dense":
            dense = 8.0 * (3 * nt * nt + 6 * m * m + nt * m)
        elif route == "solves-dense":
            dense = 8.0 * (n * m + 6 * m * m)
        else:
            sparse += _side_bytes(n, "beta")
            dense = 8.0 * 20 * (n + m)
        kernel_bytes, kernel_seconds = kernel_decision_cost(m, nt)
        # the kernel is decided before the factorizations, its arrays freed: the larger phase counts
        peak = max(peak, SYSTEM_MARGIN * (sparse + dense), kernel_bytes + 2 * 12.0 * nnz)
        seconds += SECONDS_PER_DOF15["beta"] * 2 * (n + m) ** 1.5 + 1e-9 * (m ** 3 if route != "shift-invert" else 0)
        seconds += kernel_seconds
        seconds += SYSTEM_SECONDS_3D * n ** 2 if three_d else 0.0
    return Estimate(PROCESS_BYTES["beta"] + peak, seconds)
