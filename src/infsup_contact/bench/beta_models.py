"""The β_h benchmark of each model (:class:`~.beta_bench.BetaBench`): what differs between them.

``membranes`` (``bench --what beta``, results/benchmarks/beta.csv)
    The paper's cases valid for k × both norms (H, L2); β above the structural kernel, whose
    values must stay below ``KERNEL_BETA``; the limit factorizes by SuperLU; the full-pencil
    routes ``eigsh`` and ``dense`` (:mod:`.beta_pencil`) beside ours; ``ratio_to_ours_core``.
``elastic`` (``bench --what elastic``, results/benchmarks/elastic_beta.csv)
    Every registered space valid for k (or the given ones), H norm, ν of the model; β_h itself
    compared; the limit factorizes by SuperLU.
``face`` (``bench --what face``, results/benchmarks/face.csv)
    The 3D membranes of ``MEMBRANES3D`` (hexahedra or tetrahedra, ``element``): every space built
    on the face (as ``infsup-contact beta --model membranes3d --case all``), both norms; β above
    the kernel ours decided; the limit is the cheapest known computation of the rows and counts
    its flops (:mod:`.face_limit`); the Schur-complement rows of :mod:`.face_schur` after each setup.
"""
from __future__ import annotations

from functools import partial

from ..discretization.spaces import registry
from ..errors import InputError
from ..la import pardiso
from ..models.elastic import elastic_model
from ..models.membranes import MEMBRANES
from ..models.membranes3d import MEMBRANES3D
from .beta_bench import BetaBench, beta_ours_engine, splu_best_order
from .beta_pencil import INCLUDES as PENCIL_INCLUDES
from .beta_pencil import pencil_routes
from .face_schur import INCLUDES as SCHUR_INCLUDES
from .face_schur import schur_rows
from .face_limit import face_limit

_SECONDS = ("seconds_median", "seconds_min", "seconds_max", "ratio_to_ours")
BETA_COLUMNS = ("what", "route", "k", "N", *_SECONDS, "ratio_to_ours_core", "repeats", "max_abs_diff", "kernel_ok",
                "n_problems", "ndof", "includes")
ELASTIC_COLUMNS = ("what", "route", "k", "N", *_SECONDS, "ratio_to_limit", "repeats", "max_abs_diff", "n_problems",
                   "ndof", "includes")
FACE_COLUMNS = ("what", "route", "element", "k", "N", *_SECONDS, "ratio_to_limit", "max_abs_diff", "repeats",
                "n_problems", "ndof", "dim_M_max", "limit_gflop", "gflop_per_s", "includes")


def structural_kernel(case, k, n, row) -> int:
    return registry.structural_kernel_dim(case, k, n)


def pardiso_or_splu(K) -> None:
    """PARDISO's Cholesky where MKL loads (released at once), else SuperLU in its best order."""
    if pardiso.available():
        pardiso.Factor(K).handle.release()
    else:
        splu_best_order(K)


def membranes_bench(dense_max_size: int = 2500, eigsh_max_n: int | None = None) -> BetaBench:
    """The 2D membranes' benchmark; the pencil routes within the given sizes."""
    return BetaBench(
        "beta", MEMBRANES, ("H", "L2"), BETA_COLUMNS, "ratio_to_ours_core",
        cases=lambda k, gamma, g_h, ids: registry.ids_valid_for(k, registry.PAPER_CASES if ids is None else ids),
        kernel=structural_kernel, limit_factor=splu_best_order, compare_limit=False,
        includes={"ours": "mesh+assembly+Γ-last LU+Schur+couplings+interface+Gram+eigh (+β with v1=0)",
                  "ours_core": "Γ-last LU+Schur+couplings+interface+Gram+eigh (assembled stiffness given)",
                  "limit": "best-order LU of each side + one eigh per (case,norm) (operators, Gram given)",
                  **PENCIL_INCLUDES},
        extra_routes=partial(pencil_routes, dense_max_size=dense_max_size, eigsh_max_n=eigsh_max_n))


def elastic_bench(nu: float = 0.3) -> BetaBench:
    """The plane-strain bodies' benchmark at Poisson ratio ν."""
    return BetaBench(
        "elastic_beta", elastic_model(nu), ("H",), ELASTIC_COLUMNS, "ratio_to_limit",
        cases=lambda k, gamma, g_h, ids: registry.common_ids(k) if ids is None else registry.ids_valid_for(k, ids),
        kernel=lambda case, k, n, row: 0, limit_factor=splu_best_order,
        includes={"ours": "meshes, assembly, factorization + Schur per body, couplings, interface operator, Gram, "
                          "eigh (+ β with v1 = 0), every case",
                  "ours_core": "factorization + Schur per body, couplings, interface operator, Gram, eigh, every case",
                  "limit": "one splu per body (MMD_AT_PLUS_A) + one eigh per case on given operators"})


FACE_BENCH = BetaBench(
    "face_beta", MEMBRANES3D, ("H", "L2"), FACE_COLUMNS, "ratio_to_limit",
    cases=lambda k, gamma, g_h, ids: [c for c in registry.ids_built_on(k, gamma, g_h)  # beta --case all
                                      if ids is None or c in ids],
    kernel=lambda case, k, n, row: row["kernel_dim"], limit_factor=pardiso_or_splu,
    includes={"ours": "meshes+assembly+Γ-last LU+Schur per body+couplings+kernel from Bᵀ+interface+Gram+eigh "
                      "(+β with v1=0), every case × norm",
              "ours_core": "ours' engine from the assembled stiffness: Γ-last LU+Schur per body (parity parts)+"
                           "couplings+Grams+kernel decision+interface+pencils in blocks (+β with v1=0)",
              "limit": "plain Cholesky (PARDISO) of each body's parity parts, side by side (one body on a mirrored "
                       "pair) + the eigenvalues of each parity block of each (case,norm), side by side (interface "
                       "operators, Grams given)",
              **SCHUR_INCLUDES},
    extra_rows=schur_rows, limit_route=face_limit, core_route=beta_ours_engine)
"""The 3D membranes' face benchmark (``element`` is a mesh option of ``bench_beta``)."""


BENCHES = {"beta": membranes_bench, "elastic": elastic_bench, "face": lambda: FACE_BENCH}
"""``bench --what`` → the builder of that model's benchmark (its keywords: the options it takes)."""


def bench_for(what: str, **options) -> BetaBench:
    """The benchmark ``bench --what`` names: ``beta`` (options ``dense_max_size``, ``eigsh_max_n``),
    ``elastic`` (``nu``) or ``face`` (none; its ``element`` is a mesh option of ``bench_beta``)."""
    if what not in BENCHES:
        raise InputError("what", ", ".join(BENCHES), got=what)
    return BENCHES[what](**options)
