"""The declared tables: every table the package, the CLI and the workflow read, with its columns,
their types and its key (:data:`SCHEMAS`); :func:`infsup_contact.io.read_table` checks a table
against them."""
from __future__ import annotations

# Every table the package, the CLI and the workflow read is declared here: its columns (a
# consumer's required ones and the producer's optional ones), their types, and its key.
# Column types:
#   int    an integer (finite)            int?   an integer or an empty cell
#   float  a finite number                float? a number or an empty cell (NaN)
#   str    non-empty text                 str?   text or an empty cell
#   bool   True/False                     bool?  True/False or an empty cell
# A type without "?" is one the producer always writes: an empty cell there is damage (a
# truncated row, a number cut short), not a missing value. Extra columns are allowed (the
# producers add provenance and diagnostics); only the declared ones are checked.

_BETA = {"case": "str", "k": "int", "family": "str", "N1": "int", "N2": "int", "multiplier_mesh": "str",
         "c1": "float", "c2": "float", "norm": "str", "beta": "float", "kernel_dim": "int",
         "structural_kernel_dim": "int", "smallest_nonzero": "float?", "beta_v1_zero": "float?", "dim_M": "int",
         "dim_W": "int", "ndof": "int"}
_MEASURES = {"energy_error": "float", "l2_error": "float", "lambda_l2_error": "float", "lambda_hm12_error": "float"}
_ELASTIC_BETA = {"model": "str", "case": "str", "k": "int", "family": "str", "N1": "int", "N2": "int",
                 "multiplier_mesh": "str", "E1": "float", "E2": "float", "nu": "float", "norm": "str", "beta": "float",
                 "kernel_dim": "int", "structural_kernel_dim": "int", "smallest_nonzero": "float?",
                 "beta_v1_zero": "float?", "beta_membranes": "float?", "kernel_dim_membranes": "int",
                 "bound_factor": "float?"}
SERIES_COLUMNS = ("scene", "scene_kind", "case", "k", "family", "c1", "c2", "p", "q", "seed", "multiplier_mesh")
"""Columns of a contact table that define a convergence series (those present): rates are
fitted per series, and a series lists each mesh once."""


class Schema:
    """A table kind: ``columns`` (name → type, required), ``optional`` (checked when present),
    ``key`` (columns, those present, that identify a row: no two rows share them), ``label``
    (what the table is, for messages) and ``sep`` (the field separator)."""

    def __init__(self, columns: dict, optional: dict | None = None, key: tuple = (), label: str | None = None,
                 sep: str = ","):
        self.columns, self.optional, self.key, self.label, self.sep = columns, optional or {}, key, label, sep

    def types(self, present) -> dict:
        """Type of every declared column among ``present``."""
        every = {**self.optional, **self.columns}
        return {c: every[c] for c in present if c in every}


SCHEMAS = {
    "beta": Schema(_BETA, optional={"seed": "int?", "series": "str"},
                   key=("family", "case", "k", "N1", "N2", "seed", "multiplier_mesh", "c1", "c2", "norm", "series")),
    "contact": Schema({"scene": "str", "case": "str", "k": "int", "family": "str", "N1": "int", "N2": "int",
                       "c1": "float", "c2": "float", "ndof": "int", "dim_M": "int", "cone": "str", "iterations": "int",
                       **_MEASURES, "min_lambda_pointwise": "float?", "max_penetration": "float?", "nonunique": "bool",
                       "kernel_dim": "int"},
                      optional={"p": "float?", "q": "float?", "seed": "int?", "scene_kind": "str"},
                      key=("scene", "case", "k", "family", "N1", "N2", "c1", "c2", "p", "q", "seed")),
    # `infsup-contact rates`: any contact table; its series and meshes are checked by study/contact/rates.py
    "contact_input": Schema({"scene": "str", "case": "str", "k": "int", "family": "str", "N1": "int", "N2": "int",
                             **_MEASURES},
                            optional={"c1": "float", "c2": "float", "p": "float?", "q": "float?", "seed": "int?",
                                      "scene_kind": "str", "multiplier_mesh": "str"},
                            label="a contact table (`infsup-contact contact` or results/tables/contact.csv)"),
    "rates": Schema({"scene": "str", "case": "str", "k": "int", "family": "str", "measure": "str", "slope": "float?",
                     "stderr": "float?", "points": "int", "h_min": "float", "expected": "float?"},
                    optional={"c1": "float", "c2": "float", "p": "float?", "q": "float?", "seed": "int?",
                              "scene_kind": "str", "multiplier_mesh": "str"},
                    key=(*SERIES_COLUMNS, "measure")),
    "producers": Schema({"producer": "str", "version": "str?", "space": "str", "offset": "int", "norm": "str",
                         "status": "str", "verdict": "str?", "kernel_dim": "int?", "beta_levels": "str?",
                         "kernel_levels": "str?", "h_levels": "str?", "slope": "float?", "slope_lo": "float?",
                         "slope_hi": "float?", "evidence": "str?", "seconds": "float?", "install": "str",
                         "system": "str?"}, optional={"dim_M_levels": "str?", "stabilisation": "str?", "norm_as_written": "str?"}, key=("producer", "space", "offset", "norm"),
                        label="the producers table (rules/producers.smk)"),
    "producer_modes": Schema({"producer": "str", "space": "str", "offset": "int", "level": "int", "h": "float",
                              "beta": "float", "in_kernel": "bool", "x": "float", "mu": "float"},
                             optional={"y": "float?"}, label="the producers' modes (rules/producers.smk)"),
    "census": Schema({"code": "str", "version": "str", "space": "str", "offset": "int", "matching": "str",
                      "norm": "str", "status": "str", "verdict": "str", "predicted": "str", "other_norms": "str",
                      "kernel_levels": "str", "dim_M_levels": "str", "kernel_vs_dim": "str", "h_levels": "str",
                      "beta_levels": "str", "slope": "float?", "slope_lo": "float?", "slope_hi": "float?",
                      "fix": "str", "claim": "str", "predicted_in": "str", "evidence": "str",
                      "stabilisation": "str"},
                     key=("code", "space", "offset"), label="the census (rules/producers.smk)"),
    "claims": Schema({"claim_id": "str", "paper_ref": "str", "statement": "str", "evidence": "str", "verdict": "str",
                      "predicted": "str"}, key=("claim_id",), label="a claims ledger"),
    # no key: a sample 1e-9·h inside each end of an interval may print as its neighbour's x
    "gamma_profiles": Schema({"case": "str", "k": "int", "N": "int", "x": "float", "quantity": "str",
                              "value": "float?"}),
    "field_values": Schema({"case": "str", "k": "int", "N": "int", "side": "int", "x": "float", "y": "float",
                            "u": "float"}, key=("case", "k", "N", "side", "x", "y")),
    "speed_accuracy": Schema({"scene": "str", "case": "str", "k": "int", "family": "str", "N": "int",
                              "seconds": "float", "energy_error": "float", "lambda_hm12_error": "float",
                              "ndof": "int", "dim_M": "int", "pareto_energy": "bool", "pareto_lambda": "bool"},
                             key=("scene", "case", "k", "family", "N")),
    "bench": Schema({"what": "str", "route": "str", "k": "int", "N": "int", "seconds_median": "float",
                     "seconds_min": "float", "seconds_max": "float", "ratio_to_ours": "float?"},
                    key=("what", "route", "k", "N"), label="a bench table"),
    "mesh_quality": Schema({"family": "str", "N1": "int", "N2": "int", "side": "int", "h_max": "float",
                            "h_min": "float", "min_angle": "float"}, optional={"seed": "int?"},
                           key=("family", "N1", "N2", "side", "seed")),
    # elastic stage (study/beta/elastic.py, study/patch/segment.py, study/contact/hertz.py)
    "elastic_beta": Schema(_ELASTIC_BETA, key=("model", "case", "k", "family", "N1", "N2", "multiplier_mesh", "E1",
                                               "E2", "nu", "norm")),
    "elastic_patch": Schema({"case": "str", "k": "int", "N1": "int", "N2": "int", "p": "float", "kernel_dim": "int",
                             "lambda_max_rel_error": "float", "lambda_end_rel_error": "float",
                             "lambda_middle_rel_error": "float", "u_max_rel_error": "float", "passes": "bool"},
                            optional={"scene": "str", "family": "str", "E1": "float", "E2": "float", "nu": "float",
                                      "delta": "float"},
                            key=("scene", "case", "k", "family", "N1", "N2", "E1", "E2", "nu", "delta")),
    "elastic_hertz": Schema({"study": "str", "case": "str", "k": "int", "N": "int", "d": "float", "P": "float",
                             "p_max": "float", "half_width": "float", "oscillation": "float",
                             "p_max_rel_error": "float?", "half_width_rel_error": "float?"},
                            optional={"R": "float", "nu": "float", "E1": "float", "E2": "float"},
                            key=("study", "case", "k", "N", "R", "d", "nu", "E1", "E2")),
    # the 3D contact face (rules/models.smk, plans/membranes3d.py: study/beta/batch_rows.py with models/membranes3d.py)
    "face_beta": Schema({**_BETA, "model": "str", "element": "str"},
                        key=("model", "element", "family", "case", "k", "N1", "N2", "multiplier_mesh", "c1", "c2",
                             "norm")),
    # β_h of any model of the model table (plans/beta.py): the face's columns, element "-" for a model without one
    "model_beta": Schema({**_BETA, "model": "str", "element": "str"},
                         key=("model", "element", "family", "case", "k", "N1", "N2", "multiplier_mesh", "c1", "c2",
                              "norm")),
    # the curved segment (plans/arc.py: study/beta/arc.py): β_h per curvature 1/R (0: flat) and coupling
    # (exact, projection; "paper": the flat segment's own code), rows tagged with their series
    "arc_beta": Schema({**_BETA, "curvature": "float", "coupling": "str", "series": "str"},
                       key=("curvature", "coupling", "series", "family", "case", "k", "N1", "N2", "multiplier_mesh",
                            "c1", "c2", "norm")),
    # the patch test on the arc (plans/arc.py: study/patch/arc.py): λ and u errors per curvature and coupling
    "arc_patch": Schema({"curvature": "float", "coupling": "str", "scene": "str", "case": "str", "k": "int",
                         "N1": "int", "N2": "int", "c1": "float", "c2": "float", "pressure": "float",
                         "kernel_dim": "int", "lambda_max_rel_error": "float", "lambda_interior_rel_error": "float?",
                         "u_max_rel_error": "float", "holds_constants": "bool"},
                        key=("curvature", "coupling", "case", "k", "N1", "N2")),
    # the 3D elastic bodies on the face (rules/models.smk, plans/elastic3d.py: study/face/elastic3d.py): β_h per ν
    "elastic3d_beta": Schema({**_BETA, "model": "str", "element": "str", "nu": "float"},
                             key=("model", "element", "family", "case", "k", "N1", "N2", "multiplier_mesh", "c1",
                                  "c2", "nu", "norm")),
    "elastic3d_patch": Schema({"element": "str", "case": "str", "k": "int", "N1": "int", "N2": "int",
                               "E1": "float", "E2": "float", "nu": "float", "lambda_max_rel_error": "float",
                               "u_max_rel_error": "float", "kernel_dim": "int", "passes": "bool"},
                              key=("element", "case", "k", "N1", "N2", "E1", "E2", "nu")),
    # the face studies (rules/models.smk, plans/membranes3d.py: study/patch/face.py, study/face/alpha.py, edge_dropping.py);
    # condition numbers may be inf (singular to working precision): extra columns, not declared
    "face_patch": Schema({"element": "str", "case": "str", "k": "int", "N1": "int", "N2": "int",
                          "lambda_max_rel_error": "float", "u_max_rel_error": "float", "kernel_dim": "int",
                          "passes": "bool"}, key=("element", "case", "k", "N1", "N2")),
    "face_alpha": Schema({"element": "str", "alpha": "float", "N": "int", "norm": "str", "min_weight": "float",
                          "min_weight_gauss": "float", "accepted": "bool", "beta": "float?"},
                         key=("element", "alpha", "N", "norm")),
    "face_edge": Schema({"case": "str", "k": "int", "N": "int", "theta": "float", "beta_H": "float",
                         "beta_L2": "float", "beta_H_resolved": "bool", "beta_L2_resolved": "bool",
                         "beta_L2_kappa": "float?", "beta_L2_kappa_resolved": "bool", "fit_theta_max": "float"},
                        key=("case", "k", "N", "theta")),
    # HEX20 bodies' QUAD8 faces (python -m infsup_contact.study.face.hex20; rule face_hex20_beta): β_h per N
    "face_hex20": Schema({"case": "str", "N": "int", "norm": "str", "dim_M": "int", "dim_W": "int", "kernel_dim": "int",
                          "structural_kernel_dim": "int", "kernel_decision": "str", "beta": "float", "verdict": "str"},
                         key=("case", "N", "norm")),
    # `beta --worst-mode FILE` (cli/worst_mode.py): a mode per β row sampled on Γ; y on a face
    "worst_mode": Schema({"case": "str", "multiplier_mesh": "str", "c1": "float", "c2": "float", "norm": "str",
                          "beta": "float", "x": "float", "mu": "float"}, optional={"y": "float"},
                         key=("case", "multiplier_mesh", "c1", "c2", "norm", "x", "y"), label="a worst-mode table"),
    # results/benchmarks/dag.csv (bench/dag.py: per rule of a run), read by the docs' generator
    "dag": Schema({"rule": "str", "jobs": "int", "wall_s_sum": "float", "wall_s_max": "float",
                   "cpu_s_sum": "float?", "max_rss_mb": "float?"}, key=("rule",), label="a DAG timing table"),
    # results/benchmarks/estimates.csv (bench/estimates.py: --dry-run's estimate against a measured run)
    "estimates": Schema({"example": "str", "command": "str", "est_mib": "float", "rss_mib": "float",
                         "mem_ratio": "float", "est_s": "float", "cpu_s": "float", "wall_s": "float",
                         "time_ratio": "float", "load_before": "float", "load_after": "float"},
                        key=("example",), label="an estimates table"),
    # results/benchmarks/face_phases.csv (bench/phases.py: a β_h request's time per phase)
    "phases": Schema({"what": "str", "element": "str?", "k": "int", "N": "int", "phase": "str", "cpu_s": "float",
                      "wall_s": "float", "cpu_percent": "float", "share": "float", "peak_added_mib": "float"},
                     key=("what", "element", "k", "N", "phase"), label="a phases table"),
    # Snakemake's `benchmark:` files (bench/dag.py), tab-separated
    "rule_benchmark": Schema({"s": "float"}, optional={"max_rss": "float?", "cpu_time": "float?"},
                             label="a Snakemake benchmark file", sep="\t"),
}
"""The declared tables (:func:`read_table`): one :class:`Schema` per kind."""


# ------------------------------------------------------------------ round-off columns
# What two results trees may differ in and still agree (workflow/scripts/compare_results.py):
# columns whose numbers are round-off-level by what they measure. Their digits follow the route
# that computed them (a body factorized in parity blocks, another H-Gram route) and the machine
# (OpenBLAS and MKL pick code paths by CPU), while every β_h, kernel and verdict stays the same.
# Every other column is compared as text, character by character.

_EPS = 2.220446049250313e-16


class RoundOff:
    """A round-off-level column: two values a, b agree when |a − b| <= ``atol`` + ``rtol`` ·
    max(|a|, |b|) + the row's own term (``per_row``: ``"sqrt_eta"`` or ``"cond"``, below).

    ``where`` (column, value): the rule holds on the rows where that column has that value
    (``"> 0"``: a positive number; ``"True"``/``"False"``: a flag) in both trees; elsewhere the
    column is compared as text. ``reason`` says what the column measures and why its digits are
    round-off; :meth:`describe` is the tolerance as the compare script prints it."""

    def __init__(self, reason: str, rtol: float = 0.0, atol: float = 0.0, where: tuple | None = None,
                 per_row: str | None = None):
        self.reason, self.rtol, self.atol, self.where, self.per_row = reason, rtol, atol, where, per_row

    def applies(self, row_a: dict, row_b: dict) -> bool:
        """Whether the rule holds on this pair of rows (``where`` true in both)."""
        if self.where is None:
            return True
        column, value = self.where
        return all(_holds(r.get(column, ""), value) for r in (row_a, row_b))

    def tolerance(self, a: float, b: float, row_a: dict, row_b: dict) -> float:
        """The allowed |a − b| on this pair of rows."""
        size = max(abs(a), abs(b))
        tol = self.atol + self.rtol * size
        if self.per_row == "sqrt_eta":
            tol += _sqrt_eta_term(size, row_a, row_b)
        elif self.per_row == "cond":
            tol += _EPS * size * size
        return tol

    def describe(self) -> str:
        parts = [f"{self.atol:g}" if self.atol else "", f"{self.rtol:g}·|x|" if self.rtol else "",
                 {"sqrt_eta": "min(sqrt(η), 10 η/|x|)", "cond": "ε·x²", None: ""}[self.per_row]]
        text = " + ".join(p for p in parts if p) or "0"
        return text + (f" where {self.where[0]} {self.where[1]}" if self.where else "")


def _holds(cell: str, value: str) -> bool:
    if value == "> 0":
        try:
            return float(cell) > 0
        except ValueError:
            return False
    return cell == value


def _sqrt_eta_term(size: float, row_a: dict, row_b: dict) -> float:
    """A square root of a pencil eigenvalue s = sqrt(λ) whose λ is known to η = n ε λ_max: η from the
    row itself, s²/gap_over_roundoff (gap = λ/η); s is then known to η/(2s) where s >> sqrt(η), to
    sqrt(η) where not (a factor 10 on the first: the Gram routes' own relative differences)."""
    etas = []
    for r in (row_a, row_b):
        try:
            s, gap = float(r["smallest_nonzero"]), float(r["gap_over_roundoff"])
        except (KeyError, ValueError):
            continue
        if gap > 0 and gap != float("inf"):
            etas.append(s * s / gap)
    if not etas:
        return 0.0
    eta = max(etas)
    return min(eta ** 0.5, 10 * eta / size) if size > 0 else eta ** 0.5


_GRAM_BOUND = RoundOff(
    "the H Gram's stated bound on the relative error of every pencil eigenvalue (la/richardson.py): "
    "the difference of two partial sums, whose own digits follow the route's round-off; it is checked "
    "against the Gram's rtol (1e-6), and one decimal of it is what it states", rtol=1e-4, atol=1e-12)
_COND = RoundOff(
    "a condition number κ from the extreme eigenvalues: the smallest carries an absolute error ~ ε λ_max, "
    "so κ a relative one ~ ε κ (beyond 1/ε: singular to working precision, any value)", rtol=1e-9, per_row="cond")
_PATCH = RoundOff(
    "a patch test's error where the row passes: round-off below the table's pass bound (1e-10 on the "
    "segment, 1e-8 on the face), which the row's passes flag certifies", atol=1e-8, where=("passes", "True"))


def _unresolved(norm: str) -> RoundOff:
    return RoundOff(f"β of the edge table where beta_{norm}_resolved is False: β² below the pencil's round-off "
                    "level (study/face/edge_dropping.py), its digits are noise", atol=float("inf"),
                    where=(f"beta_{norm}_resolved", "False"))


ROUNDOFF_COLUMNS = {
    "nmax_rel_error": _GRAM_BOUND,
    "h_rel_error": _GRAM_BOUND,                    # the edge table's name for it
    "gap_over_roundoff": RoundOff(
        "λ_{d+1}/η: the first pencil eigenvalue above the kernel in units of the pencil's round-off level "
        "η = n ε λ_max; an eigenvalue is known to about η, i.e. to about 1 in these units, and λ_max to "
        "its relative round-off; it is read in decades (kernel_margin_decades)", rtol=1e-8, atol=1.0),
    "smallest_nonzero": RoundOff(
        "where kernel_dim > 0: β above the kernel, the square root of a pencil eigenvalue known to "
        "η = smallest_nonzero²/gap_over_roundoff (a round-off value where gap_over_roundoff < 1); where "
        "kernel_dim = 0 it is β and compared as text", rtol=1e-10, where=("kernel_dim", "> 0"), per_row="sqrt_eta"),
    "beta_v1_zero": RoundOff(
        "β_h with v1 = 0 ((5.10)): 0 where the restricted pencil has a kernel, where the computed value "
        "is the square root of an eigenvalue's round-off (η <= 1e-14 here: up to 1e-7); elsewhere a β, "
        "to 1e-10 relative", rtol=1e-10, atol=1e-7),
    **{f"cond_{m}{s}": _COND for m in "DSG" for s in ("", "_kappa", "_unit")},
    **{c: _PATCH for c in ("lambda_max_rel_error", "lambda_end_rel_error", "lambda_middle_rel_error",
                            "u_max_rel_error")},
    "beta_H": _unresolved("H"), "beta_L2": _unresolved("L2"), "beta_L2_kappa": _unresolved("L2_kappa"),
}
"""Columns compared to a stated error instead of as text (workflow/scripts/compare_results.py), by
name: the same name is the same quantity in every table that has it."""
