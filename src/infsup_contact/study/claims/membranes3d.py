"""Ledger claims of the 3D contact face Γ = (0,1)²×{1} (models/membranes3d.py).

Same criteria as the paper's ledger (:mod:`infsup_contact.criteria.claims`: the slope interval of
log β_h vs log h inside s0 ± τ, min β_h > floor, exact kernel counts, INCONCLUSIVE where a
kernel decision is ``close``). Each claim's ``predicted`` column comes from the registry's
properties (``stable``, the 1D ``dimension`` count) and the config's meshes alone — never from
a case id and never from the table (:func:`face_predictions`). The reasoning:

* **Kernel = dimension count on matching meshes** (``face-kernel-<tag>-k<k>-<element>``).
  A face space is the tensor product of the registry's 1D space, dim M = d(k, N)² with d the
  1D count (linear in N: d = aN + b), and the trace space W of Q_k / P_k vanishing on ∂Γ has
  dim (Nk − 1)² (:meth:`Square.trace_dimension`). On matching meshes W1 = W2 = W, so the
  kernel of B A⁻¹ Bᵀ is at least dim M − dim W = (a² − k²)N² + 2(ab + k)N + b² − 1, and the
  prediction is that it is exactly that (max with 0), as in 1D (Rem 5.2: 2, Rem 5.4: 1). For
  M^1_k (Rem 5.2) this is (Nk + 1)² − (Nk − 1)² = 4Nk: the kernel *grows* with N on the face,
  where the segment's stays at 2. PASS predicted for every case.
* **Bounded** (``face-<tag>-k<k>-<element>``, H^{-1/2}_00 norm): spaces marked stable in the
  registry (their 1D proof) are predicted bounded on the face: PASS.
* **The checkerboard** (:func:`checkerboard`): on triangles, P_0 multipliers against P_2 traces
  on the same triangles have a kernel mode the dimension count misses (T4 at k = 2 on
  tetrahedra): the kernel, bounded and Remark 3.1 claims of such a space are predicted FAIL.
* **Remark 3.1 on the face** (``face-Rem3.1-<tag>-k<k>-<element>``): in the L²(Γ) norm β_h of
  a stable space decays like h^{1/2}: the inverse estimate ‖μ‖_{-1/2} ≥ c h^{1/2}‖μ‖_0 on
  piecewise polynomials and a most-oscillating μ with ‖μ‖_{-1/2} ~ h^{1/2}‖μ‖_0 hold on a
  quasi-uniform grid in any dimension: PASS predicted.
* **Kernel = dimension count on non-matching meshes** (``face-nonmatching-kernel-…``): the
  count max(dim M − dim(W1 + W2), 0) is only a lower bound. On hexahedral faces the traces
  are tensor products, B_i = A_i^x ⊗ A_i^y, and ker(A ⊗ A') = ker A ⊗ M^y + M^x ⊗ ker A', so
  ker B1 ∩ ker B2 ⊇ K1^x ⊗ K2^y + K2^x ⊗ K1^y with K_i^x = ker A_i^x of dimension >= a_i =
  d(k, N2) − (N_i k − 1) (one side's 1D count); its dimension is >= 2 a1 a2 − min(a1, a2)²
  (:func:`tensor_kernel_bound`). Where that bound exceeds the planar count on some pair of
  the config, the claim is predicted FAIL (the dimension argument undercounts). A stable
  space has no kernel (its count is 0): PASS. Otherwise both counts are lower bounds and
  nothing predicts equality (``finding``), on triangular faces (tetrahedra: no tensor traces)
  as on rectangles. On the Kuhn faces of the structured tetrahedra the sharper lower bound is
  :func:`triangle_kernel_bound` (the count per isotypic component of the face's symmetries and
  the modes of the cells along ∂Γ; docs/tet_kernel.md): where it exceeds the planar count on a
  pair of the config, the claim is predicted FAIL, as the tensor bound's on rectangles.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ...discretization.spaces.registry import SPACES
from ...errors import InputError
from ...discretization.face.kernel_bounds import symmetric_kernel_bound
from ...discretization.face.shapes.square import SQUARE, SQUARE_TRIG, Square
from ...discretization.face.partitions.tensor_grid import TensorPartition
from ...criteria.claims import FAIL, FINDING, INCONCLUSIVE, PASS, bounded_claim, close_decisions, close_text, finest, kernel_claim, \
    row, slope_verdict

REF = "beyond the paper (the 3D contact face: docs/models.md, 3D bodies with a contact face)"


def face_dimension(spec, k: int, n: int, gamma=SQUARE) -> int:
    """dim M_h of ``spec`` built by the face ``gamma`` on its uniform n × n partition (the
    construction itself: tensor products on rectangles, P_s on triangles, element spaces)."""
    return int(gamma.space(spec, k, _uniform(n)).dim)


def matching_kernel(spec, k: int, n: int, gamma=SQUARE) -> int:
    """The dimension argument on matching n × n meshes: max(dim M − dim W, 0)."""
    return max(face_dimension(spec, k, n, gamma) - gamma.trace_dimension(k, n), 0)


def kernel_formula(spec, k: int, gamma=SQUARE) -> str:
    """dim M − dim W as a polynomial in N: e.g. ``4N`` for M^1_1 (Rem 5.2, k = 1). Both counts
    are quadratic in N on every face space here; the quadratic through N = 1, 2, 3 is checked
    against the counts at N = 4, 5 (an AssertionError otherwise: no formula is printed that
    the counts do not follow)."""
    count = [face_dimension(spec, k, n, gamma) - gamma.trace_dimension(k, n) for n in range(1, 6)]
    c2 = (count[2] - 2 * count[1] + count[0]) // 2
    c1 = count[1] - count[0] - 3 * c2
    c0 = count[0] - c1 - c2
    for n in range(1, 6):
        assert c2 * n * n + c1 * n + c0 == count[n - 1]
    terms = [(c2, "N²"), (c1, "N"), (c0, "")]
    text = ""
    for c, x in terms:
        if c == 0:
            continue
        mag = "" if abs(c) == 1 and x else str(abs(c))
        text += (("−" if not text else " − ") if c < 0 else (" + " if text else "")) + mag + x
    return text or "0"


def _uniform(n: int) -> TensorPartition:
    x = np.linspace(0.0, 1.0, n + 1)
    return TensorPartition(x, x)


def checkerboard(spec, k: int, gamma=SQUARE) -> bool:
    """Whether ``gamma`` proves the checkerboard mode of ``spec`` at degree k on matching meshes
    (:meth:`~infsup_contact.discretization.face.shapes.square.Square.checkerboard_modes`: P_0 multipliers
    against P_2 traces on the same triangles; independent of N)."""
    modes = getattr(gamma, "checkerboard_modes", None)
    if modes is None or not gamma.builds(spec):
        return False
    try:
        space = gamma.space(spec, k, _uniform(4))
    except InputError:  # a space the face refuses to build (QUAD8's dual) proves nothing
        return False
    return bool(modes(space, k, [_uniform(4)] * 2))


def planar_kernel(spec, k: int, n1: int, n2: int, gamma=SQUARE) -> int:
    """The dimension argument on n1 × n1 / n2 × n2 meshes, G_h = the trace of Ω2:
    max(dim M − dim(W1 + W2), 0) (:meth:`Square.trace_sum_dimension`)."""
    return max(face_dimension(spec, k, n2, gamma) - gamma.trace_sum_dimension(k, _uniform(n1), _uniform(n2)), 0)


def tensor_kernel_bound(spec, k: int, n1: int, n2: int) -> int:
    """Lower bound of the kernel on tensor (hexahedral) faces: 2 a1 a2 − min(a1, a2)² with
    a_i = max(d(k, n2) − (n_i k − 1), 0) (module docstring; monotone in a1, a2, so a bound
    from the 1D lower bounds a_i is a bound)."""
    d = spec.dimension(k, n2)
    a1, a2 = (max(d - (n * k - 1), 0) for n in (n1, n2))
    return 2 * a1 * a2 - min(a1, a2) ** 2


def triangle_kernel_bound(spec, k: int, n1: int, n2: int, gamma=SQUARE_TRIG) -> int:
    """Lower bound of the kernel on Kuhn-triangulated (structured tetrahedral) faces, G_h = the
    trace of Ω2: Σ_c max(dim M_c − dim(W1 + W2)_c, boundary-layer modes in c, 0) over the four
    isotypic components c of the square's symmetries {id, T, R, TR} that preserve the diagonals
    (:func:`~infsup_contact.discretization.face.kernel_bounds.symmetric_kernel_bound`;
    docs/tet_kernel.md). It is >= :func:`planar_kernel` (the components' counts sum to the
    global one) and exceeds it where the components' counts differ in sign or the modes of the
    cells along ∂Γ outnumber a component's count: R5.2 at k = 1, 6:7 → 5 (count 3), 7:8 → 4
    (count 0). It is the kernel on R5.2, T3 and DUAL-ALL (k = 1, 2, N <= 10), a lower bound
    on R5.4. A space whose basis the group does not permute gets the planar count."""
    if not kuhn(gamma):
        raise InputError("gamma", "a face of Kuhn triangles (Square(cell='trig'), the structured tetrahedra's)",
                         got=getattr(gamma, "cell", type(gamma).__name__))
    planar = planar_kernel(spec, k, n1, n2, gamma)
    comps = symmetric_kernel_bound(gamma.space(spec, k, _uniform(n2)), k, n1, n2)
    return planar if comps is None else max(planar, sum(comps.values()))


def element_interfaces(model, elements) -> dict:
    """The face interface of each element of ``model`` (rectangles, triangles, QUAD8 rectangles),
    asked of a 1 × 1 × 1 mesh of each (the mesh builder names it: ``Body.interface``, the Γ its
    sides trace): a property, not an element name."""
    from ...models import make_model

    m = make_model(model) if isinstance(model, str) else model
    return {e: m.mesh("structured", 1, 1, element=e).interface for e in elements}


def kuhn(gamma) -> bool:
    """Whether the face is the Kuhn triangulation of a tensor grid (the structured tetrahedra's)."""
    return isinstance(gamma, Square) and getattr(gamma, "cell", None) == "trig"


def is_tensor(gamma) -> bool:
    """Whether the face's traces are tensor grids of rectangles (``cell`` ``quad``)."""
    return getattr(gamma, "cell", None) == "quad"


def face_predictions(spec, k: int, nonmatching, tensor: bool, gamma=SQUARE) -> dict:
    """The predicted verdicts of one (space, k, element) from registry and config alone; the
    tensor argument applies to the tensor-product spaces (those without an element build)."""
    out = {"kernel": PASS}
    if spec.stable:
        out["bounded"] = out["l2"] = PASS
    if checkerboard(spec, k, gamma):  # a proven mode the dimension count misses: β_h = 0
        out["kernel"] = out["bounded"] = out["l2"] = FAIL
    if spec.stable:  # no kernel on any pair (the planar count is 0): as the bounded claim
        out["nonmatching"] = PASS
    elif tensor and getattr(spec, "face_build", None) is None and any(
            tensor_kernel_bound(spec, k, n1, n2) > planar_kernel(spec, k, n1, n2, gamma) for n1, n2 in nonmatching):
        out["nonmatching"] = FAIL  # the tensor kernel exceeds the count on some pair
    elif kuhn(gamma) and any(triangle_kernel_bound(spec, k, n1, n2, gamma) > planar_kernel(spec, k, n1, n2, gamma)
                             for n1, n2 in nonmatching):
        out["nonmatching"] = FAIL  # the Kuhn face's symmetric and boundary-layer modes exceed it
    else:
        out["nonmatching"] = FINDING  # a lower bound only: no prediction of equality
    return out


def _nonmatching_check(rows: pd.DataFrame, spec, k: int, gamma):
    planar = np.array([planar_kernel(spec, k, int(a), int(b), gamma) for a, b in zip(rows.N1, rows.N2)])
    dims = rows.kernel_dim.to_numpy(int)
    pairs = ", ".join(f"{a}:{b} {d} vs {p}" for a, b, d, p in zip(rows.N1, rows.N2, dims, planar))
    text = f"kernel vs dimension count per pair: {pairs}"
    close = close_decisions(rows)
    if len(close):
        return INCONCLUSIVE, f"{text}; {close_text(close)}"
    ok = bool(np.all(dims == planar) and np.all(rows.structural_kernel_dim.to_numpy(int) == planar))
    return (PASS if ok else FAIL), text


def face_claims(beta: pd.DataFrame, cfg: dict, interfaces: dict) -> pd.DataFrame:
    """The face claims of a face β table (``results/tables/membranes3d_beta.csv``).

    Parameters
    ----------
    beta
        Rows of ``membranes3d`` (columns of the β table plus ``element``).
    cfg
        The ``claims`` config (slope_tolerance, beta_floor, confidence, fit_window).
    interfaces
        The face interface of each element (:func:`element_interfaces`).
    """
    tol, floor, conf, win = cfg["slope_tolerance"], cfg["beta_floor"], cfg["confidence"], cfg["fit_window"]
    out = []
    for (element, k, case), rc in beta.groupby(["element", "k", "case"], sort=False):
        spec = SPACES.get(case)
        if spec is None or spec.dimension is None:
            continue
        k = int(k)
        match, nonm = rc[rc.N1 == rc.N2], rc[(rc.N1 != rc.N2) & (rc.norm == "H")]
        pairs = sorted({(int(a), int(b)) for a, b in zip(nonm.N1, nonm.N2)})
        gamma = interfaces[element]
        pred = face_predictions(spec, k, pairs, is_tensor(gamma), gamma)
        where = f"{case}, k={k}, {element}"
        if len(match):
            dims = np.array([matching_kernel(spec, k, int(n), gamma) for n in match.N2])
            out.append(row(f"face-kernel-{spec.tag}-k{k}-{element}", REF,
                           f"face, {where}, matching meshes: dim ker = max(dim M − dim W, 0) = max({kernel_formula(spec, k, gamma)}, 0)",
                           kernel_claim(match, dims), predicted=pred["kernel"]))
        h = match[match.norm == "H"]
        if spec.stable and len(h):
            out.append(row(f"face-{spec.tag}-k{k}-{element}", REF,
                           f"face, {where}: β_h bounded away from 0 (H^-1/2_00(Γ) norm)",
                           bounded_claim(finest(h, win), tol, floor, conf), predicted=pred["bounded"]))
        l2 = finest(match[match.norm == "L2"], win)
        if spec.stable and len(l2) >= 3:
            if np.any(l2.beta.to_numpy(float) <= 0.0):  # a kernel: no decay to fit
                v, text = FAIL, f"β_h = 0 (kernel_dim {', '.join(map(str, l2.kernel_dim))}) at N = {', '.join(map(str, l2.N2))}"
            else:
                v, text = slope_verdict(1 / l2.N2.to_numpy(float), l2.beta.to_numpy(float), 0.5, tol, conf)
            out.append(row(f"face-Rem3.1-{spec.tag}-k{k}-{element}", REF,
                           f"face, {where}: in the L²(Γ) norm β_h decays like h^(1/2)", (v, text),
                           predicted=pred["l2"]))
        if len(nonm):
            out.append(row(f"face-nonmatching-kernel-{spec.tag}-k{k}-{element}", REF,
                           f"face, {where}, non-matching pairs, G_h = trace of Ω2: dim ker = max(dim M − dim(W1 + W2), 0)",
                           _nonmatching_check(nonm.sort_values("N2"), spec, k, gamma), predicted=pred["nonmatching"]))
    return pd.DataFrame(out, columns=["claim_id", "paper_ref", "statement", "evidence", "verdict", "predicted"])
