"""The α sweep of the transformed dual bases on the face: β_h against α.

Popp, Gitterle, Gee, Wall (Int. J. Numer. Meth. Engng 83 (2010) 1428–1465) and 4C transform a
quadratic face element's basis, Ñ = T(α) N (:func:`~infsup_contact.discretization.face.spaces.dual_bases.transformation`),
so that the weights ∫Ñ_k are all positive and the dual basis ψ̃ = Ã Ñ exists; 4C fixes α = 1/5.
For QUAD8 the corner weight is ∫Ñ_corner = (8α − 1)/3 (reference area 4): the dual basis exists
for α > 1/8 only. This module measures, for each α, the smallest weight, cond₂(Ã) and β_h
(H^{1/2}_00(Γ)' norm, :func:`~infsup_contact.solvers.infsup.beta_rows_all`) of the transformed
dual space (∂Γ dofs dropped, constants kept, :class:`~infsup_contact.discretization.face.spaces.cellwise.CellwiseFaceSpace`)
with Q2 displacements (k = 2, hexahedra) on matching N × N meshes. An α with a weight ≤ 0 is
refused, as the registry's DUAL-Q8 is (the row says so; no β): ``accepted`` is the
construction's own decision (:func:`accepted_by_construction`), ``weights_positive`` and
``min_weight`` / ``min_weight_gauss`` the weights by two quadratures, so a table can show
whether the two agree (the ledger's ``face-alpha-accept`` claims, :mod:`.claims.membranes3d_studies`).

TRI6: the same sweep on the triangles of tetrahedral faces (P2 displacements,
:func:`~infsup_contact.discretization.face.spaces.tri6.tri6_space`). Its weights are ∫Ñ_vertex = α/3 and
∫Ñ_edge = (1 − 2α)/6 (fractions 2α/3 and (1 − 2α)/3 of the area 1/2): positive on all of (0, 1/2),
the plain dual (α = 0) is the only one refused. The mesh element of each reference element is the
model's element whose face cells have its shape (:func:`element_of`), not a name.

Run: ``python -m infsup_contact.study.face.alpha --N 4 8`` (CSV on stdout);
``--element TRI6 --N 4 6`` for the triangles; ``--element QUAD8 --bodies hex20`` for the QUAD8 faces of
serendipity HEX20 bodies (:mod:`infsup_contact.models.hex20`) instead of Q2 hexahedra's QUAD9 traces.
"""
from __future__ import annotations

import sys

import numpy as np

from ...discretization.face.spaces.cellwise import cellwise_builder
from ...discretization.face.spaces.dual_bases import alpha_sweep, transformation
from ...discretization.face.spaces.reference_elements import reference_element
from ...discretization.face.spaces.tri6 import triangle_builder
from ...discretization.face.partitions.tensor_grid import TensorPartition
from ...discretization.spaces.spec import SpaceSpec
from ...errors import InputError

ALPHAS = (0.05, 0.1, 0.125, 0.15, 0.2, 0.25, 0.3, 1.0 / 3.0, 0.4, 0.45)
"""The sweep (0.125: the QUAD8 corner weight is exactly 0; 0.2: 4C's)."""
ELEMENTS = ("QUAD8", "QUAD9")
TRI_ALPHAS = (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 1.0 / 3.0, 0.4, 0.45)
"""The TRI6 sweep (no α in (0, 1/2) makes a TRI6 weight vanish)."""
SWEEP_ELEMENTS = ("QUAD8", "QUAD9", "TRI6")
FACE_CELL = {"quad": "quad", "tri": "trig"}
"""Reference cell of an element (:attr:`~.face_elements.ReferenceElement.cell`) → face cell shape
(:data:`~infsup_contact.discretization.face.shapes.square.CELL_SHAPES`)."""


def transformed_dual_spec(element: str, alpha: float) -> SpaceSpec:
    """An unregistered entry: the transformed dual basis of ``element`` with this α (k ≥ 2), on
    the face cells of its shape."""
    cell = FACE_CELL[reference_element(element).cell]
    build = (cellwise_builder(element, "transformed_dual", True, alpha) if cell == "quad"
             else triangle_builder("transformed_dual", alpha))
    cells = (cell, "quad8") if element == "QUAD8" else (cell,)  # QUAD8: also the HEX20 bodies' QUAD8 faces
    return SpaceSpec(f"TDUAL-{element}-a{alpha:.4g}", "Popp et al. 2010", f"transformed dual {element}, α = {alpha:.4g}",
                     None, lambda k: 2, min_k=2, gamma_dims=(2,), face_build=build, face_cells=cells)


def element_of(model: str, reference: str) -> str:
    """The mesh element (``--element``) of ``model`` whose face cells have the shape of the
    reference element ``reference`` (QUAD8 → hexahedra, TRI6 → tetrahedra), asked of the faces
    (:func:`~.claims.membranes3d.element_interfaces`)."""
    from ...models import MODELS
    from ..claims.membranes3d import element_interfaces

    options = dict(MODELS[model].mesh_options).get("element", ())
    want = FACE_CELL[reference_element(reference).cell]
    found = [e for e, g in element_interfaces(model, options).items() if g.cell == want]
    if not found:
        raise InputError("element", f"a reference element whose cells {model} has on its face", got=reference)
    return found[0]


def gauss_min_weight(element: str, alpha: float) -> float:
    """Second route to the smallest transformed weight min_k ∫Ñ_k / area: the shapes Ñ = T(α) N
    summed against a Gauss–Legendre product rule (5 × 5 points) of the reference cell — the
    square [−1, 1]², or the unit triangle collapsed from the unit square (Duffy: x = u,
    y = (1 − u) v, Jacobian 1 − u) — exact for the (bi)quadratic N, not the moments of
    :func:`~infsup_contact.discretization.face.spaces.dual_bases.weights`."""
    el = reference_element(element)
    t, w = np.polynomial.legendre.leggauss(5)
    if el.cell == "quad":
        pts = np.stack(np.meshgrid(t, t, indexing="ij"), axis=-1).reshape(-1, 2)
        ww = np.outer(w, w).ravel()
    else:
        u, wu = (t + 1.0) / 2.0, w / 2.0
        U, V = np.meshgrid(u, u, indexing="ij")
        pts = np.column_stack([U.ravel(), ((1.0 - U) * V).ravel()])
        ww = (np.outer(wu, wu) * (1.0 - U)).ravel()
    d = (el.shapes(pts) @ transformation(element, alpha).T).T @ ww
    return float(d.min() / el.area)


def accepted_by_construction(element: str, alpha: float, n: int, k: int = 2) -> bool:
    """Whether the transformed dual space of ``element`` with this α is built on the uniform
    n × n partition (its registry-style builder, :func:`transformed_dual_spec`), i.e. not refused
    with an :class:`InputError`: the construction's own decision, next to the weights."""
    x = np.linspace(0.0, 1.0, n + 1)
    try:
        transformed_dual_spec(element, alpha).face_build(k, TensorPartition(x, x))
    except InputError:
        return False
    return True


def face_models() -> list:
    """Names of the registered models whose contact interface is the face (dimension 3)."""
    from ...models import MODELS

    return [name for name, m in MODELS.items() if m.dim == 3]


def sweep(ns=(4, 8), alphas=ALPHAS, elements=ELEMENTS, k: int = 2, norms=("H",), cell: str | None = None,
          model: str | None = None) -> list[dict]:
    """One row per (element, α, N, norm): α, min weight (fraction of the cell area; ``min_weight_gauss``
    by a second quadrature), cond₂(Ã), ``weights_positive``, ``accepted`` (the construction
    built the space, :func:`accepted_by_construction`; ``refused`` its negation) and, where
    accepted, β_h, kernel_dim, dim M, dim W, n_max (``model``: a registered 3D model, default
    the first, :func:`face_models`; ``cell`` its --element, default the one whose face cells
    fit each element, :func:`element_of`)."""
    from ...models import make_model
    from ...solvers.request import MeshOptions
    from ...solvers.side_cache import SideCache

    model = face_models()[0] if model is None else model
    from ...solvers.infsup import beta_rows_all

    cache, rows = SideCache(), []
    for n in ns:
        for element in elements:
            for info in alpha_sweep(element, alphas):
                accepted = accepted_by_construction(element, info["alpha"], n, k)
                base = dict(element=element, alpha=info["alpha"], N=n, min_weight=info["min_fraction"],
                            min_weight_gauss=gauss_min_weight(element, info["alpha"]), cond_A=info["cond"],
                            weights_positive=info["positive"], accepted=accepted, refused=not accepted)
                if not accepted:
                    rows += [dict(base, norm=nm, beta=np.nan, kernel_dim=-1) for nm in norms]
                    continue
                mesh_element = cell or element_of(model, element)
                for r in beta_rows_all("structured", k, n, n, [transformed_dual_spec(element, info["alpha"])],
                                       norms=norms, model=make_model(model), side_cache=cache,
                                       mesh=MeshOptions(element=mesh_element)):
                    rows.append(dict(base, norm=r["norm"], beta=r["beta"], kernel_dim=r["kernel_dim"],
                                     dim_M=r["dim_M"], dim_W=r["dim_W"], n_max=r["n_max"]))
    return rows


def main(argv=None) -> int:
    """``python -m infsup_contact.study.face.alpha --N 4``: the sweep as CSV on stdout; bad input
    is one line on stderr naming the flag, exit 2, before any row."""
    import pandas as pd

    from ...command_line import OneLineParser, run_study

    p = OneLineParser(prog="python -m infsup_contact.study.face.alpha", description=__doc__.split("\n")[0])
    p.add_argument("--N", type=int, nargs="+", default=[4, 8], help="cells per direction (matching meshes)")
    p.add_argument("--norm", default="H", choices=["H", "L2", "all"])
    p.add_argument("--model", default=None, choices=face_models(), help="a 3D model (default: the first)")
    p.add_argument("--element", nargs="+", default=list(ELEMENTS), choices=SWEEP_ELEMENTS,
                   help="reference elements (QUAD8/QUAD9: hexahedra, TRI6: tetrahedra)")
    p.add_argument("--bodies", default=None,
                   help="the model's element of the bodies (its --element: hex20 puts QUAD8 on serendipity "
                        "bodies' QUAD8 faces; default: the one whose faces carry each reference element)")

    def check(args):
        from ...solvers.request import check_mesh_option

        if any(n < 1 for n in args.N):
            raise InputError("N", "integers >= 1", got=args.N)
        args.model = face_models()[0] if args.model is None else args.model
        for element in args.element:  # a reference element the model's faces do not carry
            element_of(args.model, element)
        if args.bodies is not None:
            from ...models import MODELS

            check_mesh_option(MODELS[args.model], "element", args.bodies)
            if args.bodies == "hex20" and args.element != ["QUAD8"]:
                raise InputError("element", "QUAD8 (the HEX20 bodies' faces)", got=" ".join(args.element))

    def run(args):
        norms = ("H", "L2") if args.norm == "all" else (args.norm,)
        quad = any(FACE_CELL[reference_element(e).cell] == "quad" for e in args.element)
        rows = sweep(tuple(args.N), ALPHAS if quad else TRI_ALPHAS, tuple(args.element), norms=norms, model=args.model,
                     cell=args.bodies)
        pd.DataFrame(rows).to_csv(sys.stdout, index=False, float_format="%.6g")

    return run_study(p, argv, check, run)


if __name__ == "__main__":
    raise SystemExit(main())
