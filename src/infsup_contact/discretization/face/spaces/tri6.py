"""Multipliers of the quadratic triangle face TRI6: the tetrahedral (P2) analogues
of the QUAD8 / QUAD9 entries of the registry, on the triangles of a tensor partition G_h of the face
(every rectangle cut by its diagonal from (x_i, y_j) to (x_{i+1}, y_{j+1}), :mod:`.face.spaces.triangles`).

* ``dual`` — Wohlmuth's dual basis ψ = D M⁻¹ N (SIAM J. Numer. Anal. 38 (2000)) needs the weights
  d_k = ∫N_k > 0; on TRI6 (reference area 1/2) ∫N_vertex = 0 and ∫N_edge = 1/6, so it does not
  exist: refused (:func:`triangle_builder` re-raises :func:`.face.spaces.dual_bases.dual_coefficients`' refusal
  with the remedy).
* ``transformed_dual`` — Popp, Wohlmuth, Gee, Wall (SIAM J. Sci. Comput. 34 (2012) B421–B446) and
  4C: Ñ = T(α) N, Ñ_vertex = N_vertex + α Σ_{adjacent edge nodes} N_m, Ñ_m = (1 − 2α) N_m, weights
  ∫Ñ_vertex = α/3, ∫Ñ_m = (1 − 2α)/6 (fractions 2α/3 and (1 − 2α)/3 of the area; at 4C's α = 1/5:
  2/15 and 1/5), all > 0 for 0 < α < 1/2, det T = (1 − 2α)³ ≠ 0; ψ̃ = D̃ M̃⁻¹ Ñ is biorthogonal to
  Ñ. The P2 nodes on ∂Γ are dropped and the constants kept by the boundary modification of
  :class:`.face.spaces.triangles.TriangleSpace` (``dual=True``, ``alpha``), as the registry's DUAL does.
* ``pwlin`` — 4C's ``LM_QUAD pwlin`` (Popp 2009, BACI ``SplitIntElements``): continuous, linear on
  the 4 sub-triangles of every TRI6 (corner triangles and the middle one,
  :func:`.face.spaces.reference_elements.pwlin_subelements`), nodal at the 6 TRI6 nodes, vanishing on ∂Γ. The red
  refinement of a triangle (x0, y0), (x1, y0), (x1, y1) of G_h has the vertices of the
  half-cells of [x0, x1] × [y0, y1], and its four sub-triangles are those half-cells' triangles cut
  by *their* diagonals (three lower ones and the upper one of the lower-right half-cell; likewise
  for the upper triangle), so the space is P1 vanishing on ∂Γ on the diagonal-cut triangulation
  of the halved tensor partition (:func:`halved`): a :class:`~.face.spaces.triangles.TriangleSpace` of
  degree 1 whose ``breakpoints`` are that partition, its pieces (quadrature and Grams run on it).

dim M_h = (2 n_x − 1)(2 n_y − 1) for all three (the interior nodes of the P2 lattice), the dimension
of the P2 trace space W of a matching n × n tetrahedral mesh: the dimension argument predicts no kernel.
"""
from __future__ import annotations

import numpy as np

from ....errors import InputError
from .dual_bases import POPP_ALPHA, dual_coefficients
from .triangles import TriangleSpace

TRI6_BASES = ("dual", "transformed_dual", "pwlin")
"""The multiplier bases of a TRI6 face (module docstring)."""


def halved(partition):
    """The tensor partition with the midpoint of every interval added in x and in y."""
    from ..partitions.tensor_grid import TensorPartition

    return TensorPartition(*(np.sort(np.concatenate([g, 0.5 * (g[:-1] + g[1:])]))
                             for g in (np.asarray(partition.xs, float), np.asarray(partition.ys, float))))


def tri6_space(partition, basis: str, alpha: float | None = None) -> TriangleSpace:
    """The TRI6 multiplier space ``basis`` on the triangles of G_h = ``partition``, ∂Γ nodes dropped.

    Parameters
    ----------
    partition : TensorPartition
        G_h (each rectangle is cut by its diagonal).
    basis : {"dual", "transformed_dual", "pwlin"}
    alpha : float, optional
        α of ``transformed_dual`` (default 1/5, 4C's); refused outside [0, 1/2).

    Raises
    ------
    InputError
        ``basis`` unknown (key ``basis``); ``dual``: the non-positive TRI6 weights (key ``element``,
        from :func:`.face.spaces.dual_bases.dual_coefficients`).
    """
    if basis not in TRI6_BASES:
        raise InputError("basis", f"one of {', '.join(TRI6_BASES)} (TRI6 multipliers)", got=basis)
    if basis == "pwlin":
        return TriangleSpace(halved(partition), 1, True, True)
    a = POPP_ALPHA if alpha is None else alpha
    dual_coefficients("TRI6", transformed=basis == "transformed_dual", alpha=a)  # the weight check
    return TriangleSpace(partition, 2, True, True, dual=True, alpha=a)


def triangle_builder(basis: str, alpha: float | None = None, refuse_with: str = ""):
    """``face_build(k, partition)`` of a registry entry (:attr:`.spaces.spec.SpaceSpec.face_build`):
    :func:`tri6_space` on G_h (k does not enter: TRI6 fixes the multiplier degree). ``refuse_with``
    replaces the generic remedy of a refused dual basis (the registered id of the remedy), as
    :func:`.face.spaces.cellwise.cellwise_builder` does for QUAD8."""
    def build(k, partition):
        try:
            return tri6_space(partition, basis, alpha)
        except InputError as err:
            if refuse_with and err.key == "element":
                reason = err.allowed.rsplit("; use ", 1)[0]
                raise InputError("case", f"{reason} (the TRI6 vertex weights ∫N = 0); {refuse_with}",
                                 got=err.got) from None
            raise
    return build
