"""The registry entries of the quadratic face elements: spaces of QUAD8/QUAD9 cells (hexahedral
faces, :mod:`..face.spaces.cellwise`) and TRI6 cells (tetrahedral faces, :mod:`..face.spaces.tri6`)
on G_h. They live on the face only (``gamma_dims=(2,)``, no segment ``build``): the registry
lists them for a face and refuses them on the segment in one line (``registry.case_space``).
"""
from __future__ import annotations

from ..face.spaces.cellwise import DiscontinuousP1Space, cellwise_builder
from ..face.spaces.reference_elements import reference_element
from ..face.spaces.tri6 import triangle_builder
from ..face.spaces.tensor import FaceSpace
from ..segment.dual import dual_space
from ..segment.multipliers import make_space
from .spec import SpaceSpec


def _face_spec(id, ref, definition, element, basis, dimension, vanish=True, expected="unknown", refuse_with="",
               cells=None):
    """A space of quadratic face elements on G_h (k ≥ 2), paired with the face cells of the element's
    reference cell: QUAD8/QUAD9 on rectangles (hexahedra), TRI6 on triangles (tetrahedra, always
    without the ∂Γ nodes); ``cells`` overrides the pairing (``quad8``: the QUAD8 traces of HEX20 bodies)."""
    quad = reference_element(element).cell == "quad"
    build = (cellwise_builder(element, basis, vanish, refuse_with=refuse_with) if quad
             else triangle_builder(basis, refuse_with=refuse_with))
    return SpaceSpec(
        id, ref, definition, None, lambda k: 2, min_k=2, expected=expected,
        dimension=dimension, nodal_basis=basis in ("standard", "pwlin"),
        claim_tag=id, gamma_dims=(2,), face_build=build,
        face_cells=cells or (("quad",) if quad else ("trig",)))


def _interior(n):       # nodes of the QUAD9 (= P2 triangle) lattice inside (0, 1)² on an n × n grid
    return (2 * n - 1) ** 2


def _quad8_nodes(n):    # QUAD8 nodes (corners and edge midpoints) on an n × n grid, ∂Γ included
    return (n + 1) ** 2 + 2 * n * (n + 1)


def _interior_q1(k, partition):  # continuous Q1 vanishing on ∂Γ: the tensor product of the 1D hats
    return FaceSpace(*(make_space(g, 1, True, True) for g in (partition.xs, partition.ys)), partition)


def _dual_q1(vanish: bool):
    """The tensor product of the 1D dual bases of continuous P1 (:func:`~..segment.dual.dual_space`, k = 1) on
    the vertices of G_h: ∫ψ_j φ_k = δ_jk ∫φ_k against the Q1 hats; ``vanish``: the ∂Γ vertices dropped, the
    end intervals' dual functions constant (Σ ψ_j = 1 kept), as DUAL does."""
    def build(k, partition):
        return FaceSpace(*(dual_space(g, 1, vanish) for g in (partition.xs, partition.ys)), partition)
    return build


def _linear_spec(id, ref, definition, build, dimension, expected, nodal=True, pair=(None, None)):
    """A space of degree 1 on the vertices of G_h against QUAD8 traces (HEX20 bodies, k = 2 only);
    ``pair``: (trial id, test id) of a Petrov–Galerkin pair (its ``build`` the trial space's)."""
    return SpaceSpec(id, ref, definition, None, lambda k: 1, min_k=2, expected=expected, dimension=dimension,
                     nodal_basis=nodal, claim_tag=id, gamma_dims=(2,), face_build=build, face_cells=("quad8",),
                     trial_space=pair[0], test_space=pair[1])


_TDUAL_Q8 = "use case TDUAL-Q8 (the transformed dual basis, Popp et al. 2012, α = 1/5)"
_TDUAL_T6 = "use case TDUAL-T6 (the transformed dual basis, Popp et al. 2012, α = 1/5)"

FACE_SPACES = (
    _face_spec("DUAL-Q9", "Wohlmuth 2000; Popp, Gitterle, Gee, Wall 2010", "dual basis of QUAD9 on ∂Γ-free nodes, "
               "constants kept", "QUAD9", "dual", lambda k, n: _interior(n)),
    _face_spec("DUAL-Q9-ALL", "Wohlmuth 2000 (all nodes)", "dual basis of QUAD9 on all nodes", "QUAD9", "dual",
               lambda k, n: (2 * n + 1) ** 2, vanish=False, expected="unstable"),
    _face_spec("DUAL-Q8", "Wohlmuth 2000 (QUAD8)", "dual basis of QUAD8 (refused: corner weights ∫N = −1/3 < 0)",
               "QUAD8", "dual", lambda k, n: _interior(n) - n * n, refuse_with=_TDUAL_Q8, cells=("quad", "quad8")),
    _face_spec("TDUAL-Q8", "Popp, Gitterle, Gee, Wall 2010; 4C", "transformed dual basis of QUAD8, α = 1/5",
               "QUAD8", "transformed_dual", lambda k, n: _interior(n) - n * n, cells=("quad", "quad8")),
    _face_spec("TDUAL-Q9", "Popp, Gitterle, Gee, Wall 2010; 4C", "transformed dual basis of QUAD9, α = 1/5",
               "QUAD9", "transformed_dual", lambda k, n: _interior(n)),
    _face_spec("PWLIN-Q9", "4C LM_QUAD pwlin (Popp 2009)", "piecewise bilinear on the 4 sub-quads of QUAD9",
               "QUAD9", "pwlin", lambda k, n: _interior(n)),
    # TRI6 (P2 traces: k = 2 tetrahedra): dim M_h = (2N − 1)², the interior P2 nodes
    _face_spec("DUAL-T6", "Wohlmuth 2000 (TRI6)", "dual basis of TRI6 (refused: vertex weights ∫N = 0)", "TRI6", "dual",
               lambda k, n: _interior(n), refuse_with=_TDUAL_T6),
    _face_spec("TDUAL-T6", "Popp, Wohlmuth, Gee, Wall 2012; 4C", "transformed dual basis of TRI6, α = 1/5, on "
               "∂Γ-free nodes, constants kept (= DUAL at k = 2 on tetrahedral faces)", "TRI6", "transformed_dual",
               lambda k, n: _interior(n)),
    _face_spec("PWLIN-T6", "4C LM_QUAD pwlin (Popp 2009)", "piecewise linear on the 4 sub-triangles of TRI6, "
               "vanishing on ∂Γ", "TRI6", "pwlin", lambda k, n: _interior(n)),
    # QUAD8 traces (serendipity HEX20 bodies, k = 2): dim W_h = (2N − 1)² − N², the interior QUAD8 nodes
    _face_spec("Q8", "standard mortar on QUAD8 faces (MOOSE; CalculiX MORTAR)", "continuous QUAD8 on ∂Γ-free nodes",
               "QUAD8", "standard", lambda k, n: _interior(n) - n * n, expected="stable", cells=("quad8",)),
    _face_spec("Q8-ALL", "standard mortar on QUAD8 faces, all nodes", "continuous QUAD8 on all nodes", "QUAD8",
               "standard", lambda k, n: _quad8_nodes(n), vanish=False, expected="unstable", cells=("quad8",)),
    # the linear multiplier on the vertices of G_h: MOOSE's lm_space = LINEAR is T5 at k = 2 (continuous Q1,
    # ∂Γ included); this one drops the ∂Γ vertices, as T3 / Q8 do
    _linear_spec("LIN0-Q8", "linear mortar on QUAD8 faces, ∂Γ vertices dropped", "continuous Q1 on the interior "
                 "vertices of G_h", _interior_q1, lambda k, n: (n - 1) ** 2, "stable"),
    # dim 3N² > dim W_h = 3N² − 4N + 1: at least 4N − 1 zero modes on matching meshes
    SpaceSpec("DISC-P1", "discontinuous P1 on QUAD8 faces", "discontinuous P1 on every rectangle of G_h", None,
              lambda k: 1, min_k=2, expected="unstable", dimension=lambda k, n: 3 * n * n, nodal_basis=False,
              claim_tag="DISC-P1", gamma_dims=(2,), face_build=lambda k, partition: DiscontinuousP1Space(partition),
              face_cells=("quad8",)),
    # CalculiX LINMORTAR: the dual basis of Q1 on the vertices (the mid-nodes ignored). Without the ∂Γ
    # vertices (constants kept) it is Wohlmuth's modified dual of Q1_0 ⊂ W_h: stable; with them the four
    # corner products ψ_0 ⊗ ψ_0, … are orthogonal to every interior hat, hence to W_h (tensor_modes): 4 modes
    _linear_spec("LINDUAL0-Q8", "CalculiX LINMORTAR, ∂Γ vertices dropped (Wohlmuth 2000)", "dual basis of Q1 on the "
                 "interior vertices of G_h, constants kept", _dual_q1(True), lambda k, n: (n - 1) ** 2, "stable",
                 nodal=False),
    _linear_spec("LINDUAL-Q8", "CalculiX LINMORTAR", "dual basis of Q1 on all vertices of G_h", _dual_q1(False),
                 lambda k, n: (n + 1) ** 2, "unstable", nodal=False),
    # CalculiX PGLINMORTAR: λ_h in the linear dual space, the constraint tested with the standard Q1 hats
    # (solvers/petrov_galerkin.py). Without the ∂Γ vertices no proof either way (a finding); with them the
    # trial space's four corner modes are in the kernel of B_N A⁻¹ B_Mᵀ
    _linear_spec("PGLIN0-Q8", "CalculiX PGLINMORTAR, ∂Γ vertices dropped", "λ_h in LINDUAL0-Q8, tested with "
                 "LIN0-Q8 (Petrov–Galerkin)", _dual_q1(True), lambda k, n: (n - 1) ** 2, "unknown", nodal=False,
                 pair=("LINDUAL0-Q8", "LIN0-Q8")),
    _linear_spec("PGLIN-Q8", "CalculiX PGLINMORTAR", "λ_h in LINDUAL-Q8, tested with T5 (continuous Q1 on all "
                 "vertices; Petrov–Galerkin)", _dual_q1(False), lambda k, n: (n + 1) ** 2, "unstable", nodal=False,
                 pair=("LINDUAL-Q8", "T5")),
)
"""The face-only entries, in registration order."""
