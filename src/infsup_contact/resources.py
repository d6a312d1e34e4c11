"""Memory and time of a request, estimated from its sizes before anything is allocated.

Pure arithmetic (no numpy, no NGSolve): the command line checks a request against the
available memory before it imports the solvers, and the workflow gives every β_h and contact
job its ``mem_mb`` from the same numbers (``workflow/rules/common.smk``).

The model
---------
Per membrane with N segments on Γ and degree k, the structured mesh has
``nd = (N k)(N k − 1)`` free dofs (× 1.3 for the unstructured family, whose netgen meshes
carry up to 1.24× the dofs). What a side costs grows like the sparse factorization:
nested-dissection fill is O(nd log nd) in 2D, and the mesh, the stiffness and its copies are
O(nd), so a side takes ``C · nd · log2(nd)`` bytes while it is kept (both sides are kept
until the request ends). The dense interface operators — the Schur complement S_i and
X_i = S_i⁻¹, (N k)² doubles each, plus the trailing blocks of the factors — and the coupling
matrices (dim M × n_Γ, quadrature points × n_Γ) are added explicitly; so is the Gram matrix
of the H^{-1/2}_00 norm (the log kernel holds one (s+1)² block and its quadrature per pair
of multiplier intervals; the sine-series route ~1600 (dim M)² bytes) and the dense
eigenproblem (a few (dim M)² doubles). The constants were measured with
``/usr/bin/time -v`` (maximum resident set size) and ``tracemalloc`` on this package (see
docs/refusals.md, "The memory estimate"); the estimate is an upper bound within ~10–40 % at sizes where the
request dominates the interpreter (≥ 100k dofs).

The time is rough (order of magnitude): a sparse LU is O(nd^1.5) in 2D.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .discretization.segment.interface import SEGMENT

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
    """Peak resident memory (bytes, interpreter included) and wall time (seconds) of a request."""

    bytes: float
    seconds: float

    @property
    def mb(self) -> int:
        """Megabytes (10⁶ B, Snakemake's ``mem_mb``), rounded up."""
        return int(math.ceil(self.bytes / 1e6))

    def describe(self) -> str:
        return f"~{human_bytes(self.bytes)} peak memory, ~{human_seconds(self.seconds)}"


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


def _dense_bytes(k: int, ns, n_mult: float, s: int, norms, h_route: str) -> float:
    """Dense Γ work of one multiplier space: interface operators, couplings, Gram, eigh."""
    m = n_mult * (s + 1)                        # dim M: at most (s + 1) per interval
    n_quad = sum(ns) * (k + s + 2) / 2          # quadrature points on the common refinement
    total = 0.0
    for n in ns:
        g = float(SEGMENT.trace_nodes(k, n))  # Γ dofs of side i
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
the process included. Peak resident memory (hexahedra, every case, ``/usr/bin/time``), with
the C each implies:

- ``pardiso``, k = 1: 0.68 GB at N = 32 (214; the 5 spaces of ``--case all``);
- ``pardiso``, k = 2: 0.30 GB at N = 8, 1.05 GB at N = 16 (400; the 12 spaces of ``--case all``);
  above dim M = 1,500 (k = 1 from N = 38, k = 2 from N = 19) :data:`LARGE_ROUTE_3D` instead;
- ``nested`` (SuperLU): 0.36 GB at N = 8, 2.3 GB at N = 16, 5.3 GB at N = 20 (k = 2), 7.1 GB
  at N = 40 (k = 1).

The estimate is above each; the ``pardiso`` route adds :data:`MKL_BYTES` for the loaded library."""
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


LARGE_ROUTE_3D = {1: (1530.0, 197.0, 6.06e-5, 5.28e-10), 2: (4350.0, 132.0, 1.31e-4, 6.49e-10)}
"""(a, b, c, d) of the large route (dim M above :data:`~.la.bottom.DENSE_MAX_M`: sparse
couplings, exponential-sum Grams in the reflections' parity blocks, bottom pencils; PARDISO):
bytes a Σ nd + b m² and seconds c Σ nd + d m³ beyond the process, m = (k N₂ + 1)² (R5.2 on
G_h = the trace of Ω2). Non-negative least squares, relative residuals, on ``beta --model
membranes3d --case all --norm all`` (hexahedra, every space the face builds: 5 at k = 1, 12 at
k = 2; 2 BLAS/MKL threads, quiet machine, ``/usr/bin/time``; the wall times in CHANGELOG.md):

- k = 1: N = 40 1.02 GB; N = 48 1.73 GB; N = 64 4.58 GB;
- k = 2: N = 20 1.19 GB; N = 24 1.94 GB; N = 28 3.16 GB; N = 32 4.73 GB; N = 36 7.32 GB.

The sparse factors grow like nd here (nd^{4/3} only asymptotically), the Grams, the pencils' and
the shared series' dense arrays like m², their factorizations like m³. The estimate multiplies
the fit by :data:`LARGE_ROUTE_MARGIN`, so it lies above every measurement (by 3 % to 29 %)."""
LARGE_ROUTE_MARGIN = 1.2
DENSE_ROUTE_SECONDS_3D = {1: 2.2e-9, 2: 5.4e-9}
"""d of c Σ nd + d m³ seconds (c of :data:`LARGE_ROUTE_3D`) on PARDISO's dense route, where the
dense SVDs and pencils cost more per m³ (fitted at k = 1, N = 32 and k = 2, N = 16, ``--case
all``). At the gate the large route is the faster one (k = 1: the large route at N = 40 takes
about 1.5× the dense route at N = 32, for twice the multipliers)."""


def _large_route_dim(k: int, n: int, components: int) -> int:
    """dim M of the largest space the face builds (R5.2: (k N + 1)² nodes, per component)."""
    return components * (k * n + 1) ** 2


def face_beta_estimate(k: int, n1: int, n2: int, components: int = 1, process: bool = True) -> Estimate:
    """One ``beta_rows`` call of a 3D model (a contact face): both sides kept. The dense route
    (dim M up to :data:`~.la.bottom.DENSE_MAX_M`, and every size on the ``nested`` route):
    C nd^{4/3} per side (:data:`SIDE_BYTES_3D`); above it with PARDISO, :data:`LARGE_ROUTE_3D`."""
    from .la.bottom import DENSE_MAX_M

    nds = [components * face_side_dofs(n, k) for n in (n1, n2)]
    route = face_route()
    base = PROCESS_BYTES["beta"] if process else 0
    m = float(_large_route_dim(k, n2, components))
    if route == "pardiso" and m > DENSE_MAX_M:
        a, b, c, d = LARGE_ROUTE_3D[min(k, 2)]
        # memory never below the dense route's estimate at the gate (that one is the looser:
        # measured k = 2, 0.93 GB at N = 18 dense, 1.12 GB at N = 19 large), so it grows with N
        # (per component: the gate's dim M is components (k gate + 1)^2 <= DENSE_MAX_M, so the floor
        # takes the dense route; without it elastic3d's 3 components recursed without end)
        gate = int((math.isqrt(DENSE_MAX_M // components) - 1) // k)
        floor = face_beta_estimate(k, gate, gate, components, process).bytes if gate >= 1 else 0.0
        return Estimate(max(base + MKL_BYTES + LARGE_ROUTE_MARGIN * (a * sum(nds) + b * m * m), floor),
                        START_SECONDS + LARGE_ROUTE_MARGIN * (c * sum(nds) + d * m ** 3))
    volume = sum(SIDE_BYTES_3D[route, min(k, 2)] * nd ** (4.0 / 3.0) for nd in nds)
    if route == "nested":
        return Estimate(base + volume, START_SECONDS + SECONDS_PER_DOF2_3D * sum(nd ** 2 for nd in nds))
    c, d = LARGE_ROUTE_3D[min(k, 2)][2], DENSE_ROUTE_SECONDS_3D[min(k, 2)]
    return Estimate(base + MKL_BYTES + volume, START_SECONDS + LARGE_ROUTE_MARGIN * (c * sum(nds) + d * m ** 3))


def beta_estimate(family: str, k: int, n1: int, n2: int, multiplier_mesh="omega2",
                  norms=("H", "L2"), h_route: str = "logkernel", process: bool = True,
                  components: int = 1, dim: int = 2) -> Estimate:
    """One ``beta_rows`` call: both sides kept, then every multiplier space in turn (the
    largest degree s ≤ k counts: a space of degree s has at most N(s + 1) functions).
    ``components``: displacement components per node (2 for the elastic model: the side
    volume is that of ``components`` × the dofs; not separately measured). ``dim`` = 3: the
    bodies of a 3D model (:func:`face_beta_estimate`)."""
    if dim == 3:
        return face_beta_estimate(k, n1, n2, components, process)
    mms = [multiplier_mesh] if isinstance(multiplier_mesh, str) else list(multiplier_mesh)
    nds = [components * side_dofs(family, n, k) for n in (n1, n2)]
    volume = sum(_side_bytes(nd, "beta") for nd in nds)
    dense = max(_dense_bytes(k, (n1, n2), _multiplier_intervals(mm, n1, n2), k, norms, h_route)
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
    total += _dense_bytes(k, (n1, n2), n2, k, ("H",), "logkernel")
    seconds = START_SECONDS + SECONDS_PER_DOF15["contact"] * sum(nd ** 1.5 for nd in nds) * max(n_cases, 1)
    if n_ref is not None:
        nd_ref = side_dofs("structured", n_ref, k + 1)
        total += 2 * _side_bytes(nd_ref, "reference") + _dense_bytes(k + 1, (n_ref, n_ref), n_ref, k + 1,
                                                                    ("H",), "logkernel")
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


def available_bytes(meminfo: str = "/proc/meminfo") -> float | None:
    """MemAvailable of /proc/meminfo in bytes (None where the file or the field is missing)."""
    try:
        with open(meminfo) as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def total_bytes(meminfo: str = "/proc/meminfo") -> float | None:
    """MemTotal of /proc/meminfo in bytes (None where unavailable)."""
    try:
        with open(meminfo) as fh:
            for line in fh:
                if line.startswith("MemTotal:"):
                    return float(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


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


def looks_3d(n: int, n_touched: int) -> bool:
    """Whether B touches a 3D body's surface (:data:`SURFACE_EXPONENT`); a foreign system does not
    declare its dimension."""
    return n > 1 and n ** SURFACE_EXPONENT <= n_touched <= INTERFACE_FRACTION * n


def system_estimate(levels) -> Estimate:
    """A foreign system (``verdict --system``, ``beta --system``): one level at a time, the
    largest sets the memory. ``levels``: (n, m, n_touched, nnz of A, route) per level. Sparse
    factors as a 2D problem's, C · n · log2 n bytes (C = 175 as for a side), the dense
    blocks of the dense routes (X or A⁻¹ Bᵀ, S, the pencil's copies) explicitly; the
    shift-invert route factorizes [[A, Bᵀ], [B, −δG]] and A (residuals). Calibrated on one
    measurement only: Taylor–Hood 16..128 (scikit-fem, 130k + 16.5k dofs at 128) peaked at
    1.02 GiB (``/usr/bin/time -v``) where the formula without :data:`SYSTEM_MARGIN` gave
    1.02 GiB; the margin makes it an upper bound until more systems are measured. Where B touches
    a 3D body's surface (:func:`looks_3d`) the sparse part is at least the 3D fill
    :data:`SYSTEM_BYTES_3D` (n/2)^{4/3} per body and the time gains :data:`SYSTEM_SECONDS_3D` n²:
    the 2D formula gave a third of the memory and of the time a 3D export took."""
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
        peak = max(peak, SYSTEM_MARGIN * (sparse + dense))
        seconds += SECONDS_PER_DOF15["beta"] * 2 * (n + m) ** 1.5 + 1e-9 * (m ** 3 if route != "shift-invert" else 0)
        seconds += SYSTEM_SECONDS_3D * n ** 2 if three_d else 0.0
    return Estimate(PROCESS_BYTES["beta"] + peak, seconds)
