"""The registry entries of the quadratic face elements (issue 28): spaces of QUAD8/QUAD9 cells
(hexahedral faces, :mod:`.face.spaces.cellwise`) and TRI6 cells (tetrahedral faces, :mod:`.face.spaces.tri6`) on
G_h, defined on the face only (the segment refuses them in one line). :mod:`.spaces.registry` calls
:func:`register_face_cases` with its own ``register``, ``SpaceSpec`` and colours, after the
paper's five and the duals (this module imports nothing of the registry: no import circle).
"""
from __future__ import annotations

from ...errors import InputError
from ..face.spaces.cellwise import cellwise_builder
from ..face.spaces.reference_elements import reference_element
from ..face.spaces.tri6 import triangle_builder


def _face_only(case: str):
    """The 1D ``build`` of a face-only entry: refuses the segment in one line."""
    def build(k, x):
        raise InputError("case", f"a space of the segment Γ: {case} is defined on the face of a 3D model "
                         f"only (e.g. --model membranes3d)", got=case)
    return build


def _face_spec(SpaceSpec, id, ref, definition, element, basis, dimension, color, marker, vanish=True,
               expected="unknown", refuse_with=""):
    """A space of quadratic face elements on G_h (k ≥ 2), paired with the face cells of the element's
    reference cell: QUAD8/QUAD9 on rectangles (hexahedra, :mod:`.face.spaces.cellwise`), TRI6 on triangles
    (tetrahedra, :mod:`.face.spaces.tri6`, always without the ∂Γ nodes)."""
    quad = reference_element(element).cell == "quad"
    build = (cellwise_builder(element, basis, vanish, refuse_with=refuse_with) if quad
             else triangle_builder(basis, refuse_with=refuse_with))
    return SpaceSpec(
        id, ref, definition, _face_only(id), lambda k: 2, min_k=2, expected=expected,
        dimension=dimension, color=color, marker=marker, nodal_basis=basis in ("standard", "pwlin"),
        claim_tag=id, gamma_dims=(2,), face_build=build, face_cells=("quad",) if quad else ("trig",))


def _interior(n):       # nodes of the QUAD9 (= P2 triangle) lattice inside (0, 1)² on an n × n grid
    return (2 * n - 1) ** 2


def register_face_cases(register, SpaceSpec, colors) -> None:
    """Register the face-element entries with the registry's ``register`` (order kept)."""
    for spec in [
        _face_spec(SpaceSpec, "DUAL-Q9", "Wohlmuth 2000; Popp, Gitterle, Gee, Wall 2010", "dual basis of QUAD9 on ∂Γ-free nodes, "
                   "constants kept", "QUAD9", "dual", lambda k, n: _interior(n), colors["black"], "H"),
        _face_spec(SpaceSpec, "DUAL-Q9-ALL", "Wohlmuth 2000 (all nodes)", "dual basis of QUAD9 on all nodes", "QUAD9", "dual",
                   lambda k, n: (2 * n + 1) ** 2, colors["sky_blue"], "d", vanish=False, expected="unstable"),
        _face_spec(SpaceSpec, "DUAL-Q8", "Wohlmuth 2000 (QUAD8)", "dual basis of QUAD8 (refused: corner weights ∫N = −1/3 < 0)",
                   "QUAD8", "dual", lambda k, n: _interior(n) - n * n, colors["vermillion"], "<",
                   refuse_with="use case TDUAL-Q8 (the transformed dual basis, Popp et al. 2012, α = 1/5)"),
        _face_spec(SpaceSpec, "TDUAL-Q8", "Popp, Gitterle, Gee, Wall 2010; 4C", "transformed dual basis of QUAD8, α = 1/5",
                   "QUAD8", "transformed_dual", lambda k, n: _interior(n) - n * n, colors["orange"], ">"),
        _face_spec(SpaceSpec, "TDUAL-Q9", "Popp, Gitterle, Gee, Wall 2010; 4C", "transformed dual basis of QUAD9, α = 1/5",
                   "QUAD9", "transformed_dual", lambda k, n: _interior(n), colors["bluish_green"], "8"),
        _face_spec(SpaceSpec, "PWLIN-Q9", "4C LM_QUAD pwlin (Popp 2009)", "piecewise bilinear on the 4 sub-quads of QUAD9",
                   "QUAD9", "pwlin", lambda k, n: _interior(n), colors["reddish_purple"], "p"),
        # TRI6 (P2 traces: k = 2 tetrahedra; :mod:`.face.spaces.tri6`): dim M_h = (2N − 1)², the interior P2 nodes
        _face_spec(SpaceSpec, "DUAL-T6", "Wohlmuth 2000 (TRI6)", "dual basis of TRI6 (refused: vertex weights ∫N = 0)", "TRI6", "dual",
                   lambda k, n: _interior(n), colors["vermillion"], "h",
                   refuse_with="use case TDUAL-T6 (the transformed dual basis, Popp et al. 2012, α = 1/5)"),
        _face_spec(SpaceSpec, "TDUAL-T6", "Popp, Wohlmuth, Gee, Wall 2012; 4C", "transformed dual basis of TRI6, α = 1/5, on "
                   "∂Γ-free nodes, constants kept (= DUAL at k = 2 on tetrahedral faces)", "TRI6", "transformed_dual",
                   lambda k, n: _interior(n), colors["bluish_green"], "d"),
        _face_spec(SpaceSpec, "PWLIN-T6", "4C LM_QUAD pwlin (Popp 2009)", "piecewise linear on the 4 sub-triangles of TRI6, "
                   "vanishing on ∂Γ", "TRI6", "pwlin", lambda k, n: _interior(n), colors["reddish_purple"], "H"),
    ]:
        register(spec)
