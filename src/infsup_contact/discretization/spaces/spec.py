"""A registry entry: what the suite knows about a multiplier space besides its basis.

How to build it (on the segment, on the face), the degrees it allows, its label and paper
reference, what is expected of it (stable, or the dimension of its kernel on matching meshes,
where a count is known) and which Γ it lives on. The entries themselves are data in
:mod:`.registry` and :mod:`.face_entries`; their colours and markers are the report's
(:mod:`infsup_contact.report.style`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ...errors import InputError
from ..gamma.constants import spans_constants
from ..segment.multipliers import SegmentSpace

K_RANGE = (1, 4)
"""Displacement degrees the suite supports."""


@dataclass(frozen=True)
class SpaceSpec:
    """A multiplier space as the suite knows it.

    Attributes
    ----------
    id : str
        The case id used on the command line, in configs and in tables (``T3``).
    paper_ref : str
        Where the space and its verdict come from (``Thm 3``, ``Rem 5.2``).
    definition : str
        The space in the paper's notation (``M^1_{0,k}``).
    build : callable or None
        ``build(k, breakpoints) -> SegmentSpace`` on a partition G_h of the segment; None for a
        space of the face only (``gamma_dims`` without 1), which has ``face_build`` instead.
    degree : callable
        Local polynomial degree s(k) of the multipliers.
    min_k : int
        Smallest displacement degree the space is defined for.
    expected : str
        ``"stable"`` (β_h bounded away from 0), ``"unstable"`` or ``"unknown"``.
    dimension : callable or None
        ``dimension(k, N) -> int``: dim M_h on N intervals (the paper's counts for its cases),
        None where no count is stated; it gives the structural kernel
        (:meth:`structural_kernel`).
    nodal_basis : bool
        True for Lagrange bases (a coefficient is a nodal value, so for s ≤ 1 the cone
        "coefficients ≥ 0" is "λ_h ≥ 0 pointwise", (5.4)); False for other bases, whose
        cone constrains coefficients only.
    finding_meshes : tuple of str
        Multiplier meshes (``omega2``, ``union``) on which the ledger records a finding
        beyond the paper for non-matching pairs.
    claim_tag : str or None
        Prefix of the space's ledger claim ids; default the paper reference without spaces
        (``Thm3-k1-structured-evenN``).
    gamma_dims : tuple of int
        Dimensions of the interfaces Γ the space is defined on: 1 the segment (the paper's
        2D models), 2 the face (0, 1)² of the 3D models. The paper's cases are both (on the
        face, the tensor products of their 1D builds); the face element spaces are (2,), and
        :func:`space_ids` / :func:`ids_valid_for` list the segment's by default, so the 2D
        consumers (configs, figures, the paper) never see them.
    face_build : callable or None
        ``face_build(k, partition) -> space`` on a tensor partition of the face, for a space
        that is not a tensor product of ``build`` (:mod:`.face.spaces.cellwise`); ``dimension(k, N)`` is
        then dim M_h on an N × N grid.
    face_cells : tuple of str
        The face cells (``quad``, ``trig``: :data:`~.face.shapes.square.CELL_SHAPES`) whose traces the space
        is defined against: the quadratic quadrilateral elements' multipliers pair with QUAD9
        traces (hexahedra) only, the TRI6 ones with P2 triangle traces (tetrahedra) only; ``quad8``:
        the QUAD8 traces of serendipity HEX20 bodies (:mod:`.face.shapes.serendipity`), which every tensor
        product space (the default) and the QUAD8 element spaces build on.
    lagrange : tuple or None
        ``(continuous, vanish)`` when ``build`` is the Lagrange space M^r_s / M^r_{0,s} of degree
        s = ``degree(k)`` (:func:`~.segment.multipliers.make_space`): the description an interface
        reads to build the analogue on other cells (P_s on triangles,
        :meth:`~.face.shapes.square.Square.space`); None for other bases.
    dual : bool
        With ``lagrange``: the space is the dual (biorthogonal) basis of that Lagrange space
        (:mod:`.segment.dual`; on triangles :class:`~.face.spaces.triangles.TriangleSpace` with ``dual=True``).
    trial_space, test_space : str or None
        A Petrov–Galerkin pair (both set): λ_h in the registered space ``trial_space`` M, the
        constraint b(v, μ) tested with μ in the registered space ``test_space`` N, dim M = dim N
        (CalculiX's PGLINMORTAR). ``build``/``face_build`` and ``dimension`` are the trial space's
        (what sizes the pair); β_h is :mod:`infsup_contact.solvers.petrov_galerkin`'s, and a consumer
        that needs one basis refuses the pair (``registry.case_space``). None: one space for both.
    """

    id: str
    paper_ref: str
    definition: str
    build: Callable[[int, np.ndarray], SegmentSpace] | None
    degree: Callable[[int], int]
    min_k: int = 1
    expected: str = "unknown"
    dimension: Callable[[int, int], int] | None = None
    nodal_basis: bool = True
    finding_meshes: tuple = field(default=())
    claim_tag: str | None = None
    gamma_dims: tuple = (1, 2)
    face_build: Callable | None = None
    face_cells: tuple = ("quad", "trig", "quad8")
    lagrange: tuple | None = None
    dual: bool = False
    trial_space: str | None = None
    test_space: str | None = None

    def __post_init__(self):
        if (self.trial_space is None) != (self.test_space is None):
            raise InputError("space", "both trial_space and test_space (a Petrov–Galerkin pair) or neither",
                             got=self.id)
        if self.build is None and self.defined_on(1):
            raise InputError("space", f"a build(k, breakpoints) for a space of the segment (gamma_dims "
                             f"{self.gamma_dims}), or gamma_dims=(2,) for a space of the face only", got=self.id)

    def defined_on(self, gamma_dim: int) -> bool:
        """Whether the space exists on an interface Γ of dimension ``gamma_dim``."""
        return gamma_dim in self.gamma_dims

    def face_space(self, k: int, n: int):
        """The space on the uniform n × n grid of the face: the square's build on the first face
        cell shape the entry is defined on (``face_cells``: rectangles, else triangles)."""
        from ..face.shapes.serendipity import face_of
        from ..face.shapes.square import CELL_SHAPES
        from ..face.partitions.tensor_grid import TensorPartition

        x = np.linspace(0.0, 1.0, n + 1)
        cell = next(c for c in CELL_SHAPES if c in self.face_cells)
        return face_of(cell).space(self, k, TensorPartition(x, x))

    @property
    def tag(self) -> str:
        return self.claim_tag or self.paper_ref.replace(" ", "")

    @property
    def petrov_galerkin(self) -> bool:
        """Whether the entry is a Petrov–Galerkin pair (trial space ≠ test space)."""
        return self.test_space is not None

    @property
    def stable(self) -> bool:
        return self.expected == "stable"

    def valid_for(self, k: int) -> bool:
        return self.min_k <= k <= K_RANGE[1]

    def contains_constants(self, k: int, n: int = 6) -> bool:
        """Whether 1 ∈ M_h for displacement degree k: :func:`~..gamma.constants.spans_constants`
        of the space built on N = ``n`` uniform intervals (a face-only space: on the n × n grid of
        the face). What a patch test of a uniform pressure asks of M_h (study/patch/)."""
        if not self.defined_on(1):
            return spans_constants(self.face_space(k, n))
        return spans_constants(self.build(k, np.linspace(0.0, 1.0, n + 1)))

    def structural_kernel(self, k: int, n: int) -> int | None:
        """max(dim M − dim W, 0) on matching meshes with N intervals (W = the trace space on
        :meth:`count_gamma`, where ``dimension`` counts), None without a dimension count."""
        if self.dimension is None:
            return None
        return max(self.dimension(k, n) - self.count_gamma().trace_dimension(k, n), 0)

    def count_gamma(self):
        """The Γ of the Γ table on which ``dimension`` counts: the segment for a space of the
        segment (its counts are per interval, Rem 5.2, Rem 5.4, Thm 5), for a space of the face
        only the n × n grid's face of its cells (QUAD9, QUAD8 or TRI6)."""
        from ..face.shapes.square import CELL_SHAPES  # the shapes build on the segment's spaces: imported late
        from .gammas import gamma_of

        if self.defined_on(1):
            return gamma_of("segment")
        from ..face.shapes.serendipity import face_of

        return face_of(next(c for c in CELL_SHAPES if c in self.face_cells))

    def cone(self, k: int) -> str:
        """``pointwise`` (λ_h ≥ 0 everywhere), ``nodal`` (at the Lagrange nodes) or
        ``coefficients`` (the basis is not nodal)."""
        if not self.nodal_basis:
            return "coefficients"
        return "pointwise" if self.degree(k) <= 1 else "nodal"

    def label(self, k: int | None = None) -> str:
        """Legend text: ``T3 (Thm 3)`` or ``T3 (Thm 3), k=2``."""
        text = f"{self.id} ({self.paper_ref})"
        return text if k is None else f"{text}, k={int(k)}"
